"""A GUI simulation in a child process: the GUI stays small, and a crash stays in the child.

MuJoCo with its off-screen renderer grew the GUI process by ~280 MiB on its first run, and a
crash in native code would have ended the GUI with it. Each run therefore has a child process
of its own (``ltl_synthesizer.isolated.ChildProcess``, the project's one process runner, which
preloads this module): the run's settings go in, progress comes back as steps and key frames
are added, then one final message. Frames and the timeline are files in the run's record
directory, passed by path. The child is killed when the GUI stops the run or it overruns its
wall-time limit, and ends by itself when the GUI dies, so no run outlives the GUI.

    run = SimulationProcess(settings)       # in the GUI, one thread per run
    final = run.run(on_progress)            # run.stop() from another thread ends it
"""

from __future__ import annotations

import dataclasses
import logging
import time
from typing import Callable

from ltl_synthesizer.errors import SynthesisError
from ltl_synthesizer.isolated import ChildProcess
from respec.errors import INTERNAL_ERROR, CodedError

#: Seconds past its own wall-time limit a child is given before it is killed.
KILL_GRACE = 30.0

#: The child's environment unless the GUI's own sets them. Off-screen rendering; llvmpipe
#: (software GL) rasterizes in the rendering thread instead of its own threads, and malloc
#: returns freed blocks over 128 KiB to the system at once (glibc otherwise keeps the GL
#: driver's freed buffers): a run peaked at ~204 MiB without the last two, ~187 MiB with them,
#: with byte-identical frames and the same CPU time (bench/bench_reliability.py, simulations).
CHILD_ENVIRONMENT = {'MUJOCO_GL': 'egl', 'LP_NUM_THREADS': '0', 'MALLOC_TRIM_THRESHOLD_': '131072'}

logger = logging.getLogger(__name__)


class SimulationProcess:
    """One run in its child process (``settings``: see :func:`simulate`)."""

    def __init__(self, settings: dict):
        self.settings = settings
        self.child = ChildProcess(preload=__name__, environment=CHILD_ENVIRONMENT)
        self.process = self.child.process

    def run(self, on_progress: Callable[[dict], None]) -> dict:
        """Wait for the run, calling ``on_progress({'robot_time', 'steps', 'frames'})`` as it
        advances; return its final message, ``{'result': {...}}`` or ``{'error': {'code', 'item',
        'message'}, 'steps': [...] or None}``, also when the child dies or is stopped."""
        last_steps = None

        def progress(update: dict):
            nonlocal last_steps
            last_steps = update['steps']
            on_progress(update)

        try:
            return self.child.call(simulate, (self.settings,), on_progress=progress,
                                   deadline=time.monotonic() + self.settings['max_wall_time'] + KILL_GRACE)
        except SynthesisError:  # the child died, was stopped or overran its time
            pass
        finally:
            self.child.kill()
        return {'error': {'code': INTERNAL_ERROR, 'item': 'simulation process',
                          'message': f'the simulation process ended (exit code {self.process.returncode}) '
                                     'without a result'},
                'steps': last_steps}

    def stop(self) -> None:
        """End the child now, from any thread (the GUI stops): run() returns the error message."""
        if self.process.poll() is None:
            self.process.kill()


def simulate(settings: dict, progress: Callable[[dict], None]) -> dict:
    """In the child: run the machine on atlas_sim's robot, reporting ``progress``; the final message."""
    simulator, sent = None, [0, 0]

    def step_added(steps, frames):  # every control tick: report only when a step or frame was added
        if (len(steps), len(frames)) != tuple(sent):
            sent[:] = [len(steps), len(frames)]
            progress({'robot_time': simulator.time, 'steps': [dataclasses.asdict(s) for s in steps],
                      'frames': [str(path) for path in frames]})

    try:
        from pathlib import Path

        from atlas_sim.closed_loop import run_and_check
        from atlas_sim.simulated_robot import SimulatedRobot
        from atlas_sim.simulator.factory import make_simulator, parse_faults
        from respec.parsing import spec_from_text_sections
        from respec.robot import robot_system_from_files

        # The GUI's system as the GUI read it (perhaps from a suite elsewhere), not a file here.
        system = robot_system_from_files(settings['system'], settings['files'], settings['config_file'])
        simulator = make_simulator(system, settings['initial_conditions'],
                                   faults=parse_faults(fail_first=[f'{c}:1' for c in settings['fail_first']]))
        run = run_and_check(settings['states'], SimulatedRobot(simulator), simulator, system,
                            spec_from_text_sections(settings['ltl_specification']), settings['goals'],
                            ordered=settings['ordered'], record_dir=Path(settings['record_dir']),
                            max_robot_time=settings['max_robot_time'],
                            max_wall_time=settings['max_wall_time'], on_progress=step_added)
        return {'result': {'outcome': run.result.outcome, 'check': run.check.to_dict(),
                           'timeline': str(run.timeline) if run.timeline else None,
                           'frames': [str(path) for path in run.frames], 'robot_time': simulator.time,
                           'steps': [dataclasses.asdict(step) for step in run.result.trace.steps]}}
    except Exception as error:  # ExecutionError, bad faults, rendering, a missing module: reported to the GUI
        if not isinstance(error, CodedError):
            logger.exception('simulation failed')
        trace = getattr(error, 'trace', None)
        return {'error': {'code': error.code if isinstance(error, CodedError) else INTERNAL_ERROR,
                          'item': getattr(error, 'item', ''), 'message': str(error)},
                'steps': [dataclasses.asdict(step) for step in trace.steps] if trace else None}
