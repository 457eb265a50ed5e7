"""The generator's engine: automaton + FlexBE mapping -> the ``StateMachine`` tree
(``sm_generation.for_system.generate_state_machine`` is the front door that picks the mapping).

The tree, in the order of its StateInstantiation list (``to_instantiations``):

1. the root (``state_path='/'``, ``:STATEMACHINE``): ``initial_state_name`` is the first
   state to run, ``outcomes`` the machine's outcomes (e.g. ``finished``, ``failed``);
   its ``transitions`` repeat them (each outcome leaves as itself) and ``autonomy`` is 0;
2. one entry per state, breadth-first from the initial state (``/look_down``). A state
   with one part is that FlexBE state: ``outcomes`` are its configured outcomes that some
   observation maps to (in configuration order) and ``transitions`` the next state or
   machine outcome for each. A state with several parts is a ``:CONCURRENCY`` container
   (``/look_down_and_stand``) followed by its inner states (``/look_down_and_stand/stand``):
   one container outcome per observation, named after the outcome propositions it
   contains (``look_down_c__stand_c``; a sensor event is ``obj_detected_true``);
   ``cond_outcome[i]`` is returned when all inner outcomes of ``cond_transition[i]``
   have been returned (an outcome proposition mapped to
   several state outcomes gives one condition per combination, all with the same
   container outcome; conditions with more inner states come first, because FlexBE
   returns the first that holds). Inner states list the outcomes used in conditions and,
   as transition, the first container outcome each one takes part in;
3. one ``:OUTCOME`` entry per machine outcome (``/finished``), which only places it in
   the drawing (FlexBE 4.x editor).

Names come from the activated propositions without ``_a`` (sorted, joined with
``_and_``); repeated names get ``_1``, ``_2``, ... in breadth-first order.
"""

from __future__ import annotations

from typing import Callable

from respec.automaton import Automaton
from sm_generation.config import FlexBEConfig, StateConfig
from sm_generation.errors import SMGenerationError
from sm_generation.instantiation import DECISION_CLASS, NOTHING_CLASS, OutcomeCondition, StateInstantiation
from sm_generation.layout import inner_positions, layered_positions
from sm_generation.abstract_machine import (
    DECISION, NOTHING_TO_DO, AutomatonView, AbstractMachine, AbstractState, Observation, Target, build_machine)
from sm_generation.reduction import bisimulation_blocks, reduce_machine, target_class
from sm_generation.state_machine import State, StateMachine


NAME_SEPARATOR = '_and_'
CONDITION_SEPARATOR = '__'
SENSOR_EVENT_SUFFIX = '_true'
# The helper states' names (their classes: instantiation.DECISION_CLASS, NOTHING_CLASS).
DECISION_NAME = 'choose_initial_state'
DECISION_AUTONOMY = 3  # Full: the operator confirms where to start at every level up to Full
NOTHING_NAME = 'nothing_to_do'


def generate_from_config(automaton: Automaton, config: FlexBEConfig, initial_conditions: list[str] | None = None,
                         reduce: bool = False) -> StateMachine:
    """The FlexBE state machine implementing ``automaton`` with the FlexBE mapping ``config``.

    Initial state: the automaton's ``initial_states`` (kept only if they satisfy the
    ``initial_conditions``), or else the states that activate nothing, exit nothing and
    have the completion proposition of every initial condition true (with no initial
    conditions given, those nothing leads back to are preferred). Each is resolved to the
    first state that does something (or to a machine outcome). If they all behave the same
    (bisimilar) the first is used; otherwise an operator decision (``choose_initial_state``,
    flexbe_states' OperatorDecisionState) offers one start per behaviour. A start that is
    already an outcome gets a ``nothing_to_do`` LogState. ``reduce`` merges equivalent
    states. Raises ``SMGenerationError``.
    """
    view = AutomatonView(automaton, config)
    machine = machine_from_view(view, initial_conditions)
    for source, target in machine.dropped:
        import logging  # only here: the rare warning is not worth logging's import in every process
        logging.getLogger(__name__).warning(
            'automaton step %s -> %s changes the activations without any outcome or sensor event; '
            'FlexBE cannot take it, so it is left out', source, target)
    if reduce:
        machine = reduce_machine(machine)
    root = _instantiate(machine)
    root.input_keys = userdata_from_outside(machine)
    return root


