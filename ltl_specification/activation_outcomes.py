"""The activation–outcomes paradigm: one function per formula family of the ATLAS paper.

Every action or control mode ``p`` has a system proposition ``p_a`` (p is being activated)
and one environment proposition per outcome, ``p_<first letter>`` (``p_c`` completed,
``p_f`` failed). Goal memories ``g_m`` and the state machine's outcomes (``finished``,
``failed``) are system propositions. Equation numbers refer to the paper ("Automated
synthesis of ... high-level robot behaviors", ICRA 2016), Sections V-B to V-D.

Each function returns a list of conjuncts (``respec.ltl`` trees) for one specification
section, named in its docstring; text is only made by ``respec.ltl``'s printers.
"""

from __future__ import annotations

from typing import Iterable, Mapping, Sequence

from respec.ltl import FALSE, TRUE, Formula, conj, disj, iff, implies, neg, next_, var
from respec.vocabulary.naming import COMPLETED as COMPLETED, FAILED, FINISHED, activation as activation, memory as memory
from respec.vocabulary.naming import outcome_proposition as outcome_proposition  # components.py reads these four here



def _unique(formulas: Iterable[Formula]) -> list[Formula]:
    """Drop repeated formulas, keeping the first occurrence (for disjunctions like (11))."""
    return list(dict.fromkeys(formulas))


# --- generic formulas, actions and control modes alike (Sec. V-B.1) -------------------------

