"""A small FlexBE-compatible executive that runs synthesized state machines on a robot (ROS-free).

Input: a StateInstantiation list as returned by ``/behavior_synthesis`` (dicts of the 16
fields, or ``sm_generation.StateInstantiation`` objects). Semantics (FlexBE's):

* the root (``state_path='/'``, ``:STATEMACHINE``) starts at ``initial_state_name`` and
  ends when a transition names one of its ``outcomes`` (``:OUTCOME`` entries only place
  those outcomes in the editor's drawing);
* a state returning ``outcomes[i]`` continues with ``transitions[i]``;
* a ``:CONCURRENCY`` container starts all its children (``/<container>/<child>``) together
  and returns ``cond_outcome[k]`` as soon as ``cond_transition[k]`` holds (every named
  child has returned the named outcome; the first condition that holds wins);
* a state (class + parameter values, or ``:BEHAVIOR`` + behavior_class) is identified
  through the system config's ``flexbe.states`` section: activation proposition ``<p>_a``
  -> capability ``<p>`` of the robot; the capability's result ``completed``/``failed``
  becomes the first state outcome listed under ``<p>_c``/``<p>_f`` in ``output_mapping``.
  Sensor states return their outcome when the sensor turns true. The generator's helper
  states (``LogState``: returns at once; ``OperatorDecisionState``: the ``decide`` hook or
  its first outcome) take no robot time.

With ``control`` (:class:`atlas_sim.executive.runtime_control.RuntimeControl`) an operator is in
the loop as in FlexBE's Runtime Control: a transition whose required autonomy (the state's
``autonomy`` for the outcome) is not below the control's level waits for the operator's
confirmation; the operator may force any outcome of the active state (or of one of its
children) at any time, pause, resume and stop; an ``InputState`` asks the operator, with the
robot's own answer (``robot.input_default(capability)``) offered, and the answer reaches the
robot through ``robot.give_input(capability, value)``. The robot is not stepped while the
executive waits for the operator, so robot time stands still. Without ``control`` the run is
unattended, as before.

Activation–outcome semantics on the robot: a capability activated by a state that is
still running from the previous state (a concurrency container returned before all its
children did) keeps running, as its activation proposition stays true; a running request
that the next state does not activate is abandoned (the robot cannot cancel it) and
whatever it still reports is recorded, so the trace check sees it.

The robot is anything with the :class:`atlas_sim.executive.robot.Robot` protocol: ``SimulatedRobot`` drives
an ``AtlasSimulator`` directly; ``synthesis_manager.ros.atlas_sim_robot.RosRobot`` drives the
simulator node. The machine is the tree of :mod:`sm_generation.state_machine`, as generated (or
as a message's list became it where it arrived).

    atlas = robot_system('atlas')
    sim = make_simulator(atlas, initial_conditions=['stand_prep'])
    run = execute_state_machine(machine, SimulatedRobot(sim), atlas)
    run.outcome, run.trace                  # 'finished', Trace (see atlas_sim.executive.trace_check)
"""

from __future__ import annotations

import ast
import re
import time
from dataclasses import dataclass, field
from typing import Any, Callable

from atlas_sim.executive.errors import ExecutionError, UndeclaredOutcomeError, next_target
from atlas_sim.executive.robot import CapabilityResult, Robot
from atlas_sim.executive.runtime_control import RuntimeControl
from atlas_sim.executive.trace_check import OutcomeTracker, Trace, TraceStep
from respec.vocabulary.errors import ErrorCode
from respec.vocabulary.naming import activated, is_activation, outcome_proposition
from respec.robot import RobotSystem
from sm_generation.config import INPUT_STATE_CLASS, flexbe_config
from sm_generation.instantiation import DECISION_CLASS, HELPER_STATE_CLASSES, StateInstantiation
from sm_generation.state_machine import State, StateMachine

BEHAVIOR = StateInstantiation.CLASS_BEHAVIOR

# --- errors -----------------------------------------------------------------------------------

class UnmappedStateError(ExecutionError):
    """A state whose class/parameters match no entry of the system's ``flexbe.states``."""

    code = ErrorCode.CONFIG_VARIABLE_CONFIG_INVALID


