"""From a synthesized automaton to the ``AbstractMachine``: the automaton-shaped intermediate of
generation, FlexBE states and their observed transitions before names, paths and layout (the
generator turns it into the ``StateMachine`` tree).

Semantics (the activation–outcomes paradigm, paper Sec. IV–V):

* An automaton state *activates* the activation propositions that are true in it; each
  has a configured FlexBE state (a *part*). One part gives a plain state, several a
  concurrency container.
* A successor ``T`` of ``S`` is *observed* through an **observation**: for every part
  activated in ``S``, the outcome proposition of that part that is true in ``T`` (at most
  one), plus every configured sensor that turns true from ``S`` to ``T`` (sensors are
  events, their states are added as extra parts). Each distinct observation becomes one
  outcome of the FlexBE state; two successors with the same observation cannot be told
  apart by FlexBE, so the first one in the automaton's transition order wins.
* A successor with an empty observation is a *silent* step: no FlexBE state has returned.
  If it keeps the same activations (a "stay", including self-loops), the FlexBE state
  simply keeps running, so its observations are collected too (after the direct ones).
  A silent step that changes the activations cannot be triggered by FlexBE and is dropped
  (listed in ``AbstractMachine.dropped``).
* A state where an SM-outcome proposition (``finished``/``failed``) is true is an exit:
  transitions into it go to that outcome of the machine.
* A state that activates nothing is *passed through*: transitions into it go to the first
  activating (or exit) state reachable from it by silent steps (breadth-first, in
  transition order). If there is none but sensors lead on, it becomes a state that waits
  for those sensors; if nothing leads on, the automaton is invalid.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field

from respec.automaton import AutomatonState
from respec.vocabulary.errors import quoted
from respec.vocabulary.naming import activation, is_memory
from sm_generation.config import FlexBEConfig, StateConfig
from sm_generation.errors import (AutomatonInvalidError, InitialConditionsInvalidError, InputValuationInvalidError,
                                  NextStateInvalidError, NoInitialStateError, OutputValuationInvalidError,
                                  StateConfigInvalidError)


# An observation: sorted pairs (proposition of a part, outcome proposition seen).
Observation = tuple[tuple[str, str], ...]
# Where a transition goes: ('state', key) or ('outcome', machine outcome name).
Target = tuple[str, str]

# Helper states that are not in the automaton (FlexBE's generic flexbe_states).
DECISION = 'decision'
NOTHING_TO_DO = 'nothing_to_do'


@dataclass
class AbstractState:
    """One state of the abstract machine; ``key`` is the automaton state it stands for."""

    key: str
    parts: tuple[StateConfig, ...]
    transitions: list[tuple[Observation, Target]] = field(default_factory=list)
    helper: str = ''  # '' for automaton states, else DECISION or NOTHING_TO_DO


@dataclass
class AbstractMachine:
    """States in breadth-first order from ``initial``; ``outcomes`` of the whole machine."""

    states: dict[str, AbstractState]
    initial: str
    outcomes: list[str]
    dropped: list[tuple[str, str]] = field(default_factory=list)  # silent steps FlexBE cannot take


class AutomatonView:
    """A validated automaton read through a system's FlexBE configuration."""

    def __init__(self, automaton: object, config: FlexBEConfig) -> None:
        self.config = config
        self.output_variables = _variables(automaton, 'output_variables')
        self.input_variables = _variables(automaton, 'input_variables')
        self.states = _states(automaton, len(self.output_variables), len(self.input_variables))
        self.initial_states = [str(n) for n in (getattr(automaton, 'initial_states', None) or [])]
        for name in self.initial_states:
            if name not in self.states:
                raise AutomatonInvalidError(f'initial state {quoted(name)} is not a state', name)
        self._classify_variables()
        self.activations = {name: self._true_activations(state) for name, state in self.states.items()}
        self.exits = {name: self._exit_outcome(state) for name, state in self.states.items()}
        self._inputs = {name: dict(zip(self.input_variables, state.input_valuation))
                        for name, state in self.states.items()}
        self._observed: dict[str, list[tuple[Observation, str]]] = {}
        self.dropped: list[tuple[str, str]] = []

    # --- variables and valuations -----------------------------------------------------

    def _classify_variables(self) -> None:
        config = self.config
        self.sm_outcome_props = [v for v in self.output_variables if v in config.sm_outcomes]
        self.activation_props = [v for v in self.output_variables if v in config.states]
        self.sensor_props = [v for v in self.input_variables if v in config.states]
        for index, prop in enumerate(self.output_variables):
            if prop in config.sm_outcomes or prop in config.states or is_memory(prop):
                continue
            if any(state.output_valuation[index] for state in self.states.values()):
                raise StateConfigInvalidError(f'output proposition {prop!r} is activated by the automaton but has '
                                              f'no entry in flexbe.states of system {config.system!r}', prop)
        for index, prop in enumerate(self.input_variables):
            if prop in config.states or config.owner_of_outcome(prop) is not None:
                continue
            # Nothing in FlexBE reports it: harmless while it never changes, wrong otherwise.
            if any(state.input_valuation[index] != self.states[successor].input_valuation[index]
                   for state in self.states.values() for successor in state.transitions):
                raise StateConfigInvalidError(f'input proposition {prop!r} changes in the automaton but no state in '
                                              f'flexbe.states of system {config.system!r} reports it', prop)

    def _true_activations(self, state: _State) -> tuple[str, ...]:
        true = {v for v, value in zip(self.output_variables, state.output_valuation) if value}
        return tuple(sorted((p for p in self.activation_props if p in true),
                            key=lambda p: self.config.states[p].label))

    def _exit_outcome(self, state: _State) -> str | None:
        true = [p for p, value in zip(self.output_variables, state.output_valuation)
                if value and p in self.config.sm_outcomes]
        if len(true) > 1:
            raise AutomatonInvalidError(f'state {state.name!r} sets several SM '
                                        f'outcomes at once: {", ".join(true)}', state.name)
        return self.config.sm_outcomes[true[0]] if true else None

    def inputs(self, name: str) -> dict[str, bool]:
        return self._inputs[name]

    def machine_outcomes(self) -> list[str]:
        """Outcomes of the machine: those whose propositions the automaton has, else all."""
        props = self.sm_outcome_props or list(self.config.sm_outcomes)
        return list(dict.fromkeys(self.config.sm_outcomes[p] for p in props))

    # --- observations -------------------------------------------------------------------

    def observation(self, activations: tuple[str, ...], source: str, target: str) -> Observation:
        """What FlexBE sees when the automaton moves from ``source`` to ``target``."""
        now, before = self.inputs(target), self.inputs(source)
        pairs: list[tuple[str, str]] = []
        for active in activations:
            seen = [p for p in self.config.states[active].output_mapping if now.get(p)]
            if len(seen) > 1:
                raise InputValuationInvalidError(f'state {target!r} reports several outcomes of {active!r} '
                                                 f'at once: {", ".join(seen)}', target)
            pairs.extend((active, p) for p in seen)
        for sensor in self.sensor_props:
            if now[sensor] and not before[sensor]:
                pairs.append((sensor, sensor))
        return tuple(sorted(pairs))

    def observed_transitions(self, name: str) -> list[tuple[Observation, str]]:
        """Observed transitions of the FlexBE state for automaton state ``name``.

        Silent steps that keep the activations are followed (the FlexBE state keeps
        running), breadth-first; the first successor seen for an observation wins.
        """
        if name not in self._observed:
            self._observed[name] = self._collect_observed_transitions(name)
        return self._observed[name]

    def _collect_observed_transitions(self, name: str) -> list[tuple[Observation, str]]:
        activations = self.activations[name]
        found: dict[Observation, str] = {}
        queue, seen = deque([name]), {name}
        while queue:
            current = queue.popleft()
            for successor in self.states[current].transitions:
                observation = self.observation(activations, current, successor)
                if observation:
                    found.setdefault(observation, successor)
                elif self.keeps_running(name, successor):
                    if successor not in seen:
                        seen.add(successor)
                        queue.append(successor)
                elif (current, successor) not in self.dropped:
                    self.dropped.append((current, successor))
        return sorted(found.items(), key=lambda item: (-len(item[0]), item[0]))

    def keeps_running(self, name: str, other: str) -> bool:
        """Whether ``other`` continues the FlexBE state of ``name`` (same activations, no exit)."""
        return self.exits[other] is None and self.activations[other] == self.activations[name]

    # --- where a transition into a state leads --------------------------------------------

    def resolve(self, name: str) -> Target:
        """The machine target standing for automaton state ``name`` (see module doc)."""
        outcome = self.exits[name]
        if outcome is not None:
            return ('outcome', outcome)
        if self.activations[name]:
            return ('state', name)
        exit_state = self._first_silent_exit(name)
        if exit_state is not None:
            return self.resolve(exit_state)
        if self.observed_transitions(name):
            return ('state', name)  # waits for its sensors
        raise AutomatonInvalidError(f'state {name!r} activates nothing and no '
                                    'outcome or sensor ever leads out of it', name)

    def _first_silent_exit(self, name: str) -> str | None:
        queue, seen = deque([name]), {name}
        while queue:
            current = queue.popleft()
            for successor in self.states[current].transitions:
                if successor in seen or self.observation((), current, successor):
                    continue
                if self.exits[successor] is not None or self.activations[successor]:
                    return successor
                seen.add(successor)
                queue.append(successor)
        return None

    def parts(self, name: str, transitions: list[tuple[Observation, Target]]) -> tuple[StateConfig, ...]:
        """Activated states, then the sensor states some observation of them mentions."""
        sensors = sorted({part for observation, _ in transitions for part, _ in observation
                          if part in self.sensor_props})
        return tuple(self.config.states[p] for p in (*self.activations[name], *sensors))

    # --- initial states -----------------------------------------------------------------

    def initial_candidates(self, initial_conditions: list[str] | None) -> list[str]:
        """Automaton states the behaviour may start in (see ``generate_state_machine``)."""
        required = self._initial_condition_props(initial_conditions or [])
        if self.initial_states:
            pool = list(self.initial_states)
        else:
            pool = [n for n in self.states if not self.activations[n] and self.exits[n] is None]
        candidates = [n for n in pool if all(self.inputs(n)[p] for p in required)]
        if not self.initial_states and initial_conditions is None:
            # Without any hint, prefer states nothing leads back to (the start of a run).
            entered = {t for name, state in self.states.items() for t in state.transitions if t != name}
            unentered = [n for n in candidates if n not in entered]
            candidates = unentered or candidates
        if not candidates:
            detail = f' with {", ".join(required)} true' if required else ''
            raise NoInitialStateError(f'no initial state{detail}: give Automaton.initial_states or a state '
                                      'that activates nothing', ','.join(initial_conditions or []))
        return candidates

    def _initial_condition_props(self, initial_conditions: list[str]) -> list[str]:
        """Completion propositions of the initial conditions (names or propositions).

        A configured action or mode is given by name (``stand_prep``: its first
        ``output_mapping`` proposition, ``stand_prep_c``, means completion). One the
        automaton does not mention (the compiler left it out as irrelevant) cannot narrow
        the start and is skipped; a name the system does not know is an error.
        """
        props = []
        for condition in initial_conditions:
            if condition in self.input_variables:
                props.append(condition)
                continue
            state = self.config.states.get(activation(condition)) or self.config.states.get(condition)
            if state is None:
                raise InitialConditionsInvalidError(
                    f'initial condition {quoted(condition)} is neither a proposition of this automaton nor a state '
                    f'of system {self.config.system!r}', condition)
            completion = next(iter(state.output_mapping))
            if completion in self.input_variables:
                props.append(completion)
        return props


