"""Sub-specifications of a task, each built from the formula families of activation_outcomes.

A task specification is the merge (``respec.spec.merge_specifications``) of, in this order:
the control-mode specification, the action specification, the initial-conditions
specification and the goal specification. Within each section, formulas are grouped per item
(mode, action, goal) in the order the items are given, families in equation order.

Every sub-specification is made of ``FormulaGroup``s: the formulas one paper equation adds
for one item. The groups are the provenance of a compiled specification (which equation and
which configuration entry or request field each formula comes from); unrealizable cores
(``ltl_synthesizer.unrealizable_core``) are sets of groups.

``retry_after_failure`` selects the encoding used when the state machine has no ``failed``
outcome (see ``ltl_specification.compiler`` for why it is sound): failure outcomes do not
force deactivation, so keeping ``π_p`` on means "try again", and the fairness assumptions
promise completion, not just some outcome, of an action or mode change kept activated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

from ltl_specification import activation_outcomes as ao
from respec.vocabulary.naming import FAILED, FINISHED
from respec.ltl import Formula
from respec.spec import FORMULA_SECTIONS, GR1Specification

# Where a group's formulas come from: the robot's configuration or the operator's request.
SOURCE_CONTROL_MODES = 'control_modes'
SOURCE_ACTIONS = 'actions'
SOURCE_INITIAL_CONDITIONS = 'initial_conditions'
SOURCE_GOALS = 'goals'
SOURCE_SM_OUTCOMES = 'sm_outcomes'
SOURCE_CUSTOM = 'custom_ltl'


@dataclass(frozen=True)
class FormulaGroup:
    """The formulas of one section that one paper equation adds for one item.

    ``equation`` is the paper's label, e.g. '(9)'; ``title`` names the family; ``item`` is
    the mode, action or goal it is about ('' when it is about all of them); ``source`` is
    one of the SOURCE_* names (the config section or request field that produced it).
    """

    section: str
    equation: str
    title: str
    item: str
    source: str
    formulas: tuple[Formula, ...]

    @property
    def is_assumption(self) -> bool:
        """Environment sections are assumptions; the others are the system's guarantees."""
        return self.section.startswith('env_')


def specification_from_groups(groups: Sequence[FormulaGroup], env_props: Sequence[str] = (),
                              sys_props: Sequence[str] = ()) -> GR1Specification:
    """The specification whose sections are the groups' formulas, concatenated in group order."""
    spec = GR1Specification(env_props=list(env_props), sys_props=list(sys_props))
    for group in groups:
        getattr(spec, group.section).extend(group.formulas)
    return spec


class _GroupList(list[FormulaGroup]):
    """Collects groups, leaving out empty ones (an equation that adds nothing for an item)."""

    def add(self, section: str, equation: str, title: str, item: str, source: str,
            formulas: Formula | Sequence[Formula]) -> None:
        assert section in FORMULA_SECTIONS, section
        group_formulas = tuple(formulas) if isinstance(formulas, (list, tuple)) else (formulas,)
        if group_formulas:
            self.append(FormulaGroup(section, equation, title, item, source, group_formulas))