class ExecutionLimitError(ExecutionError):
    """The run reached its robot-time or state-count limit without an SM outcome."""

    code = ErrorCode.TIMEOUT


# --- mapping states to capabilities ---------------------------------------------------------------

@dataclass(frozen=True)
class Part:
    """A primitive state being run: on the robot (capability), a sensor, or a helper."""

    node: State
    kind: str                      # 'capability', 'sensor', 'helper'
    proposition: str = ''          # activation proposition or sensor name
    output_mapping: dict | None = None

    @property
    def capability(self) -> str:
        return (activated(self.proposition) or '') if self.kind == 'capability' else ''


class StateMapping:
    """State class + parameter values (or behavior class) -> ``flexbe.states`` entry."""

    def __init__(self, system: RobotSystem):
        self.flexbe = flexbe_config(system)
        abstraction = system.required_abstraction()
        self.control_modes = list(abstraction.control_modes)
        self.sensors = list(abstraction.sensors)
        self._by_key: dict[tuple, Any] = {}
        for state in self.flexbe.states.values():
            self._by_key.setdefault(self._key(state.state_class, state.behavior_class, state.parameter_values),
                                    []).append(state)

    @staticmethod
    def _key(state_class, behavior_class, parameter_values) -> tuple:
        if state_class == BEHAVIOR:
            return (BEHAVIOR, behavior_class)
        return (state_class, tuple(parameter_values))

    def part(self, node: State) -> Part:
        if node.state_class in HELPER_STATE_CLASSES:
            return Part(node, 'helper')
        matches = self._by_key.get(self._key(node.state_class, node.behavior_class, node.parameter_values), [])
        if len(matches) > 1:  # same class and parameters: the state's name ('stand_2') says which
            label = re.sub(r'_\d+$', '', node.name)
            matches = [s for s in matches if s.label in (node.name, label)] or matches[:1]
        if not matches:
            what = node.behavior_class if node.state_class == BEHAVIOR else \
                f'{node.state_class}({", ".join(node.parameter_values)})'
            raise UnmappedStateError(f'state {node.state_path!r} ({what}) matches no entry of flexbe.states of '
                                     f'{self.flexbe.system!r}', item=node.state_path)
        config = matches[0]
        kind = 'capability' if is_activation(config.proposition) else 'sensor'
        return Part(node, kind, config.proposition, dict(config.output_mapping))

    def sm_outcome_propositions(self) -> dict[str, str]:
        """SM outcome -> its proposition (inverse of ``flexbe.sm_outcomes``)."""
        return {outcome: prop for prop, outcome in self.flexbe.sm_outcomes.items()}


# --- running ------------------------------------------------------------------------------------

@dataclass
class ExecutionResult:
    outcome: str | None          # None while a run watched on FlexBE's engine goes on (engine_trace)
    trace: Trace
    robot_time: float            # robot clock at the end
    min_pelvis_height: float
    fallen: bool
    ticks: int
    robot_started_at: float = 0.0  # robot clock at the start
    operator_events: list = field(default_factory=list)  # the operator's commands (RuntimeControl)

    @property
    def duration(self) -> float:
        """Robot time the run took."""
        return self.robot_time - self.robot_started_at

    def to_dict(self) -> dict:
        return {'outcome': self.outcome, 'trace': self.trace.to_dict(), 'robot_time': round(self.robot_time, 4),
                'robot_started_at': round(self.robot_started_at, 4),
                'min_pelvis_height': round(self.min_pelvis_height, 4), 'fallen': self.fallen,
                'ticks': self.ticks, **({'operator_events': self.operator_events} if self.operator_events else {})}


def entered_step(trace: Trace, state: State, parts: list[Part], snapshot: dict,
                 tracker: OutcomeTracker) -> TraceStep:
    """Append the step of top-level ``state`` (run as ``parts``) entered now to ``trace``."""
    step = TraceStep(index=len(trace.steps), state=state.state_path, state_class=state.state_class,
                     activated=sorted(p.proposition for p in parts if p.kind == 'capability'),
                     capabilities=[p.capability for p in parts if p.kind == 'capability'],
                     entered_at=snapshot['time'], mode_at_entry=snapshot['mode'],
                     outcomes_at_entry=tracker.true_propositions())
    trace.steps.append(step)
    return step


