"""A GUI simulation in a child process: the GUI stays small, and a crash stays in the child.

MuJoCo with its off-screen renderer grew the GUI process by ~280 MiB on its first run, and a
crash in native code would have ended the GUI with it. Each run therefore has a child process
of its own (``respec.child_processes.runner.ChildProcess``, the project's one process runner, which
preloads this module): the run's settings go in, progress comes back as steps and key frames
are added, then one final message (the state machine goes in as its tree, pickled with the rest).
Frames and the timeline are files in the run's record
directory, passed by path. The child is killed when the GUI stops the run or it overruns its
wall-time limit, and ends by itself when the GUI dies, so no run outlives the GUI.

The operator is in the loop (FlexBE's Runtime Control, ``atlas_sim.executive.runtime_control``):
``run.command({...})`` from another thread reaches the run's RuntimeControl through the child's
command channel, and each progress message says what the run waits for (``operator``). The
run starts at ``settings['autonomy']`` (default Full: nothing in the configs waits then, so an
untouched run is the unattended one).

    run = SimulationProcess(settings)       # in the GUI, one thread per run
    final = run.run(on_progress)            # run.stop() from another thread ends it
    run.command({'command': 'force', 'state': '/stand', 'outcome': 'failed'})
"""

from __future__ import annotations

import dataclasses
import logging
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable

from atlas_sim.executive.runtime_control import FULL, RuntimeControl
from respec.child_processes.errors import ChildWorkError
from respec.child_processes.runner import ChildProcess
from respec.vocabulary.errors import INTERNAL_ERROR, CodedError

if TYPE_CHECKING:  # the child imports them when it runs (simulate, simulate_capability_robot)
    from atlas_sim.executive.capability_run import CapabilityRun
    from atlas_sim.executive.executor import Executive

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
    """One run in its child process (``settings``: see :func:`simulate`), by ``simulator``: the
    name of this module's function that runs it (``simulate``: atlas_sim's ATLAS;
    ``simulate_capability_robot``: a capability robot without physics)."""

    def __init__(self, settings: dict, simulator: str = 'simulate'):
        self.settings = settings
        self.simulator = globals()[simulator]
        self.child = ChildProcess(preload=__name__, environment=CHILD_ENVIRONMENT)
        self.process = self.child.process

    def run(self, on_progress: Callable[[dict], None]) -> dict:
        """Wait for the run, calling ``on_progress({'robot_time', 'steps', 'frames', 'operator'})`` as it
        advances; return its final message, ``{'result': {...}}`` or ``{'error': {'code', 'item',
        'message'}, 'steps': [...] or None}``, also when the child dies or is stopped."""
        last_steps = None

        def progress(update: dict):
            nonlocal last_steps
            last_steps = update['steps']
            on_progress(update)

        try:
            return self.child.call(self.simulator, (self.settings,), on_progress=progress, wants_commands=True,
                                   deadline=time.monotonic() + self.settings['max_wall_time'] + KILL_GRACE)
        except ChildWorkError:  # the child died, was stopped or overran its time
            pass
        finally:
            self.child.kill()
        return {'error': {'code': INTERNAL_ERROR, 'item': 'simulation process',
                          'message': f'the simulation process ended (exit code {self.process.returncode}) '
                                     'without a result'},
                'steps': last_steps}

    def command(self, command: dict) -> bool:
        """Send an operator command (checked by the caller) to the run; False once it has ended."""
        return self.child.command(command)

    def stop(self) -> None:
        """End the child now, from any thread (the GUI stops): run() returns the error message."""
        if self.process.poll() is None:
            self.process.kill()


