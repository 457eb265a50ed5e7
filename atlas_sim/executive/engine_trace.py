"""The trace of a run on another engine (the real FlexBE), from what the simulator saw (ROS-free).

When FlexBE's engine runs a synthesized behavior, its states drive the simulator node and
our executive is not involved; to check the run against the specification
(:func:`atlas_sim.executive.trace_check.check_trace`) the same :class:`~atlas_sim.executive.trace_check.Trace`
is built from two event streams:

* the engine's top-level states: the runner calls :meth:`EngineTraceRecorder.entered`
  when a top-level state of the machine starts and :meth:`~EngineTraceRecorder.returned`
  when it returns an outcome;
* the simulator's request events (``AtlasSimulator.add_listener``): a ``started`` request
  is a fresh activation of its capability (a state re-activating a capability that is
  still running joins it, so no new request starts: its outcome proposition stays as it
  is, as in our executive); a ``finished`` request is the robot's report.

Steps, activations and outcome propositions follow :class:`atlas_sim.executive.executor.Executive`:
a step's ``activated`` are the activation propositions of the state (or of the children
of a concurrency container), a report of a capability the current step does not activate
is recorded as ``abandoned``.

Threads: the simulator's listener runs wherever the simulator is stepped (the node's
physics thread, holding ``simulator_lock``); ``entered``/``returned`` run in the engine's
thread and take the simulator lock only to read a snapshot, never together with the
recorder's own lock, so the two threads cannot deadlock.
"""

from __future__ import annotations

import contextlib
import threading

from atlas_sim.executive.executor import ExecutionResult, StateMapping, entered_step, record_forced
from atlas_sim.executive.errors import next_target
from atlas_sim.executive.trace_check import OutcomeTracker, Trace, TraceStep
from respec.robot import RobotSystem
from sm_generation.state_machine import StateMachine


class EngineTraceRecorder:
    """Builds the trace of one run of ``machine`` on ``simulator`` (see the module docstring)."""

    def __init__(self, machine: StateMachine, simulator, system: RobotSystem, simulator_lock=None):
        self.root = machine
        self.mapping = StateMapping(system)
        self.simulator = simulator
        self.simulator_lock = simulator_lock or contextlib.nullcontext()
        self.states = {child.name: child for child in self.root.states}
        self.parts = {child.name: [self.mapping.part(node) for node in (child.states or (child,))]
                      for child in self.root.states}
        self.trace = Trace(sm_outcome_propositions=self.mapping.sm_outcome_propositions())
        self._lock = threading.Lock()
        snapshot = self._snapshot()
        self.start_time = snapshot['time']
        self.min_pelvis = snapshot.get('pelvis_height', float('nan'))
        self.fallen = bool(snapshot.get('fallen', False))
        self.tracker = OutcomeTracker(self.mapping.control_modes, snapshot['mode'],
                                      snapshot.get('completed_actions', []), snapshot.get('sensors', {}))
        self._current: TraceStep | None = None
        simulator.add_listener(self._on_simulator_event)

    def close(self) -> None:
        """Stop listening to the simulator."""
        with self.simulator_lock:
            self.simulator.remove_listener(self._on_simulator_event)

    def _snapshot(self) -> dict:
        with self.simulator_lock:
            return self.simulator.snapshot()

    # --- the engine's side ---------------------------------------------------------------------

    def entered(self, name: str) -> None:
        """Top-level state ``name`` starts (before it requests anything)."""
        snapshot = self._snapshot()
        with self._lock:
            self._observe(snapshot)
            self._current = entered_step(self.trace, self.states[name], self.parts[name], snapshot, self.tracker)

    def returned(self, name: str, outcome: str, forced: bool = False) -> None:
        """Top-level state ``name`` returned ``outcome`` (``forced``: the operator's choice, sent
        as FlexBE's transition command, not the state's own result)."""
        target = next_target(self.states[name], outcome)
        snapshot = self._snapshot()
        with self._lock:
            self._observe(snapshot)
            step = self._current
            assert step is not None  # entered() came first
            if forced:
                record_forced(step, step.state, outcome, self.parts[name])
            step.state_outcome, step.transition = outcome, target
            step.ended_at, step.mode_at_exit = snapshot['time'], snapshot['mode']
            step.outcomes_at_exit = self.tracker.true_propositions()
            if target in self.root.outcomes:
                self.trace.outcome = target

    def result(self) -> ExecutionResult:
        """The run so far, as our executive reports it."""
        snapshot = self._snapshot()
        with self._lock:
            self._observe(snapshot)
            return ExecutionResult(self.trace.outcome, self.trace, snapshot['time'], self.min_pelvis,
                                   self.fallen, ticks=0, robot_started_at=self.start_time)

    # --- the simulator's side (its stepping thread, under its lock) -------------------------------

    def _on_simulator_event(self, event: str, request) -> None:
        snapshot = self.simulator.snapshot()
        with self._lock:
            self._observe(snapshot)
            if event == 'started':
                self.tracker.activate([request.name])
            elif event == 'finished' and request.result is not None:
                done = request.result
                self.tracker.report(request.name, done.outcome)
                if self._current is not None:
                    self._current.results.append({
                        'capability': request.name, 'outcome': done.outcome, 'reason': done.reason,
                        'time': done.finished_at, 'abandoned': request.name not in self._current.capabilities})

    def _observe(self, snapshot: dict) -> None:
        self.min_pelvis = min(self.min_pelvis, snapshot.get('pelvis_height', self.min_pelvis))
        self.fallen |= bool(snapshot.get('fallen', False))
        self.tracker.read_sensors(snapshot.get('sensors', {}))