def _variables(automaton: object, attribute: str) -> list[str]:
    values = getattr(automaton, attribute, None)
    if not isinstance(values, (list, tuple)) or not all(isinstance(v, str) for v in values):
        raise AutomatonInvalidError(f'automaton.{attribute} must be a list of names',
                                    attribute)
    duplicates = sorted({v for v in values if list(values).count(v) > 1})
    if duplicates:
        raise AutomatonInvalidError(f'{attribute} lists {duplicates[0]!r} twice',
                                    duplicates[0])
    return list(values)


def _states(automaton: object, n_outputs: int, n_inputs: int) -> dict[str, _State]:
    states = getattr(automaton, 'states', None)
    if not states:
        raise AutomatonInvalidError('the automaton has no states', 'states')
    by_name = {}
    for state in states:
        name = str(state.name)
        if name in by_name:
            raise AutomatonInvalidError(f'two states are named {name!r}', name)
        for valuation, expected, error in ((state.output_valuation, n_outputs, OutputValuationInvalidError),
                                           (state.input_valuation, n_inputs, InputValuationInvalidError)):
            if len(valuation) != expected or not all(v in (0, 1) for v in valuation):
                raise error(f'state {name!r}: expected {expected} truth values, got {list(valuation)!r}', name)
        by_name[name] = state
    for name, state in by_name.items():
        for successor in state.transitions:
            if str(successor) not in by_name:
                raise NextStateInvalidError(f'state {name!r} has a transition to unknown state {successor!r}',
                                            str(successor))
    return {name: _normalized(state, name) for name, state in by_name.items()}