def simulate(settings: dict, progress: Callable[[dict], None], commands: Callable[[float], list] | None = None) -> dict:
    """In the child: run the machine on atlas_sim's robot with the operator's ``commands``,
    reporting ``progress``; the final message."""
    simulator: Any  # the AtlasSimulator (made below, where the child imports atlas_sim)
    executive: Executive | None
    sent: list[Any]
    simulator, executive, sent = None, None, [0, 0, None]
    frames_dir = Path(settings['record_dir']) / 'frames'
    listed: list[Any] = [0.0, []]

    def frames(now: bool = False) -> list[str]:  # the recorder's files so far, looked up 20 times a second
        if now or time.monotonic() - listed[0] > 0.05:
            listed[:] = [time.monotonic(), recorded_frames(frames_dir)]
        return listed[1]

    def report(force: bool = False):  # only when a step, a frame or the operator's view changed
        steps = executive.trace.steps if executive else []
        found = frames(force)
        operator = control.status() if control else None
        if force or (len(steps), len(found), operator) != tuple(sent):
            sent[:] = [len(steps), len(found), operator]
            progress({'robot_time': simulator.time, 'steps': [dataclasses.asdict(s) for s in steps],
                      'frames': found, 'operator': operator})

    control = RuntimeControl(commands, report=lambda status: report(force=True),
                             autonomy_level=settings.get('autonomy', FULL)) if commands else None
    try:
        from atlas_sim.closed_loop import run_and_check
        from atlas_sim.executive.executor import Executive, StateMapping
        from atlas_sim.simulated_robot import SimulatedRobot
        from atlas_sim.simulator.factory import make_simulator, parse_faults
        from respec.parsing import spec_from_text_sections
        from respec.robot import robot_system_from_files

        # The GUI's system as the GUI read it (perhaps from a suite elsewhere), not a file here.
        system = robot_system_from_files(settings['system'], settings['files'], settings['config_file'])
        simulator = make_simulator(system, settings['initial_conditions'],
                                   faults=parse_faults(fail_first=[f'{c}:1' for c in settings['fail_first']]))
        robot = SimulatedRobot(simulator)

        def run_machine(tick):  # our Executive, with the operator in the loop
            nonlocal executive

            def on_tick(robot_now):
                tick(robot_now)
                report()
            executive = Executive(settings['machine'], robot, StateMapping(system),
                                  max_robot_time=settings['max_robot_time'], max_wall_time=settings['max_wall_time'],
                                  on_tick=on_tick, control=control)
            return executive.run()

        run = run_and_check(settings['machine'], robot, simulator, system,
                            spec_from_text_sections(settings['ltl_specification']), settings['goals'],
                            ordered=settings['ordered'], record_dir=Path(settings['record_dir']),
                            max_robot_time=settings['max_robot_time'],
                            max_wall_time=settings['max_wall_time'], run_machine=run_machine)
        return {'result': {'outcome': run.result.outcome, 'check': run.check.to_dict(),
                           'timeline': str(run.timeline) if run.timeline else None,
                           'frames': [str(path) for path in run.frames], 'robot_time': simulator.time,
                           'steps': [dataclasses.asdict(step) for step in run.result.trace.steps],
                           'operator_events': run.result.operator_events}}
    except Exception as error:  # ExecutionError, bad faults, rendering, a missing module: reported to the GUI
        if not isinstance(error, CodedError):
            logger.exception('simulation failed')
        trace = getattr(error, 'trace', None)
        return {'error': {'code': error.code if isinstance(error, CodedError) else INTERNAL_ERROR,
                          'item': getattr(error, 'item', ''), 'message': str(error)},
                'steps': [dataclasses.asdict(step) for step in trace.steps] if trace else None,
                'frames': frames(now=True)}


