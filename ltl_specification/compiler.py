"""Compile a task (system, initial conditions, goals) into a GR(1) specification.

The specification is the merge, in this fixed order, of: the control-mode formulas, the
action formulas, the initial conditions, the goal formulas, the sensors that custom LTL
uses and the user's custom LTL
(see ``ltl_specification.components`` and ``respec.spec.merge_specifications``). Pertinent actions and
modes are inferred from the task (``ltl_specification.pertinence``) and listed in
configuration order, so the same request always gives a byte-identical specification.

State-machine outcomes
----------------------
``('finished', 'failed')``: any failure outcome of a pertinent action or mode change makes
the state machine end in ``failed`` (18b); reaching all goals ends it in ``finished`` (18a).

``('finished',)`` — retry after failure. The original encoding keeps (3) and (7) and is
unrealizable for every task: (3) makes the system deactivate an action after ANY outcome,
and (7) only promises SOME outcome, so an environment that fails every attempt satisfies
all assumptions while no goal is ever reached. Adding □◇(¬π_a ∨ ◯π_a^c) alone does not
help, because the deactivation step forced after each failure already satisfies ¬π_a.

Our encoding:

* (3) applies to the completion outcome only: after a failure the system may keep ``π_a``
  on, which means "execute a again" (or switch it off).
* The fairness assumptions become completion fairness: □◇(¬π_a ∨ ◯π_a^c) for each
  action (variant of (7)) and □◇(⋁_m (φ_m ∧ ◯π_m^c) ∨ φ_M^none) for mode changes
  (variant of (13)): an action or mode change that stays activated eventually completes.

Why this is sound: (a) the assumptions cannot be falsified by the system — whatever the
system does, the environment can satisfy every safety assumption and both fairness
conditions by answering each activation with completion, which (4)-(6) and (10)-(12)
always allow — so the system cannot win vacuously by forcing the environment into a
violation; (b) the system wins honestly by working through the precondition order along
the pertinent modes and keeping each activation on until it completes: failures merely
repeat a step, and fairness rules out failing forever. So the specification is realizable
exactly under the stated assumption that a retried action eventually succeeds, and a
controller synthesized from it retries each failed action or mode change.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, fields
from typing import Any, Mapping, Sequence

from respec.robot import RobotSystem, for_description
from respec.robot.abstraction import RobotAbstraction
from respec.robot.cnu import CapabilitySystem
from ltl_specification.components import (
    SOURCE_CUSTOM, FormulaGroup, action_groups, action_specification, control_mode_groups,
    control_mode_specification, goal_groups, goal_specification, initial_conditions_groups,
    initial_conditions_specification,
)
from respec.vocabulary.errors import CodedError, quoted
from respec.ltl import Formula, variables
from respec.vocabulary.naming import (DEFAULT_SM_OUTCOMES, FAILED, FINISHED, activation, did_you_mean,
                                      outcome_proposition, parse_names)
from respec.parsing import ParseError, UnknownVariableError, parse_formula, spec_from_text_sections
from respec.spec import (
    FORMULA_SECTIONS, PROPOSITION_SECTIONS, SECTIONS, GR1Specification, PropositionConflictError,
    merge_specifications,
)
from respec.robot.state_library import StateClass, workspace_state_library

from ltl_specification.capabilities import compile_capability_task
from ltl_specification.capability_precheck import check_capability_names, check_capability_task
from ltl_specification.diagnosis import REFUSAL_DIAGNOSIS_SECONDS, refusal_diagnosis
from ltl_specification.errors import (
    ImpossibleGoalsError, InvalidFormulaError, InvalidGoalsError, InvalidInitialConditionsError,
    InvalidSmOutcomesError, UnknownPropositionError,
)
from ltl_specification.pertinence import Pertinence, infer_pertinence, mode_distances
from ltl_specification.provenance import Provenance, task_provenance
from ltl_specification.systems import load_task_abstraction

SUPPORTED_SM_OUTCOMES = (DEFAULT_SM_OUTCOMES, (FINISHED,))


@dataclass
class CompiledSpecification(GR1Specification):
    """A GR1Specification that also records its ``provenance`` (not part of equality)."""

    provenance: Provenance | None = field(default=None, compare=False, repr=False)

    def explain(self) -> str:
        return explain(self)


def compile_task(system: RobotSystem, initial_conditions: Sequence[str] | str, goals: Sequence[str] | str,
                 sm_outcomes: Sequence[str] = DEFAULT_SM_OUTCOMES, strict_order: bool = True,
                 custom_ltl: Mapping[str, Sequence[str]] | None = None,
                 state_library: Mapping[str, StateClass] | None = None,
                 explain_refusal: bool = True) -> CompiledSpecification:
    """Compile the GR(1) specification of reaching ``goals`` from ``initial_conditions``.

    ``system`` is a RobotSystem (a name becomes one at the edge: ``respec.robot.robot_system``
    inside ``ltl_specification.systems.task_system_errors``). A system described by CNU
    capability files (``respec.robot.cnu``) is compiled by ``ltl_specification.capabilities``;
    its state classes are checked against ``state_library`` (default: the FlexBE state packages
    on ``AMENT_PREFIX_PATH``); its mappings name the ``sm_outcomes`` (CNU's request semantics),
    and ``strict_order`` does not apply;
    ``ltl_specification.capability_precheck`` refuses, before synthesis, an initial condition
    that names nothing of it, a goal no capability can make true and a precondition nothing
    establishes.

    Goals and initial conditions are action or control-mode names (a list, or one
    comma-separated string). At most one initial condition may be a control mode; without
    one, the system's ``initial_mode`` is used. ``strict_order`` selects (20) over (17).
    ``custom_ltl`` maps LTLSpecification section names to infix formulas (or, for
    env_props / sys_props, new proposition names) that are conjoined to the result.
    Raises a ``SpecificationError`` subclass naming the offending item. A goal mode (or a mode
    custom LTL names) that no route from the initial mode reaches is refused before synthesis
    (INVALID_GOALS, ``ImpossibleGoalsError``) with the diagnosis synthesis would give (sentence,
    unrealizable core, environment play; ``ltl_specification.diagnosis.refusal_diagnosis``,
    up to its REFUSAL_DIAGNOSIS_SECONDS); ``explain_refusal=False`` refuses with the sentence
    alone, at once (for callers that only need the verdict).
    """
    # a file without an abstraction: section: the mode compiler names what is missing
    compile_for = for_description(_COMPILERS, system, missing=_compiled_for_modes)
    return compile_for(system, initial_conditions, goals, sm_outcomes, strict_order, custom_ltl, state_library,
                       explain_refusal)


def _compiled_for_capabilities(system: RobotSystem, initial_conditions: Sequence[str] | str, goals: Sequence[str] | str,
                               sm_outcomes: Sequence[str], strict_order: bool,
                               custom_ltl: Mapping[str, Sequence[str]] | None,
                               state_library: Mapping[str, StateClass] | None,
                               explain_refusal: bool) -> CompiledSpecification:
    del strict_order, explain_refusal  # CNU's goals hold together; its refusals come from the pre-check
    library = workspace_state_library() if state_library is None else state_library
    initial_conditions = _names(initial_conditions, 'initial conditions', InvalidInitialConditionsError)
    goals = _names(goals, 'goals', InvalidGoalsError)
    check_capability_names(system, initial_conditions)   # first: the sentence names the entry to change
    spec = compile_capability_task(system.required_capabilities(), library, initial_conditions, goals, custom_ltl,
                                   _names(sm_outcomes, 'state-machine outcomes', InvalidSmOutcomesError))
    check_capability_task(system, initial_conditions, goals)   # once the files' own errors are ruled out
    return CompiledSpecification(**_spec_fields(spec))


def _compiled_for_modes(system: RobotSystem, initial_conditions: Sequence[str] | str, goals: Sequence[str] | str,
                        sm_outcomes: Sequence[str], strict_order: bool, custom_ltl: Mapping[str, Sequence[str]] | None,
                        state_library: Mapping[str, StateClass] | None,
                        explain_refusal: bool) -> CompiledSpecification:
    del state_library  # the abstraction's flexbe: section names its states
    abstraction = load_task_abstraction(system)
    sm_outcomes = _check_sm_outcomes(sm_outcomes)
    goals = _check_goals(abstraction, goals)
    initial_conditions = _check_initial_conditions(abstraction, initial_conditions)
    initial_mode = _initial_mode(abstraction, initial_conditions)
    custom_formulas = _parse_custom_ltl(custom_ltl)
    mentioned, sensors = _items_mentioned(abstraction, custom_formulas)
    where = system.config_file
    pertinence = infer_pertinence(abstraction, initial_mode, initial_conditions, goals, mentioned)
    unreachable = _unreachable_modes(abstraction, pertinence)
    parts, groups = _sub_specifications(abstraction, pertinence, initial_conditions, goals, sm_outcomes,
                                        strict_order)
    groups += _custom_groups(custom_formulas)
    parts.append(GR1Specification(env_props=sensors))
    parts.append(_custom_specification(custom_ltl, custom_formulas))
    try:
        spec = merge_specifications(parts)
    except PropositionConflictError as error:
        raise InvalidFormulaError(
            f'custom LTL declares {quoted(error.item)} with the wrong kind: {error}', item=error.item) from error
    _check_custom_scopes(spec, custom_ltl)
    provenance = task_provenance(system.name, abstraction, where, initial_conditions, goals, sm_outcomes, strict_order,
                                 pertinence, tuple(s for s in SECTIONS if custom_ltl and custom_ltl.get(s)),
                                 groups, _flexbe_states(system))
    compiled = CompiledSpecification(**_spec_fields(spec), provenance=provenance)
    if unreachable:
        raise _impossible_goals(compiled, *unreachable[0], explain=explain_refusal)
    return compiled


_COMPILERS = {RobotAbstraction: _compiled_for_modes, CapabilitySystem: _compiled_for_capabilities}


def _flexbe_states(system: RobotSystem) -> dict[str, Any]:
    """The ``flexbe.states`` section of the system file (empty without one): it names the states
    and outcomes of a diagnosis' play."""
    states = system.section('flexbe').get('states') if system.has_section('flexbe') else None
    return states if isinstance(states, dict) else {}


def _spec_fields(spec: GR1Specification) -> dict[str, Any]:
    return {f.name: getattr(spec, f.name) for f in fields(GR1Specification)}


def _sub_specifications(abstraction: RobotAbstraction, pertinence: Pertinence, initial_conditions: list[str],
                        goals: list[str], sm_outcomes: tuple[str, ...], strict_order: bool
                        ) -> tuple[list[GR1Specification], list[FormulaGroup]]:
    """The generated parts of the task specification, in merge order (modes, actions, init, goals),
    and the formula groups they are made of (their provenance)."""
    retry = FAILED not in sm_outcomes
    outcomes = abstraction.outcomes
    adjacency = {m: (m, *(t for t in abstraction.control_modes[m] if t in pertinence.modes))
                 for m in pertinence.modes}
    items = [*pertinence.modes, *pertinence.actions]
    # The default initial mode holds initially just as if it had been named.
    initially_completed = [i for i in [*initial_conditions, pertinence.initial_mode] if i in items]
    failures = [outcome_proposition(item, o) for item in items for o in abstraction.failure_outcomes]
    actions = {a: abstraction.actions[a] for a in pertinence.actions}
    goal_arguments = (goals, sm_outcomes, strict_order, failures, abstraction.success_outcome)
    # Each formula is built once: the groups are the provenance, the parts are made of them.
    mode_groups = control_mode_groups(adjacency, outcomes, retry)
    action_groups_ = action_groups(actions, outcomes, retry)
    initial_groups = initial_conditions_groups(items, initially_completed, outcomes)
    goals_groups = goal_groups(*goal_arguments)
    parts = [
        control_mode_specification(adjacency, outcomes, retry, groups=mode_groups),
        action_specification(actions, outcomes, retry, groups=action_groups_),
        initial_conditions_specification(items, initially_completed, outcomes, groups=initial_groups),
        goal_specification(*goal_arguments, groups=goals_groups),
    ]
    return parts, [*mode_groups, *action_groups_, *initial_groups, *goals_groups]


def _custom_groups(custom_formulas: dict[str, list[Formula]]) -> list[FormulaGroup]:
    """One group per custom formula, named by its section and index (as the request gave it)."""
    return [FormulaGroup(section, 'custom', 'custom LTL', f'{section}[{index}]', SOURCE_CUSTOM, (formula,))
            for section in FORMULA_SECTIONS for index, formula in enumerate(custom_formulas.get(section, []))]


def explain(spec: CompiledSpecification) -> str:
    """A short human-readable account of what the specification contains and why."""
    p = spec.provenance
    if p is None:
        return 'no provenance recorded'
    order = 'in this order' if p.strict_order else 'in any order'
    lines = [f'Task on {p.system}: from {", ".join(p.initial_conditions) or p.pertinence.initial_mode}'
             f' reach {", ".join(p.goals)} ({order}); state-machine outcomes: {", ".join(p.sm_outcomes)}'
             + (' (failures are retried)' if FAILED not in p.sm_outcomes else '') + '.']
    for title, items in (('Control modes', p.pertinence.modes), ('Actions', p.pertinence.actions)):
        described = ', '.join(f'{i} ({p.pertinence.reasons[i]})' for i in items) or 'none'
        lines.append(f'{title}: {described}.')
    if p.pertinence.left_out:
        lines.append('Left out: ' + ', '.join(f'{i} ({why})' for i, why in p.pertinence.left_out.items()) + '.')
    if p.custom_sections:
        lines.append(f'Custom LTL in: {", ".join(p.custom_sections)}.')
    counts = ', '.join(f'{len(getattr(spec, s))} {s}' for s in FORMULA_SECTIONS)
    lines.append(f'Size: {len(spec.env_props)} environment and {len(spec.sys_props)} system '
                 f'propositions; {counts}.')
    return '\n'.join(lines)


# --- request validation ---------------------------------------------------------------------

def _names(value: Sequence[str] | str | None, what: str, error: type[CodedError]) -> list[str]:
    if value is None:
        return []
    if isinstance(value, str):
        value = parse_names(value)
    if not isinstance(value, (list, tuple)):
        raise error(f'{what} must be a list of names, got {quoted(value)}', item=quoted(value))
    names = list(value)
    for name in names:
        if not isinstance(name, str) or not name:
            raise error(f'{what} must be non-empty names, got {quoted(name)}', item=quoted(name))
    return names


def _check_sm_outcomes(sm_outcomes: Sequence[str]) -> tuple[str, ...]:
    names = _names(sm_outcomes, 'state-machine outcomes', InvalidSmOutcomesError)
    for name in names:
        if name not in (FINISHED, FAILED):
            raise InvalidSmOutcomesError(
                f'unsupported state-machine outcome {quoted(name)} (supported: [finished, failed] or [finished])',
                item=name)
    normalized = tuple(o for o in (FINISHED, FAILED) if o in names)
    if len(names) != len(set(names)) or normalized not in SUPPORTED_SM_OUTCOMES:
        raise InvalidSmOutcomesError(
            f'unsupported state-machine outcomes {names} (supported: [finished, failed] or [finished])',
            item=','.join(names))
    return normalized


def _check_goals(abstraction: RobotAbstraction, goals: Sequence[str] | str) -> list[str]:
    names = _names(goals, 'goals', InvalidGoalsError)
    if not names:
        raise InvalidGoalsError('no goals given: name at least one action or control mode', item='')
    for index, goal in enumerate(names):
        if abstraction.kind_of(goal) is None:
            raise UnknownPropositionError(
                f'unknown goal {quoted(goal)}: not an action or control mode of {abstraction.system}'
                f'{did_you_mean(goal, abstraction.items())} (known: {", ".join(abstraction.items())})',
                item=goal)
        if goal in names[:index]:
            raise InvalidGoalsError(f'goal {quoted(goal)} is given twice', item=goal)
    return names


def _check_initial_conditions(abstraction: RobotAbstraction, initial_conditions: Sequence[str] | str) -> list[str]:
    names = _names(initial_conditions, 'initial conditions', InvalidInitialConditionsError)
    for name in names:
        if abstraction.kind_of(name) is None:
            raise UnknownPropositionError(
                f'unknown initial condition {quoted(name)}: not an action or control mode of '
                f'{abstraction.system}{did_you_mean(name, abstraction.items())} '
                f'(known: {", ".join(abstraction.items())})', item=name)
    return list(dict.fromkeys(names))


def _unreachable_modes(abstraction: RobotAbstraction, pertinence: Pertinence) -> list[tuple[str, str]]:
    """(mode, sentence) for each needed mode that no route from the initial mode reaches: such a
    task is refused before synthesis (``_impossible_goals``)."""
    initial_mode = pertinence.initial_mode
    if initial_mode is None:
        return []
    reachable = mode_distances(abstraction.control_modes, initial_mode)
    return [(mode, f'control mode {mode!r} ({pertinence.reasons[mode]}) cannot be reached from the '
                   f'initial mode {initial_mode!r} on {abstraction.system}')
            for mode in pertinence.modes if mode not in reachable]


def _impossible_goals(spec: CompiledSpecification, mode: str, sentence: str,
                      explain: bool = True) -> ImpossibleGoalsError:
    """The refusal of a task whose ``mode`` no route reaches: INVALID_GOALS, with the diagnosis
    that synthesis would have given (the pre-check's sentence, the core, the environment play),
    so every channel tells one story whichever stage finds the impossibility. ``sentence`` leads
    when the pre-check names no goal (a mode needed by a precondition's precondition, or one
    that custom LTL mentions)."""
    diagnosis = refusal_diagnosis(spec, sentence, seconds=REFUSAL_DIAGNOSIS_SECONDS if explain else 0.0)
    item = diagnosis.findings[0].item if diagnosis.findings else mode
    return ImpossibleGoalsError(diagnosis.message(), item=item, diagnosis=diagnosis)


def _initial_mode(abstraction: RobotAbstraction, initial_conditions: list[str]) -> str | None:
    modes = [i for i in initial_conditions if abstraction.kind_of(i) == 'control_mode']
    if len(modes) > 1:
        raise InvalidInitialConditionsError(
            f'the robot can only start in one control mode, got {", ".join(modes)}', item=modes[1])
    if modes:
        return modes[0]
    if abstraction.control_modes and abstraction.initial_mode is None:
        raise InvalidInitialConditionsError(
            f'no initial control mode: name one of {", ".join(abstraction.control_modes)} among the '
            f'initial conditions ({abstraction.system} defines no initial_mode)', item='')
    return abstraction.initial_mode


# --- custom LTL -----------------------------------------------------------------------------------

def _parse_custom_ltl(custom_ltl: object) -> dict[str, list[Formula]]:
    """Parse the custom formulas (syntax only); names are checked once the task is known."""
    if not custom_ltl:
        return {}
    if not isinstance(custom_ltl, Mapping):
        raise InvalidFormulaError(f'custom LTL must map section names to lists, got {quoted(custom_ltl)}',
                                  item=quoted(custom_ltl))
    parsed: dict[str, list[Formula]] = {}
    for section, entries in custom_ltl.items():
        if section not in SECTIONS:
            raise InvalidFormulaError(
                f'unknown custom LTL section {quoted(section)} (expected one of {", ".join(SECTIONS)})', item=str(section))
        if isinstance(entries, str) or not isinstance(entries, (list, tuple)):
            raise InvalidFormulaError(f'custom LTL section {section} must be a list of strings', item=quoted(entries))
        if section in PROPOSITION_SECTIONS:
            for name in entries:
                if not isinstance(name, str):
                    raise InvalidFormulaError(f'custom {section} entry {quoted(name)} is not a name', item=quoted(name))
            continue
        parsed[section] = []
        for text in entries:
            try:
                parsed[section].append(parse_formula(text))
            except ParseError as error:
                raise InvalidFormulaError(f'custom {section} formula {quoted(text)}: {error}', item=str(text)) from error
    return parsed


def _items_mentioned(abstraction: RobotAbstraction, custom_formulas: dict[str, list[Formula]]
                     ) -> tuple[list[str], list[str]]:
    """Actions/modes and sensors whose propositions the custom formulas use (config order)."""
    owner_of = {}
    for item in abstraction.items():
        owner_of[activation(item)] = item
        for o in abstraction.outcomes:
            owner_of[outcome_proposition(item, o)] = item
    used = set().union(*(variables(f) for formulas in custom_formulas.values() for f in formulas))
    owners = {owner_of[name] for name in used if name in owner_of}
    items = [item for item in abstraction.items() if item in owners]
    sensors = [s for s in abstraction.sensors if s in used]
    return items, sensors


def _custom_specification(custom_ltl: Mapping[str, Sequence[str]] | None,
                          custom_formulas: dict[str, list[Formula]]) -> GR1Specification:
    if not custom_ltl:
        return GR1Specification()
    return GR1Specification(env_props=list(custom_ltl.get('env_props', [])),
                            sys_props=list(custom_ltl.get('sys_props', [])), **custom_formulas)


def _check_custom_scopes(spec: GR1Specification, custom_ltl: Mapping[str, Sequence[str]] | None) -> None:
    """Re-parse the custom formulas against the task's declarations and slugs' section rules."""
    if not custom_ltl:
        return
    sections = {'env_props': spec.env_props, 'sys_props': spec.sys_props}
    sections.update({s: list(custom_ltl[s]) for s in FORMULA_SECTIONS if s in custom_ltl})
    try:
        spec_from_text_sections(sections)
    except UnknownVariableError as error:
        raise UnknownPropositionError(
            f'custom LTL names unknown proposition {quoted(error.token)} ({error})'
            f'{did_you_mean(error.token, spec.propositions())}; '
            f'the task defines: {", ".join(spec.propositions())}', item=error.token) from error
    except ParseError as error:
        raise InvalidFormulaError(f'custom LTL: {error}', item=_custom_entry(custom_ltl, error)) from error


def _custom_entry(custom_ltl: Mapping[str, Sequence[str]], error: ParseError) -> str:
    """The custom formula (or name) a parse error is about: its filename is 'section[index]'."""
    match = re.fullmatch(r'(\w+)\[(\d+)\]', error.filename)
    if match and match[1] in custom_ltl and int(match[2]) < len(custom_ltl[match[1]]):
        return str(custom_ltl[match[1]][int(match[2])])
    return str(error.item)