def control_mode_groups(adjacency: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                        retry_after_failure: bool = False) -> list[FormulaGroup]:
    """Formulas (3)-(5) and (9)-(13) for the control modes in ``adjacency``, as groups."""
    modes = list(adjacency)
    groups = _GroupList()
    if not modes:
        return groups
    success = outcomes[0]
    deactivating = outcomes[:1] if retry_after_failure else outcomes
    source = SOURCE_CONTROL_MODES
    for m in modes:
        groups.add('sys_trans', '(3)', 'deactivation after an outcome', m, source,
                   ao.deactivation_after_outcome(m, deactivating))
    for m, formula in zip(modes, ao.mode_topology(adjacency, success)):
        groups.add('sys_trans', '(9)', 'control-mode topology', m, source, formula)
    for m in modes:
        groups.add('env_trans', '(4)', 'outcome mutual exclusion', m, source, ao.outcome_mutual_exclusion(m, outcomes))
        groups.add('env_trans', '(5)', 'outcome constraints', m, source, ao.outcome_constraints(m, outcomes))
    groups.add('env_trans', '(10)', 'one control mode at a time', '', source, ao.mode_mutual_exclusion(modes, success))
    groups.add('env_trans', '(11)', 'single-step mode change', '', source, ao.single_step_mode_change(adjacency, outcomes))
    groups.add('env_trans', '(12)', 'mode outcome persistence', '', source, ao.mode_outcome_persistence(modes, outcomes))
    if retry_after_failure:
        groups.add('env_liveness', '(13)', 'mode-change completion fairness', '', source,
                   ao.mode_completion_fairness(modes, success))
    else:
        groups.add('env_liveness', '(13)', 'mode-change fairness', '', source, ao.mode_fairness(modes, outcomes))
    return groups


def control_mode_specification(adjacency: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                               retry_after_failure: bool = False,
                               groups: Sequence[FormulaGroup] | None = None) -> GR1Specification:
    """Formulas (3)-(5) and (9)-(13) for the control modes in ``adjacency``.

    ``adjacency`` maps every mode to the modes it may change to, its own self-loop included.
    ``groups``: those formulas, when the caller already built them (``control_mode_groups``).
    """
    modes = list(adjacency)
    return specification_from_groups(
        groups if groups is not None else control_mode_groups(adjacency, outcomes, retry_after_failure),
        env_props=[ao.outcome_proposition(m, o) for m in modes for o in outcomes],
        sys_props=[ao.activation(m) for m in modes])


def action_groups(actions: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                  retry_after_failure: bool = False) -> list[FormulaGroup]:
    """Formulas (3)-(8) for each action in ``actions`` (action -> its preconditions), as groups."""
    success = outcomes[0]
    deactivating = outcomes[:1] if retry_after_failure else outcomes
    groups = _GroupList()
    source = SOURCE_ACTIONS
    for action, required in actions.items():
        groups.add('sys_trans', '(3)', 'deactivation after an outcome', action, source,
                   ao.deactivation_after_outcome(action, deactivating))
        groups.add('sys_trans', '(8)', 'preconditions', action, source, ao.preconditions(action, required, success))
        groups.add('env_trans', '(4)', 'outcome mutual exclusion', action, source,
                   ao.outcome_mutual_exclusion(action, outcomes))
        groups.add('env_trans', '(5)', 'outcome constraints', action, source, ao.outcome_constraints(action, outcomes))
        groups.add('env_trans', '(6)', 'outcome persistence', action, source, ao.outcome_persistence(action, outcomes))
        if retry_after_failure:
            groups.add('env_liveness', '(7)', 'completion fairness', action, source,
                       ao.action_completion_fairness(action, success))
        else:
            groups.add('env_liveness', '(7)', 'action fairness', action, source, ao.action_fairness(action, outcomes))
    return groups


def action_specification(actions: Mapping[str, Sequence[str]], outcomes: Sequence[str],
                         retry_after_failure: bool = False,
                         groups: Sequence[FormulaGroup] | None = None) -> GR1Specification:
    """Formulas (3)-(8) for each action in ``actions`` (action -> its preconditions);
    ``groups`` when already built (``action_groups``)."""
    return specification_from_groups(
        groups if groups is not None else action_groups(actions, outcomes, retry_after_failure),
        env_props=[ao.outcome_proposition(a, o) for a in actions for o in outcomes],
        sys_props=[ao.activation(a) for a in actions])