def simulate_capability_robot(settings: dict, progress: Callable[[dict], None],
                              commands: Callable[[float], list] | None = None) -> dict:
    """In the child: run a capability robot's machine on the simulated capability robot
    (``atlas_sim.executive.capability_run``, no physics) with the operator's ``commands``: each
    state's answer waits for the operator where the autonomy level asks it (confirm it, or force
    another outcome: CapabilityRun's ``choose``), ``fail_first`` capabilities answer their failure,
    ``sensors`` are held as the operator set them (at the start, or by a ``sensor`` command). Reports the steps as atlas_sim's trace steps, and
    the trace check with each violation worded with who chose the answer."""
    machine_steps: list[dict] = []
    control = RuntimeControl(commands, report=lambda status: report(), autonomy_level=settings.get('autonomy', FULL)) \
        if commands else None
    run: CapabilityRun | None
    active: list[Any]
    run, active = None, ['', -1]   # the state being answered and the steps taken before it

    def report(pending: str = ''):
        steps = capability_steps(run.result.steps, machine) if run else []
        if pending:
            active[:] = [pending, len(steps)]
        pending = active[0] if active[1] == len(steps) else ''
        if pending:
            steps.append({'index': len(steps), 'state': pending, 'capabilities': [by_path[pending][1]],
                          'activated': [by_path[pending][1]], 'results': [], 'state_outcome': '', 'transition': '',
                          'entered_at': 0.0, 'ended_at': 0.0})
        machine_steps[:] = steps
        progress({'robot_time': 0.0, 'steps': steps, 'frames': [], 'operator': control.status() if control else None})

    try:
        from atlas_sim.executive.capability_run import CapabilityRun, capability_of, parse_script
        from respec.parsing import spec_from_text_sections
        from respec.robot import robot_system_from_files
        from respec.robot.state_library import capability_outcomes, workspace_state_library
        system = robot_system_from_files(settings['system'], settings['files'], settings['config_file'])
        capabilities = system.required_capabilities()
        script = parse_script(capabilities, capability_outcomes(capabilities, workspace_state_library()),
                              list(settings['fail_first']),
                              [f'{name}={"true" if value else "false"}' for name, value in settings['sensors'].items()])
        machine = settings['machine']
        by_path = {state.state_path: (state, capability_of(state, capabilities)) for state in machine.states}
        deadline = time.monotonic() + settings['max_wall_time']

        def take_sensors():  # the operator's sensor changes, from this answer on
            for name, value in control.sensors.items():
                if value is None:
                    run.sensors.pop(name, None)
                else:
                    run.sensors[name] = value
            control.sensors.clear()

        def choose(path: str, outcomes: list[str]) -> str | None:
            """The operator's outcome for the state at ``path``, or None: the robot's own (with
            the sensors as the operator set them: a change while the answer waits asks again)."""
            report(pending=path)
            if control is None:
                return None
            control.between_ticks(path, deadline)
            take_sensors()
            forced = control.take_forced([path])
            if forced:
                return forced[1] if forced[1] in outcomes else None
            capability = by_path[path][1]
            before = len(control.events)
            answer = None
            assert run is not None  # asked by run.run()
            while answer is None:  # asked again with the robot's new answer when the operator sets a sensor
                proposed = run.proposed
                required = capabilities.capabilities[capability].autonomy.get(proposed, 0) if capability else 0
                answer = control.confirm(path, proposed, required, outcomes, deadline,
                                         until=lambda: bool(control.sensors))
                take_sensors()
            forced_now = any(event.get('command') == 'force' and event.get('state') == path
                             for event in control.events[before:])
            return answer if forced_now else None

        spec = spec_from_text_sections(settings['ltl_specification'])
        run = CapabilityRun(machine, settings['automaton'], capabilities, spec, script, choose=choose)
        result = run.run()
        steps = capability_steps(result.steps, machine)
        if result.not_finished and not result.violations:
            return {'error': {'code': 'TIMEOUT', 'item': steps[-1]['state'] if steps else '',
                              'message': result.not_finished}, 'steps': steps}
        violations = [{'kind': 'guarantee' if 'broke a guarantee' in text else 'assumption', 'message': text}
                      for text in result.violations]
        return {'result': {'outcome': result.outcome, 'robot_time': 0.0, 'steps': steps, 'timeline': None, 'frames': [],
                           'check': {'ok': not violations, 'outcome': result.outcome, 'positions': len(steps),
                                     'goals': list(settings['goals']), 'goals_completed_at': {},
                                     'violations': violations},
                           'operator_events': control.events if control else []}}
    except Exception as error:  # a bad script, the operator's stop, a missing state class: reported to the GUI
        if not isinstance(error, CodedError):
            logger.exception('capability simulation failed')
        return {'error': {'code': error.code if isinstance(error, CodedError) else INTERNAL_ERROR,
                          'item': getattr(error, 'item', ''), 'message': str(error)},
                'steps': machine_steps or None}


def capability_steps(steps, machine) -> list[dict]:
    """A capability run's steps (CapabilityRun's RunStep) as the page shows atlas_sim's trace
    steps: the state, its capability, the outcome it answered (and who chose it) and where the
    machine went on. No physics: no robot time passes."""
    by_path = {state.state_path: state for state in machine.states}
    return [{'index': index, 'state': step.state, 'capabilities': [step.capability], 'activated': [step.capability],
             'results': [{'capability': step.capability, 'outcome': step.outcome}], 'state_outcome': step.outcome,
             'transition': by_path[step.state].next_target(step.outcome), 'chosen_by': step.chosen_by,
             'forced': step.outcome if step.chosen_by == 'the operator' else '', 'entered_at': 0.0, 'ended_at': 0.0}
            for index, step in enumerate(steps)]


def recorded_frames(directory: Path) -> list[str]:
    """The frame files in ``directory`` in the order they were taken (their names start with
    their index)."""
    if not directory.is_dir():
        return []
    files = [path for path in directory.iterdir() if path.suffix == '.png' and path.name.split('_', 1)[0].isdigit()]
    return [str(path) for path in sorted(files, key=lambda path: int(path.name.split('_', 1)[0]))]
