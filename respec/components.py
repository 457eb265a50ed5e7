"""Sub-specifications of a task, each built from the formula families of activation_outcomes.

A task specification is the merge (``respec.spec.merge_specifications``) of, in this order:
the control-mode specification, the action specification, the initial-conditions
specification and the goal specification. Within each section, formulas are grouped per item
(mode, action, goal) in the order the items are given, families in equation order.

``retry_after_failure`` selects the encoding used when the state machine has no ``failed``
outcome (see ``ltl_specification.compiler`` for why it is sound): failure outcomes do not
force deactivation, so keeping ``π_p`` on means "try again", and the fairness assumptions
promise completion, not just some outcome, of an action or mode change kept activated.
"""

from __future__ import annotations

from typing import Mapping, Sequence

from respec import activation_outcomes as ao
from respec.spec import GR1Specification


def control_mode_specification(adjacency: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                               retry_after_failure: bool = False) -> GR1Specification:
    """Formulas (3)-(5) and (9)-(13) for the control modes in ``adjacency``.

    ``adjacency`` maps every mode to the modes it may change to, its own self-loop included.
    """
    modes = list(adjacency)
    if not modes:
        return GR1Specification()
    success = outcomes[0]
    deactivating = outcomes[:1] if retry_after_failure else outcomes
    spec = GR1Specification(
        env_props=[ao.outcome_proposition(m, o) for m in modes for o in outcomes],
        sys_props=[ao.activation(m) for m in modes])
    for m in modes:
        spec.sys_trans += ao.deactivation_after_outcome(m, deactivating)
    spec.sys_trans += ao.mode_topology(adjacency, success)
    for m in modes:
        spec.env_trans += ao.outcome_mutual_exclusion(m, outcomes)
        spec.env_trans += ao.outcome_constraints(m, outcomes)
    spec.env_trans += ao.mode_mutual_exclusion(modes, success)
    spec.env_trans += ao.single_step_mode_change(adjacency, outcomes)
    spec.env_trans += ao.mode_outcome_persistence(modes, outcomes)
    spec.env_liveness.append(ao.mode_completion_fairness(modes, success) if retry_after_failure
                             else ao.mode_fairness(modes, outcomes))
    return spec


def action_specification(actions: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                         retry_after_failure: bool = False) -> GR1Specification:
    """Formulas (3)-(8) for each action in ``actions`` (action -> its preconditions)."""
    success = outcomes[0]
    deactivating = outcomes[:1] if retry_after_failure else outcomes
    spec = GR1Specification(
        env_props=[ao.outcome_proposition(a, o) for a in actions for o in outcomes],
        sys_props=[ao.activation(a) for a in actions])
    for action, required in actions.items():
        spec.sys_trans += ao.deactivation_after_outcome(action, deactivating)
        spec.sys_trans += ao.preconditions(action, required, success)
        spec.env_trans += ao.outcome_mutual_exclusion(action, outcomes)
        spec.env_trans += ao.outcome_constraints(action, outcomes)
        spec.env_trans += ao.outcome_persistence(action, outcomes)
        spec.env_liveness.append(ao.action_completion_fairness(action, success) if retry_after_failure
                                 else ao.action_fairness(action, outcomes))
    return spec


def goal_specification(goals: Sequence[str], sm_outcomes: Sequence[str], strict_order: bool,
                       failure_propositions: Sequence[str], success: str = ao.COMPLETED,
                       finished: str = 'finished', failed: str = 'failed') -> GR1Specification:
    """Formulas (16)-(20): goal memories, state-machine outcomes and the single liveness.

    ``sm_outcomes`` contains ``finished`` and optionally ``failed``; ``failure_propositions``
    are the failure outcomes that make the state machine fail (18b).
    """
    spec = GR1Specification(sys_props=[ao.memory(g) for g in goals] + list(sm_outcomes))
    spec.sys_init += ao.goal_memory_initial_conditions(goals)
    spec.sys_init += ao.sm_outcome_initial_conditions(sm_outcomes)
    spec.sys_trans += (ao.strict_goal_order(goals, success) if strict_order
                       else ao.goal_memory(goals, success))
    spec.sys_trans.append(ao.success_outcome(goals, finished))
    if failed in sm_outcomes:
        spec.sys_trans.append(ao.failure_outcome(failure_propositions, failed))
    spec.sys_trans += ao.sm_outcome_persistence(sm_outcomes)
    spec.sys_liveness.append(ao.single_liveness(sm_outcomes))
    return spec


def initial_conditions_specification(items: Sequence[str], initially_completed: Sequence[str],
                                     outcomes: Sequence[str]) -> GR1Specification:
    """Formulas (14) and (15) over all ``items`` (actions and modes) of the task."""
    return GR1Specification(
        env_init=ao.environment_initial_conditions(items, initially_completed, outcomes),
        sys_init=ao.system_initial_conditions(items))