def userdata_from_outside(machine: AbstractMachine) -> list[str]:
    """The keys the machine's states read and none of them writes: the root's input keys."""
    parts = [part for state in machine.states.values() for part in state.parts]
    written = {key for part in parts for key in part.writes}
    return sorted({key for part in parts for key in part.reads} - written)


def machine_from_view(view: AutomatonView, initial_conditions: list[str] | None) -> AbstractMachine:
    """The abstract machine, with a helper state when the start needs one."""
    starts = list(dict.fromkeys(view.resolve(name) for name in view.initial_candidates(initial_conditions)))
    if len(starts) > 1:
        # Starts that behave the same need no choice: keep the first of each kind.
        blocks = bisimulation_blocks(build_machine(view, starts))
        first_of_class: dict[tuple[str, int | str], Target] = {}
        for target in starts:
            first_of_class.setdefault(target_class(target, blocks), target)
        starts = list(first_of_class.values())
    if len(starts) == 1 and starts[0][0] == 'state':
        return build_machine(view, starts)
    machine = build_machine(view, starts)
    helper = DECISION if len(starts) > 1 else NOTHING_TO_DO
    transitions: list[tuple[Observation, Target]] = [((('', f'choice{index}'),), target)
                                                     for index, target in enumerate(starts)]
    start = AbstractState(key=f'<{helper}>', parts=(), transitions=transitions, helper=helper)
    machine.states = {start.key: start, **machine.states}
    machine.initial = start.key
    return machine


# --- naming -----------------------------------------------------------------------------

def _base_name(state: AbstractState) -> str:
    if state.helper == DECISION:
        return DECISION_NAME
    if state.helper == NOTHING_TO_DO:
        return NOTHING_NAME
    return NAME_SEPARATOR.join(part.label for part in state.parts)


def _assign_names(machine: AbstractMachine) -> dict[str, str]:
    bases = {key: _base_name(state) for key, state in machine.states.items()}
    counts: dict[str, int] = {}
    for base in bases.values():
        counts[base] = counts.get(base, 0) + 1
    taken = set(machine.outcomes)
    names: dict[str, str]
    next_index: dict[str, int]
    names, next_index, plain = {}, {}, set(bases.values())
    for key, base in bases.items():
        if counts[base] == 1 and base not in taken:
            name = base
        else:
            index = next_index.get(base, 1)
            while f'{base}_{index}' in taken or f'{base}_{index}' in plain:
                index += 1
            name = f'{base}_{index}'
            next_index[base] = index + 1
        taken.add(name)
        names[key] = name
    return names


# --- the tree's nodes -----------------------------------------------------------

def _instantiate(machine: AbstractMachine) -> StateMachine:
    """The tree of ``machine``: the root owns its states (a concurrency container its inner
    states) and the ``:OUTCOME`` entries placing its outcomes."""
    names = _assign_names(machine)

    def target_name(target: Target) -> str:
        kind, name = target
        return names[name] if kind == 'state' else name

    edges = {names[key]: [target_name(t) for _, t in state.transitions] for key, state in machine.states.items()}
    positions = layered_positions(edges, names[machine.initial], machine.outcomes)
    root = StateMachine(
        state_path='/', state_class=StateInstantiation.CLASS_STATEMACHINE,
        initial_state_name=names[machine.initial], outcomes=list(machine.outcomes),
        transitions=list(machine.outcomes), autonomy=[0] * len(machine.outcomes), position=[0.0, 0.0])
    states = []
    for key, state in machine.states.items():
        name = names[key]
        if state.helper:
            node = _helper_entry(state, name, target_name)
        elif len(state.parts) == 1:
            node = _single_entry(state, f'/{name}', target_name)
        else:
            node = _concurrency_container(state, name, target_name)
        node.position = positions[name]
        states.append(node)
    root.states = tuple(states)
    root.outcome_entries = tuple(State(state_path=f'/{outcome}', state_class=StateInstantiation.CLASS_OUTCOME,
                                       position=positions[outcome]) for outcome in machine.outcomes)
    return root


def _part_entry(part: StateConfig, path: str) -> State:
    return State(
        state_path=path, state_class=part.state_class, behavior_class=part.behavior_class,
        parameter_names=list(part.parameter_names), parameter_values=list(part.parameter_values),
        userdata_keys=list(part.userdata_keys), userdata_remapping=list(part.userdata_remapping))


