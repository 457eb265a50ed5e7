"""One closed-loop run: execute a state machine on the robot, record key frames, check the
executed trace against the specification and the goal order, draw the timeline.

``behavior-synthesis execute`` and the web GUI's simulations both run this sequence.
"""

from __future__ import annotations

import collections
import contextlib
from dataclasses import dataclass, field
from pathlib import Path
import time
from typing import Callable

from atlas_sim.executive.executor import ExecutionResult, Executive, StateMapping
from atlas_sim.executive.timeline import plot_timeline
from atlas_sim.executive.trace_check import TraceCheckReport, TraceStep, check_trace
from atlas_sim.simulator.rendering import KeyFrameRecorder
from respec.robot import RobotSystem
from respec.spec import GR1Specification
from sm_generation.state_machine import StateMachine

FRAME_WIDTH, FRAME_HEIGHT = 480, 360


@dataclass
class CheckedRun:
    """What a closed-loop run produced."""

    result: ExecutionResult
    check: TraceCheckReport
    wall_seconds: float
    frames: list[Path] = field(default_factory=list)
    timeline: Path | None = None


def run_and_check(machine: StateMachine, robot, simulator, system: RobotSystem, spec: GR1Specification,
                  goals: list[str], *,
                  ordered: bool = True, record_dir: str | Path | None = None,
                  max_robot_time: float = 300.0, max_wall_time: float | None = None,
                  on_progress: Callable[[list[TraceStep], list[Path]], None] | None = None,
                  view=None, lock=None,
                  run_machine: Callable[[Callable], ExecutionResult] | None = None) -> CheckedRun:
    """Run ``machine`` on ``robot`` (driving ``simulator``), then check and plot the run.

    The simulator's incidents (the robot's body in furniture, a fall) go into the trace, so the
    check reports them as violations.

    With ``record_dir``, frames go to ``record_dir/frames`` (key moments, and the motion at
    ``MOTION_FPS`` frames per robot second; each file name carries its robot time, see
    ``KeyFrameRecorder``) and the timeline to ``record_dir/timeline.png``. ``view`` is what the frame recorder watches (default: the
    simulator; see ``DeferredEvents`` when another thread steps it: its ``replay()`` runs every
    tick) and ``lock`` guards rendering. ``on_progress(steps, frames)`` follows every control
    tick. ``run_machine(on_tick) -> ExecutionResult`` runs the machine on another engine (default:
    our ``Executive``). An ``ExecutionError`` (with the partial trace) propagates once the
    recorder is closed.
    """
    lock = lock or contextlib.nullcontext()
    recorder = None
    if record_dir is not None:
        recorder = KeyFrameRecorder(view or simulator, Path(record_dir) / 'frames', width=FRAME_WIDTH,
                                    height=FRAME_HEIGHT)
        with lock:
            recorder.capture('start')
    executive = None

    def tick(_robot):
        if view is not None and hasattr(view, 'replay'):
            view.replay()
        if recorder is not None:
            with lock:
                recorder.capture_motion()
        if on_progress is not None and executive is not None:
            on_progress(executive.trace.steps, list(recorder.paths) if recorder else [])

    started = time.monotonic()
    try:
        if run_machine is None:
            executive = Executive(machine, robot, StateMapping(system), max_robot_time=max_robot_time,
                                  max_wall_time=max_wall_time, on_tick=tick)
            result = executive.run()
        else:
            result = run_machine(tick)
    finally:
        if recorder is not None:
            tick(robot)
            with lock:
                recorder.capture('end')
            recorder.close()
    wall_seconds = time.monotonic() - started
    result.trace.incidents = [incident.to_dict() for incident in simulator.incidents]
    check = check_trace(result.trace, spec, goals=list(goals), ordered=ordered)
    run = CheckedRun(result, check, wall_seconds, frames=list(recorder.paths) if recorder else [])
    if record_dir is not None:
        run.timeline = plot_timeline(result.trace, Path(record_dir) / 'timeline.png',
                                     f'{", ".join(goals)}: {result.outcome}')
    return run


class DeferredEvents:
    """A simulator view for ``KeyFrameRecorder`` when another thread steps the simulator.

    OpenGL contexts belong to the thread that made them, so the simulator's events are
    queued in the stepping thread and replayed (rendered) in this one under ``lock``; frames
    show the robot a poll period after the event, named with the event's sim time.
    """

    def __init__(self, simulator, lock):
        self.simulator, self.lock = simulator, lock
        self.physics = simulator.physics
        self.time = simulator.time
        self._listeners, self._queue = [], collections.deque()
        simulator.add_listener(self._enqueue)

    def _enqueue(self, event: str, request) -> None:
        self._queue.append((event, request, self.simulator.time))

    def add_listener(self, listener) -> None:
        self._listeners.append(listener)

    def remove_listener(self, listener) -> None:
        self._listeners.remove(listener)
        if not self._listeners:
            self.simulator.remove_listener(self._enqueue)

    def replay(self) -> None:
        while self._queue:
            event, request, self.time = self._queue.popleft()
            with self.lock:
                for listener in list(self._listeners):
                    listener(event, request)
        self.time = self.simulator.time