def goal_groups(goals: Sequence[str], sm_outcomes: Sequence[str], strict_order: bool,
                failure_propositions: Sequence[str], success: str = ao.COMPLETED,
                finished: str = FINISHED, failed: str = FAILED) -> list[FormulaGroup]:
    """Formulas (16)-(20), as groups (one per goal for (16), (17) and (20))."""
    groups = _GroupList()
    for g, formula in zip(goals, ao.goal_memory_initial_conditions(goals)):
        groups.add('sys_init', '(16)', 'no goal achieved initially', g, SOURCE_GOALS, formula)
    for o, formula in zip(sm_outcomes, ao.sm_outcome_initial_conditions(sm_outcomes)):
        groups.add('sys_init', '(18)', 'no state-machine outcome initially', o, SOURCE_SM_OUTCOMES, formula)
    if strict_order:
        for g, formula in zip(goals, ao.strict_goal_order(goals, success)):
            groups.add('sys_trans', '(20)', 'goals in the given order', g, SOURCE_GOALS, formula)
    else:
        for g, formula in zip(goals, ao.goal_memory(goals, success)):
            groups.add('sys_trans', '(17)', 'goal memory', g, SOURCE_GOALS, formula)
    groups.add('sys_trans', '(18a)', 'finished exactly when all goals are achieved', finished, SOURCE_GOALS,
               ao.success_outcome(goals, finished))
    if failed in sm_outcomes:
        groups.add('sys_trans', '(18b)', 'failed exactly when something failed', failed, SOURCE_SM_OUTCOMES,
                   ao.failure_outcome(failure_propositions, failed))
    for o, formula in zip(sm_outcomes, ao.sm_outcome_persistence(sm_outcomes)):
        groups.add('sys_trans', '(18c)', 'a state-machine outcome persists', o, SOURCE_SM_OUTCOMES, formula)
    groups.add('sys_liveness', '(19)', 'eventually an outcome', '', SOURCE_SM_OUTCOMES, ao.single_liveness(sm_outcomes))
    return groups


def goal_specification(goals: Sequence[str], sm_outcomes: Sequence[str], strict_order: bool,
                       failure_propositions: Sequence[str], success: str = ao.COMPLETED,
                       finished: str = FINISHED, failed: str = FAILED,
                       groups: Sequence[FormulaGroup] | None = None) -> GR1Specification:
    """Formulas (16)-(20): goal memories, state-machine outcomes and the single liveness.

    ``sm_outcomes`` contains ``finished`` and optionally ``failed``; ``failure_propositions``
    are the failure outcomes that make the state machine fail (18b). ``groups`` when already
    built (``goal_groups``).
    """
    return specification_from_groups(
        groups if groups is not None else
        goal_groups(goals, sm_outcomes, strict_order, failure_propositions, success, finished, failed),
        sys_props=[ao.memory(g) for g in goals] + list(sm_outcomes))


def initial_conditions_groups(items: Sequence[str], initially_completed: Sequence[str],
                              outcomes: Sequence[str]) -> list[FormulaGroup]:
    """Formulas (14) and (15), one group per item (action or mode) of the task."""
    groups = _GroupList()
    per_item = len(outcomes)
    environment = ao.environment_initial_conditions(items, initially_completed, outcomes)
    for index, item in enumerate(items):
        groups.add('env_init', '(14)', 'initial outcomes', item, SOURCE_INITIAL_CONDITIONS,
                   environment[index * per_item:(index + 1) * per_item])
    for item, formula in zip(items, ao.system_initial_conditions(items)):
        groups.add('sys_init', '(15)', 'nothing activated initially', item, SOURCE_INITIAL_CONDITIONS, formula)
    return groups


def initial_conditions_specification(items: Sequence[str], initially_completed: Sequence[str],
                                     outcomes: Sequence[str],
                                     groups: Sequence[FormulaGroup] | None = None) -> GR1Specification:
    """Formulas (14) and (15) over all ``items`` (actions and modes) of the task; ``groups``
    when already built (``initial_conditions_groups``)."""
    return specification_from_groups(
        groups if groups is not None else initial_conditions_groups(items, initially_completed, outcomes))