@dataclass(frozen=True)
class _State:
    name: str
    output_valuation: tuple[bool, ...]
    input_valuation: tuple[bool, ...]
    transitions: tuple[str, ...]


def _normalized(state: AutomatonState, name: str) -> _State:
    # Names may be ints in hand-written files; valuations may be 0/1.
    return _State(name, tuple(bool(v) for v in state.output_valuation),
                  tuple(bool(v) for v in state.input_valuation),
                  tuple(dict.fromkeys(str(t) for t in state.transitions)))


def build_machine(view: AutomatonView, start: list[Target]) -> AbstractMachine:
    """The machine reachable from ``start`` targets (breadth-first, transition order)."""
    states: dict[str, AbstractState] = {}
    queue = deque(key for kind, key in start if kind == 'state')
    while queue:
        key = queue.popleft()
        if key in states:
            continue
        transitions = [(observation, view.resolve(successor))
                       for observation, successor in view.observed_transitions(key)]
        states[key] = AbstractState(key=key, parts=view.parts(key, transitions), transitions=transitions)
        queue.extend(target for kind, target in (t for _, t in transitions) if kind == 'state')
    first = next((key for kind, key in start if kind == 'state'), '')
    return AbstractMachine(states=states, initial=first, outcomes=view.machine_outcomes(), dropped=view.dropped)