def deactivation_after_outcome(item: str, outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (3), sys_trans: deactivate once an outcome is returned.

    ⋀_o □(π_p ∧ ◯π_p^o ⇒ ◯¬π_p)
    """
    active = var(activation(item))
    return [implies(conj([active, next_(var(outcome_proposition(item, o)))]), next_(neg(active)))
            for o in outcomes]


def outcome_mutual_exclusion(item: str, outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (4), env_trans: at most one outcome at a time (no outcome is allowed).

    ⋀_o □(◯π_p^o ⇒ ⋀_{o'≠o} ◯¬π_p^{o'}); the ◯ operators are there for slugs, as the
    paper remarks. A single outcome needs no formula.
    """
    if len(outcomes) < 2:
        return []
    return [implies(next_(var(outcome_proposition(item, o))),
                    conj([next_(neg(var(outcome_proposition(item, other))))
                          for other in outcomes if other != o]))
            for o in outcomes]


def outcome_constraints(item: str, outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (5), env_trans: an outcome cannot appear unless p is activated.

    ⋀_o □(¬π_p^o ∧ ¬π_p ⇒ ◯¬π_p^o)
    """
    inactive = neg(var(activation(item)))
    return [implies(conj([neg(var(outcome_proposition(item, o))), inactive]),
                    next_(neg(var(outcome_proposition(item, o)))))
            for o in outcomes]


# --- action formulas (Sec. V-B.2) ------------------------------------------------------------

def outcome_persistence(action: str, outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (6), env_trans: an action's outcome persists until the action is activated again.

    ⋀_o □(π_a^o ∧ ¬π_a ⇒ ◯π_a^o)
    """
    inactive = neg(var(activation(action)))
    return [implies(conj([var(outcome_proposition(action, o)), inactive]),
                    next_(var(outcome_proposition(action, o))))
            for o in outcomes]


def action_fairness(action: str, outcomes: Sequence[str]) -> Formula:
    """Eq. (7), env_liveness: an activated action eventually returns some outcome.

    □◇((π_a ∧ ⋁_o ◯π_a^o) ∨ ¬π_a); the ¬π_a disjunct keeps the system from winning by
    never activating the action.
    """
    active = var(activation(action))
    returns = disj([next_(var(outcome_proposition(action, o))) for o in outcomes])
    return disj([conj([active, returns]), neg(active)])


def action_completion_fairness(action: str, success: str = COMPLETED) -> Formula:
    """Variant of Eq. (7) for retrying after failure, env_liveness: an action that is kept
    activated eventually completes.

    □◇(¬π_a ∨ ◯π_a^c); see ltl_specification.compiler for why this makes retrying sound.
    """
    return disj([neg(var(activation(action))), next_(var(outcome_proposition(action, success)))])


def preconditions(action: str, required: Sequence[str], success: str = COMPLETED) -> list[Formula]:
    """Eq. (8), sys_trans: an action may only be activated once its preconditions completed.

    □(⋁_{p ∈ Prec(a)} ¬π_p^c ⇒ ¬π_a); no formula when there are no preconditions.
    """
    if not required:
        return []
    missing = disj([neg(var(outcome_proposition(p, success))) for p in required])
    return [implies(missing, neg(var(activation(action))))]


# --- control-mode formulas (Sec. V-B.3) --------------------------------------------------------

def mode_activation(mode: str, modes: Sequence[str]) -> Formula:
    """φ_m = π_m ∧ ⋀_{m'≠m} ¬π_{m'}: activate the change to m and to no other mode."""
    return conj([var(activation(mode))] + [neg(var(activation(m))) for m in modes if m != mode])


def no_mode_activation(modes: Sequence[str]) -> Formula:
    """φ_M^none = ⋀_m ¬π_m: stay in the current control mode."""
    return conj([neg(var(activation(m))) for m in modes])


def mode_topology(adjacency: Mapping[str, Sequence[str]], success: str = COMPLETED) -> list[Formula]:
    """Eq. (9), sys_trans: from mode m, only activate changes to modes adjacent to m (or none).

    ⋀_m □(◯π_m^c ⇒ ⋁_{m' ∈ Adj(m)} ◯φ_{m'} ∨ ◯φ_M^none); ``adjacency`` lists the self-loop.
    """
    modes = list(adjacency)
    return [implies(next_(var(outcome_proposition(m, success))),
                    disj([next_(mode_activation(target, modes)) for target in adjacency[m]]
                         + [next_(no_mode_activation(modes))]))
            for m in modes]


def mode_mutual_exclusion(modes: Sequence[str], success: str = COMPLETED) -> list[Formula]:
    """Eq. (10), env_trans: the robot is in exactly one control mode.

    ⋀_m □(◯π_m^c ⇔ ⋀_{m'≠m} ◯¬π_{m'}^c); the ◯ operators are there for slugs. With a
    single mode this is just □◯π_m^c.
    """
    if len(modes) == 1:
        return [next_(var(outcome_proposition(modes[0], success)))]
    return [iff(next_(var(outcome_proposition(m, success))),
                conj([next_(neg(var(outcome_proposition(other, success)))) for other in modes if other != m]))
            for m in modes]


def single_step_mode_change(adjacency: Mapping[str, Sequence[str]], outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (11), env_trans: activating a change from m to m' either leaves the robot in m or
    returns an outcome of m' in the next step.

    ⋀_m ⋀_{m' ∈ Adj(m)} □(π_m^c ∧ φ_{m'} ⇒ ◯π_m^c ∨ ⋁_o ◯π_{m'}^o)
    """
    modes = list(adjacency)
    success = outcomes[0]
    formulas = []
    for m in modes:
        in_m = var(outcome_proposition(m, success))
        for target in adjacency[m]:
            results = _unique([next_(in_m)] + [next_(var(outcome_proposition(target, o))) for o in outcomes])
            formulas.append(implies(conj([in_m, mode_activation(target, modes)]), disj(results)))
    return formulas


def mode_outcome_persistence(modes: Sequence[str], outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (12), env_trans: mode outcomes persist while no mode change is activated.

    ⋀_m ⋀_o □(π_m^o ∧ φ_M^none ⇒ ◯π_m^o)
    """
    staying = no_mode_activation(modes)
    return [implies(conj([var(outcome_proposition(m, o)), staying]), next_(var(outcome_proposition(m, o))))
            for m in modes for o in outcomes]


def mode_fairness(modes: Sequence[str], outcomes: Sequence[str]) -> Formula:
    """Eq. (13), env_liveness: an activated mode change eventually returns an outcome.

    □◇(⋁_m (φ_m ∧ ⋁_o ◯π_m^o) ∨ φ_M^none), one formula for all modes.
    """
    return disj([conj([mode_activation(m, modes),
                       disj([next_(var(outcome_proposition(m, o))) for o in outcomes])])
                 for m in modes] + [no_mode_activation(modes)])


def mode_completion_fairness(modes: Sequence[str], success: str = COMPLETED) -> Formula:
    """Variant of Eq. (13) for retrying after failure, env_liveness: a mode change that is
    kept activated eventually completes.

    □◇(⋁_m (φ_m ∧ ◯π_m^c) ∨ φ_M^none)
    """
    return disj([conj([mode_activation(m, modes), next_(var(outcome_proposition(m, success)))])
                 for m in modes] + [no_mode_activation(modes)])


# --- initial conditions (Sec. V-C) ---------------------------------------------------------------

def environment_initial_conditions(items: Sequence[str], initially_completed: Iterable[str],
                                   outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (14), env_init: initial conditions have completed; no other outcome holds.

    φ_i^e = ⋀_{i ∈ I} (π_i^c ⋀_{o≠c} ¬π_i^o) ∧ ⋀_{j ∉ I} ⋀_o ¬π_j^o; ``outcomes[0]`` is c.
    """
    completed = set(initially_completed)
    formulas = []
    for item in items:
        for index, o in enumerate(outcomes):
            proposition = var(outcome_proposition(item, o))
            formulas.append(proposition if index == 0 and item in completed else neg(proposition))
    return formulas


def system_initial_conditions(items: Sequence[str]) -> list[Formula]:
    """Eq. (15), sys_init: nothing is being activated initially, initial conditions included.

    φ_i^s = ⋀_{i ∈ I} ¬π_i ∧ ⋀_{j ∉ I} ¬π_j
    """
    return [neg(var(activation(item))) for item in items]


# --- goals (Sec. V-D) ------------------------------------------------------------------------------

def goal_memory_initial_conditions(goals: Sequence[str]) -> list[Formula]:
    """Eq. (16), sys_init: no goal has been achieved yet, ⋀_g ¬μ_g."""
    return [neg(var(memory(g))) for g in goals]


def sm_outcome_initial_conditions(sm_outcomes: Sequence[str]) -> list[Formula]:
    """sys_init companion of Eq. (18): the state machine has no outcome yet, ⋀_o ¬π_SM^o.

    (18a)/(18b) constrain the current step only, so with robotics semantics an initial
    state with a premature outcome would otherwise be allowed, and lose.
    """
    return [neg(var(o)) for o in sm_outcomes]


def goal_memory(goals: Sequence[str], success: str = COMPLETED) -> list[Formula]:
    """Eq. (17), sys_trans: remember each goal once it has completed (in any order).

    ⋀_g □(◯π_g^c ∨ μ_g ⇔ ◯μ_g)
    """
    return [iff(disj([next_(var(outcome_proposition(g, success))), var(memory(g))]), next_(var(memory(g))))
            for g in goals]


def strict_goal_order(goals: Sequence[str], success: str = COMPLETED) -> list[Formula]:
    """Eq. (20), sys_trans: goal g_i only counts when achieved after g_{i-1} (μ_{g_0} = True).

    ⋀_i □(((π_{g_i} ∧ ◯π_{g_i}^c) ∧ μ_{g_{i-1}}) ∨ μ_{g_i} ⇔ ◯μ_{g_i})
    """
    formulas = []
    previous: Formula = TRUE
    for g in goals:
        achieved_now = conj([var(activation(g)), next_(var(outcome_proposition(g, success))), previous])
        formulas.append(iff(disj([achieved_now, var(memory(g))]), next_(var(memory(g)))))
        previous = var(memory(g))
    return formulas


def success_outcome(goals: Sequence[str], finished: str = FINISHED) -> Formula:
    """Eq. (18a), sys_trans: the state machine finishes exactly when all goals are achieved.

    □(π_SM^c ⇔ ⋀_g μ_g)
    """
    return iff(var(finished), conj([var(memory(g)) for g in goals]))


def failure_outcome(failure_propositions: Sequence[str], failed: str = FAILED) -> Formula:
    """Eq. (18b), sys_trans: the state machine fails exactly when something has failed.

    □(π_SM^f ⇔ ⋁ π^f) over the failure outcomes of every action and control mode.
    """
    return iff(var(failed), disj([var(p) for p in failure_propositions]) if failure_propositions else FALSE)


def sm_outcome_persistence(sm_outcomes: Sequence[str]) -> list[Formula]:
    """Eq. (18c), sys_trans: once the state machine has an outcome, it keeps it.

    ⋀_o □(π_SM^o ⇒ ◯π_SM^o)
    """
    return [implies(var(o), next_(var(o))) for o in sm_outcomes]


def single_liveness(sm_outcomes: Sequence[str]) -> Formula:
    """Eq. (19), sys_liveness: eventually the state machine has an outcome, □◇(⋁_o π_SM^o)."""
    return disj([var(o) for o in sm_outcomes])