def record_forced(step: TraceStep, path: str, outcome: str, parts) -> None:
    """Note on ``step`` the outcome the operator forced on ``path`` (the state or one of its
    children) and the outcome propositions that outcome stands for (trace_check reads them as
    reported)."""
    step.forced = outcome if path == step.state else f'{outcome} (on {path})'
    step.forced_propositions = sorted({
        proposition for part in parts if part.node.state_path == path or path == step.state and len(parts) == 1
        for proposition, outcomes in (part.output_mapping or {}).items() if outcome in outcomes})


@dataclass
class _Running:
    """A started request of the robot and what has been seen of it."""

    capability: str
    handle: Any
    result: CapabilityResult | None = None
    abandoned: bool = False


class Executive:
    """Runs one state machine on one robot; see :func:`execute_state_machine`."""

    def __init__(self, machine: StateMachine, robot: Robot, mapping: StateMapping, max_robot_time: float = 600.0,
                 max_states: int = 500, max_wall_time: float | None = None,
                 decide: Callable[[str, list[str]], str] | None = None,
                 on_tick: Callable[[Robot], None] | None = None, control: RuntimeControl | None = None):
        self.root = machine
        self.robot, self.mapping = robot, mapping
        self.max_robot_time, self.max_states = max_robot_time, max_states
        self.wall_deadline = None if max_wall_time is None else time.monotonic() + max_wall_time
        self.decide = decide or (lambda path, outcomes: outcomes[0])
        self.on_tick = on_tick
        self.control = control
        self.parts = {node.state_path: mapping.part(node) for state in self.root.states
                      for node in (state.states or (state,))}
        self.trace = Trace(sm_outcome_propositions=mapping.sm_outcome_propositions())
        self.running: dict[str, _Running] = {}   # capability -> latest request
        self.abandoned: list[_Running] = []
        self.ticks = 0
        snapshot = robot.snapshot()
        self.start_time = snapshot['time']
        self.min_pelvis = snapshot.get('pelvis_height', float('nan'))
        self.fallen = bool(snapshot.get('fallen', False))
        self.tracker = OutcomeTracker(mapping.control_modes, snapshot['mode'],
                                      snapshot.get('completed_actions', []), snapshot.get('sensors', {}))

    def run(self) -> ExecutionResult:
        try:
            return self._run()
        except ExecutionError as error:
            error.trace = error.trace or self.trace  # what ran until then
            raise

    def _run(self) -> ExecutionResult:
        states = {child.name: child for child in self.root.states}
        current = states[self.root.initial_state_name]
        while True:
            if len(self.trace.steps) >= self.max_states:
                raise ExecutionLimitError(f'no SM outcome after {self.max_states} states', item=current.state_path,
                                          trace=self.trace)
            state_outcome = self._run_state(current)
            target = next_target(current, state_outcome)
            self.trace.steps[-1].state_outcome, self.trace.steps[-1].transition = state_outcome, target
            if target in self.root.outcomes:
                self.trace.outcome = target
                snapshot = self.robot.snapshot()
                return ExecutionResult(target, self.trace, snapshot['time'], self.min_pelvis,
                                       self.fallen or bool(snapshot.get('fallen')), self.ticks, self.start_time,
                                       list(self.control.events) if self.control else [])
            current = states[target]

    # one top-level state ------------------------------------------------------------------------

    def _run_state(self, state: State) -> str:
        parts = [self.parts[node.state_path] for node in (state.states or (state,))]
        step = entered_step(self.trace, state, parts, self.robot.snapshot(), self.tracker)
        if self.control:
            self._ask_inputs(parts)
        self._activate(step.capabilities)
        sensors_at_entry = dict(self.tracker.sensors)
        returned: dict[str, str] = {}          # part path -> state outcome returned
        outcome: str | None
        while True:
            forced = self._forced(state, parts)
            if forced is not None:
                path, forced_outcome = forced
                record_forced(step, path, forced_outcome, parts)
                if path == state.state_path:
                    outcome = forced_outcome
                    break
                returned[path] = forced_outcome
            for part in parts:
                if part.node.state_path not in returned:
                    outcome = self._returned(part, sensors_at_entry)
                    if outcome is not None:
                        returned[part.node.state_path] = outcome
            outcome = self._state_outcome(state, returned)
            if outcome is not None:
                chosen = self._confirmed(state, outcome)
                if chosen != outcome:  # the operator forced another outcome at the waiting transition
                    record_forced(step, state.state_path, chosen, parts)
                outcome = chosen
                break
            self._tick(step)
        snapshot = self.robot.snapshot()
        step.ended_at, step.mode_at_exit = snapshot['time'], snapshot['mode']
        step.outcomes_at_exit = self.tracker.true_propositions()
        return outcome

    # the operator (RuntimeControl) -------------------------------------------------------------

    def _forced(self, state: State, parts: list[Part]) -> tuple[str, str] | None:
        """Between robot steps: the operator's commands (pause holds here, stop raises) and an
        outcome forced for ``state`` or one of its children, if one of theirs."""
        if not self.control:
            return None
        self.control.between_ticks(state.state_path, self.wall_deadline)  # run() adds the trace to errors
        nodes = {node.state_path: node for node in (state, *(p.node for p in parts))}
        forced = self.control.take_forced(nodes)
        if forced is not None and forced[1] not in nodes[forced[0]].outcomes:
            self.control.events.append({'command': 'refused', 'reason': f'{forced[1]!r} is no outcome of '
                                                                        f'{forced[0]!r}'})
            return None
        return forced

    def _confirmed(self, state: State, outcome: str) -> str:
        """``outcome``, or what the operator chose instead, once its transition may be taken."""
        if not self.control:
            return outcome
        index = state.outcomes.index(outcome) if outcome in state.outcomes else -1
        required = state.autonomy[index] if 0 <= index < len(state.autonomy) else 0
        chosen = self.control.confirm(state.state_path, outcome, required, list(state.outcomes), self.wall_deadline)
        assert chosen is not None  # without ``until`` the wait ends only with an outcome
        return chosen

    def _ask_inputs(self, parts: list[Part]) -> None:
        """Ask the operator for the data of each InputState among ``parts`` before they start."""
        assert self.control is not None  # asked only with an operator (_run_state)
        for part in parts:
            if part.kind != 'capability' or part.node.state_class != INPUT_STATE_CLASS:
                continue
            if part.capability in self.running and self.running[part.capability].result is None:
                continue  # still running from the previous state: already answered
            default_of = getattr(self.robot, 'input_default', None)
            default = default_of(part.capability) if default_of else None
            value = self.control.ask_input(part.node.state_path, input_prompt(part.node), default, self.wall_deadline)
            give = getattr(self.robot, 'give_input', None)
            if give:
                give(part.capability, value)

    def _activate(self, capabilities: list[str]) -> None:
        """Start the state's capabilities, keeping those still running from the previous state."""
        still_running = {c for c, r in self.running.items() if r.result is None}
        for capability in list(self.running):
            if capability not in capabilities:
                request = self.running.pop(capability)
                if request.result is None:  # cannot be cancelled: watch what it still reports
                    request.abandoned = True
                    self.abandoned.append(request)
        fresh = [c for c in capabilities if c not in still_running]
        self.tracker.activate(fresh)
        for capability, handle in zip(fresh, self.robot.start_concurrently(fresh) if fresh else []):
            self.running[capability] = _Running(capability, handle)
        self._collect_results(self.trace.steps[-1])  # refusals finish at once

    def _returned(self, part: Part, sensors_at_entry: dict) -> str | None:
        if part.kind == 'helper':
            if part.node.state_class == DECISION_CLASS:
                return self.decide(part.node.state_path, list(part.node.outcomes))
            return part.node.outcomes[0] if part.node.outcomes else None
        assert part.output_mapping is not None  # a sensor's and a capability's part have one
        if part.kind == 'sensor':  # sensors are events: the reading turns true
            if self.tracker.sensors.get(part.proposition) and not sensors_at_entry.get(part.proposition):
                return part.output_mapping[part.proposition][0]
            return None
        result = self.running[part.capability].result
        if result is None:
            return None
        proposition = outcome_proposition(part.capability, result.outcome)
        outcomes = part.output_mapping.get(proposition)
        if not outcomes:
            raise UndeclaredOutcomeError(f'state {part.node.state_path!r} has no outcome for {proposition!r} in '
                                         'flexbe.states', item=part.node.state_path, trace=self.trace)
        if outcomes[0] not in part.node.outcomes:
            raise UndeclaredOutcomeError(
                f'state {part.node.state_path!r} returned {outcomes[0]!r} ({proposition}: {result.reason}), which '
                f'is not one of its outcomes {part.node.outcomes}', item=part.node.state_path, trace=self.trace)
        return outcomes[0]

    @staticmethod
    def _state_outcome(state: State, returned: dict[str, str]) -> str | None:
        if state.state_class != StateInstantiation.CLASS_CONCURRENCY:
            return returned.get(state.state_path)
        assert isinstance(state, StateMachine)  # a concurrency container
        by_name = {path.rsplit('/', 1)[-1]: outcome for path, outcome in returned.items()}
        for outcome, condition in state.conditions:  # FlexBE returns the first that holds
            if all(by_name.get(name) == wanted for name, wanted in condition):
                return outcome
        return None

    def _tick(self, step: TraceStep) -> None:
        self.robot.step()
        self.ticks += 1
        snapshot = self.robot.snapshot()
        self.min_pelvis = min(self.min_pelvis, snapshot.get('pelvis_height', self.min_pelvis))
        self.fallen |= bool(snapshot.get('fallen', False))
        self.tracker.read_sensors(snapshot.get('sensors', {}))
        self._collect_results(step)
        if self.on_tick:
            self.on_tick(self.robot)
        if snapshot['time'] - self.start_time > self.max_robot_time:
            raise ExecutionLimitError(f'no SM outcome after {self.max_robot_time:g} s of robot time '
                                      f'(state {step.state!r} still running)', item=step.state, trace=self.trace)
        if self.wall_deadline is not None and time.monotonic() > self.wall_deadline:
            raise ExecutionLimitError(f'no SM outcome within the wall-clock limit (state {step.state!r} still '
                                      'running; is the robot alive?)', item=step.state, trace=self.trace)

    def _collect_results(self, step: TraceStep) -> None:
        for request in [*self.running.values(), *self.abandoned]:
            if request.result is not None:
                continue
            request.result = self.robot.result(request.handle)
            if request.result is not None:
                self.tracker.report(request.capability, request.result.outcome)
                step.results.append({'capability': request.capability, 'outcome': request.result.outcome,
                                     'reason': request.result.reason, 'time': request.result.time,
                                     'abandoned': request.abandoned})
        self.abandoned = [r for r in self.abandoned if r.result is None]