def _single_entry(state: AbstractState, path: str, target_name: Callable[[Target], str]) -> State:
    part = state.parts[0]
    entry = _part_entry(part, path)
    by_proposition = {observation[0][1]: target for observation, target in state.transitions}
    for proposition, outcomes in part.output_mapping.items():
        if proposition in by_proposition:
            for outcome in outcomes:
                entry.outcomes.append(outcome)
                entry.transitions.append(target_name(by_proposition[proposition]))
                entry.autonomy.append(part.autonomy[outcome])
    return entry


def _concurrency_container(state: AbstractState, name: str, target_name: Callable[[Target], str]) -> StateMachine:
    parts = {part.proposition: part for part in state.parts}
    labels = _inner_labels(state.parts)
    container = StateMachine(state_path=f'/{name}', state_class=StateInstantiation.CLASS_CONCURRENCY)
    first_use: dict[tuple[str, str], str] = {}  # (inner state, outcome) -> first container outcome
    for observation, target in state.transitions:
        outcome_name = _container_outcome(observation)
        autonomy = 0
        for combination in _combinations([parts[p].output_mapping[prop] for p, prop in observation]):
            inner_names = [labels[p] for p, _ in observation]
            container.cond_outcome.append(outcome_name)
            container.cond_transition.append(OutcomeCondition(state_name=inner_names, state_outcome=list(combination)))
            for (p, _), outcome, label in zip(observation, combination, inner_names):
                autonomy = max(autonomy, parts[p].autonomy[outcome])
                first_use.setdefault((label, outcome), outcome_name)
        container.outcomes.append(outcome_name)
        container.transitions.append(target_name(target))
        container.autonomy.append(autonomy)
    keys = sorted({key for part in state.parts for key in part.userdata_remapping})
    container.input_keys, container.output_keys = list(keys), list(keys)
    container.initial_state_name = labels[state.parts[0].proposition]

    inner_states = []
    for part, position in zip(state.parts, inner_positions(len(state.parts))):
        inner = _part_entry(part, f'/{name}/{labels[part.proposition]}')
        inner.position = position
        for outcome in part.outcomes:
            if (labels[part.proposition], outcome) in first_use:
                inner.outcomes.append(outcome)
                inner.transitions.append(first_use[(labels[part.proposition], outcome)])
                inner.autonomy.append(part.autonomy[outcome])
        inner_states.append(inner)
    container.states = tuple(inner_states)
    return container


def _container_outcome(observation: Observation) -> str:
    """Container outcome of an observation: its outcome propositions, joined.

    A sensor event (observed as the pair (sensor, sensor)) is written ``<sensor>_true``,
    so that the outcome differs from the name of the sensor's inner state.
    """
    return CONDITION_SEPARATOR.join(f'{proposition}{SENSOR_EVENT_SUFFIX}' if part == proposition else proposition
                                    for part, proposition in observation)


def _inner_labels(parts: tuple[StateConfig, ...]) -> dict[str, str]:
    labels = {part.proposition: part.label for part in parts}
    if len(set(labels.values())) < len(labels):  # e.g. sensor 'x' next to activation 'x_a'
        labels = {part.proposition: part.proposition for part in parts}
    return labels


def _combinations(choices: list[tuple[str, ...]]) -> list[tuple[str, ...]]:
    result: list[tuple[str, ...]] = [()]
    for options in choices:
        result = [(*prefix, option) for prefix in result for option in options]
    return result


def _helper_entry(state: AbstractState, name: str, target_name: Callable[[Target], str]) -> State:
    targets = [target_name(target) for _, target in state.transitions]
    if state.helper == DECISION:
        return State(
            state_path=f'/{name}', state_class=DECISION_CLASS,
            parameter_names=['outcomes', 'hint', 'suggestion'],
            # The first start is suggested: an operator at any level up to Full confirms it or
            # picks another (FlexBE waits on a transition whose autonomy is not below the level);
            # unattended runs (FlexBE's level 255, our executive without an operator) take it.
            parameter_values=[repr(targets), '"Several initial states are possible: choose where to start"',
                              repr(targets[0])],
            outcomes=list(targets), transitions=list(targets), autonomy=[DECISION_AUTONOMY] * len(targets))
    if state.helper == NOTHING_TO_DO:
        return State(
            state_path=f'/{name}', state_class=NOTHING_CLASS, parameter_names=['text', 'severity'],
            parameter_values=[f'"Nothing to do: the task ends with {targets[0]}"', 'Logger.REPORT_HINT'],
            outcomes=['done'], transitions=targets[:1], autonomy=[0])
    raise SMGenerationError(f'unknown helper state {state.helper!r}', name)