def input_prompt(node: State) -> str:
    """What an InputState asks: its ``message`` parameter (a Python literal), or its name."""
    if 'message' in node.parameter_names:
        text = node.parameter_values[node.parameter_names.index('message')]
        try:
            value = ast.literal_eval(text)
        except (ValueError, SyntaxError):
            value = text
        return str(value)
    return node.name


def execute_state_machine(machine: StateMachine, robot: Robot, system: RobotSystem, **options) -> ExecutionResult:
    """Run ``machine`` on ``robot`` until an SM outcome; returns the outcome and the trace.

    ``system`` is the RobotSystem ``machine`` was generated for (its FlexBE mapping).

    ``options``: ``max_robot_time`` (s, default 600), ``max_states`` (default 500),
    ``max_wall_time`` (s, default none),
    ``decide(path, outcomes) -> outcome`` for operator decisions, ``on_tick(robot)``,
    ``control`` (a :class:`RuntimeControl`: the operator in the loop).
    Raises :class:`ExecutionError` subclasses (with ``item`` and the partial ``trace``).
    """
    return Executive(machine, robot, StateMapping(system), **options).run()


__all__ = ['execute_state_machine', 'Executive', 'ExecutionResult', 'StateMapping', 'UnmappedStateError',
           'ExecutionLimitError']
