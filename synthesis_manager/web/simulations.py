"""Closed-loop runs of a job's state machine on the simulated robot (atlas_sim): their records, and
``SimulationRuns``, which starts, follows, steers and forgets them."""

from __future__ import annotations

import importlib.util
import shutil
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

from atlas_sim.executive.runtime_control import AUTONOMY_LEVELS, FULL, CommandError, checked_command
from respec.vocabulary.errors import CodedError, quoted
from respec.robot import RobotSystem
from synthesis_manager.limits import BusyError
from synthesis_manager.web.artifacts import Artifact
from synthesis_manager.web.errors import InvalidJobRequestError, NotAvailableError, NotFoundError
from synthesis_manager.web.job_queue import JobQueue
from synthesis_manager.web.jobs import Job, checked_body, names_field, update_record
from synthesis_manager.web.robot_views import robot_view
from synthesis_manager.web.simulation_process import SimulationProcess

SIMULATION_RETRY_AFTER = 10  # seconds: a short simulation's run time


@dataclass
class Simulation:
    """One closed-loop run of a job's state machine on the simulated robot (atlas_sim)."""

    id: str
    job_id: str
    fail_first: tuple[str, ...] = ()   # capabilities whose first attempt fails (a capability robot's: always)
    sensors: dict = field(default_factory=dict)  # a capability robot's sensors as the run starts
    sensor_names: tuple[str, ...] = ()  # the sensors an operator may set (a capability robot's)
    state: str = 'running'             # running -> finished
    steps: list[dict] = field(default_factory=list)  # atlas_sim TraceStep dicts so far
    robot_time: float = 0.0
    frames: list[Path] = field(default_factory=list, repr=False)
    timeline_png: Path | None = field(default=None, repr=False)
    outcome: str | None = None         # the SM outcome reached
    error: dict | None = None          # {'code', 'item', 'message'} if the run broke off
    check: dict | None = None          # atlas_sim trace check report
    wall_seconds: float = 0.0
    operator: dict = field(default_factory=dict)   # RuntimeControl status: autonomy, paused, waiting
    operator_events: list[dict] = field(default_factory=list)  # the operator's commands, once finished
    revision: int = 0

    def to_dict(self) -> dict:
        return {'id': self.id, 'job_id': self.job_id, 'fail_first': list(self.fail_first),
                'sensors': dict(self.sensors),
                'state': self.state, 'steps': list(self.steps), 'robot_time': round(self.robot_time, 3),
                'frames': [{'index': i, 'label': p.stem} for i, p in enumerate(self.frames)],
                'timeline': self.timeline_png is not None, 'outcome': self.outcome,
                'error': self.error, 'check': self.check, 'wall_seconds': round(self.wall_seconds, 3),
                'operator': self.operator, 'operator_events': list(self.operator_events)}


def simulation_available() -> bool:
    """Whether MuJoCo, which atlas_sim simulates with, is installed."""
    return importlib.util.find_spec('mujoco') is not None


class SimulationRuns:
    """The simulations of ``jobs``' finished jobs, each in its child process (web/simulation_process.py).

    A simulation takes a process of ~225 MiB and a core for up to minutes: at most
    ``max_running`` run at once, and a job keeps only its newest ``max_per_job`` runs (frames
    included). ``catalog`` loads a job's robot system.
    """

    def __init__(self, jobs: JobQueue, catalog, stopping: threading.Event, max_running: int = 2,
                 max_per_job: int = 5):
        self.jobs = jobs
        self.catalog = catalog
        self.stopping = stopping
        self.max_running = max_running
        self.max_per_job = max_per_job
        self.available = simulation_available()
        self._runs: dict[str, Simulation] = {}
        self._processes: set[SimulationProcess] = set()
        self._children: dict[str, SimulationProcess] = {}   # running simulation id -> its child
        self._lock = threading.Lock()
        self._directory = tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-')
        jobs.on_forget.append(self.forget_job)

    def start(self, job_id: str, body) -> Simulation:
        """Run the state machine of a finished job on atlas_sim's simulated robot."""
        job = self.jobs.job(job_id)
        body = checked_body({} if body is None else body)
        unknown = sorted(set(body) - {'fail_first', 'autonomy', 'sensors'})
        if unknown:
            raise InvalidJobRequestError(f'unknown field {quoted(unknown[0])} (fields: fail_first, autonomy, sensors)',
                                         unknown[0])
        fail_first = names_field(body, 'fail_first')
        sensors = body.get('sensors', {})
        if not isinstance(sensors, dict) or not all(isinstance(v, bool) for v in sensors.values()):
            raise InvalidJobRequestError('sensors is an object of sensor names to true or false', 'sensors')
        autonomy = body.get('autonomy', FULL)
        if autonomy not in AUTONOMY_LEVELS.values() or isinstance(autonomy, bool):
            raise InvalidJobRequestError('autonomy is 0 (Off), 1 (Low), 2 (High) or 3 (Full)', 'autonomy')
        if not (job.finished and job.finished_outcome.machine is not None):
            raise NotAvailableError(f'job {quoted(job_id)} has no state machine to simulate', job_id)
        try:
            robot = self.catalog.load(job.request.system)
        except CodedError as error:
            raise NotAvailableError(str(error), error.item or job.request.system) from error
        view = robot_view(robot)
        support = view.simulation_support(self.available)
        if not support['available']:
            raise NotAvailableError(support['note'], job.request.system)
        unknown = sorted(set(sensors) - set(support.get('sensors', ())))
        if unknown:
            raise InvalidJobRequestError(f'{quoted(unknown[0])} is no sensor of {job.request.system} '
                                         f'(sensors: {", ".join(support.get("sensors", ())) or "none"})', unknown[0])
        simulation = Simulation(id=f'{job_id}-sim{next(self.jobs.counter)}', job_id=job_id, fail_first=fail_first,
                                operator={'autonomy': autonomy, 'paused': False, 'waiting': None},
                                sensors=dict(sensors), sensor_names=tuple(support.get('sensors', ())))
        with self._lock:
            self._admit(job_id)
            self._runs[simulation.id] = simulation
        threading.Thread(target=self._simulate, args=(simulation, job, robot, view.simulator),
                         name=f'gui-{simulation.id}', daemon=True).start()
        return simulation

    def _admit(self, job_id: str):
        """Refuse a run beyond max_running (429); make room for it among the job's max_per_job
        newest runs by forgetting its oldest finished one. Holds _lock."""
        running = [run for run in self._runs.values() if run.state != 'finished']
        if len(running) >= self.max_running:
            raise BusyError(
                f'{len(running)} simulations are running (at most {self.max_running} at once); '
                'try again when one has finished', 'simulations', retry_after=SIMULATION_RETRY_AFTER)
        runs = [run for run in self._runs.values() if run.job_id == job_id]
        finished = [run for run in runs if run.state == 'finished']
        for run in finished[:max(0, len(runs) + 1 - self.max_per_job)]:
            self._forget(run.id)

    def _forget(self, simulation_id: str):
        """Drop a finished simulation and its recorded frames. Holds _lock."""
        self._runs.pop(simulation_id, None)
        shutil.rmtree(self._record_dir(simulation_id), ignore_errors=True)

    def forget_job(self, job_id: str) -> None:
        """Drop the simulations of a forgotten job."""
        with self._lock:
            for run_id in [r for r, run in self._runs.items() if run.job_id == job_id]:
                self._forget(run_id)

    def _record_dir(self, simulation_id: str) -> Path:
        return Path(self._directory.name) / simulation_id

    def status(self, simulation_id: str) -> Simulation:
        with self._lock:
            simulation = self._runs.get(simulation_id)
        if simulation is None:
            raise NotFoundError(f'unknown simulation {quoted(simulation_id)}', simulation_id)
        return simulation

    def revision(self, simulation_id: str) -> int:
        return self.status(simulation_id).revision

    def frame(self, simulation_id: str, index: int) -> Artifact:
        simulation = self.status(simulation_id)
        if not 0 <= index < len(simulation.frames):
            raise NotFoundError(f'simulation {quoted(simulation_id)} has no frame {index}', str(index))
        path = simulation.frames[index]
        return Artifact(path.read_bytes(), 'image/png', path.name)

    def timeline(self, simulation_id: str) -> Artifact:
        simulation = self.status(simulation_id)
        if simulation.timeline_png is None:
            raise NotAvailableError(f'simulation {quoted(simulation_id)} has no timeline yet', simulation_id)
        return Artifact(simulation.timeline_png.read_bytes(), 'image/png', f'{simulation_id}_timeline.png')

    def command(self, simulation_id: str, body) -> Simulation:
        """Pass an operator command (atlas_sim.executive.runtime_control) to a running simulation."""
        simulation = self.status(simulation_id)
        try:
            command = checked_command(checked_body({} if body is None else body))
        except CommandError as error:
            raise InvalidJobRequestError(str(error), 'command') from None
        if command['command'] == 'sensor' and command['name'] not in simulation.sensor_names:
            raise InvalidJobRequestError(f'{quoted(command["name"])} is no sensor of this run\'s robot '
                                         f'(sensors: {", ".join(simulation.sensor_names) or "none"})', command['name'])
        with self._lock:
            child = self._children.get(simulation_id)
        if child is None or simulation.state == 'finished' or not child.command(command):
            raise NotAvailableError(f'simulation {quoted(simulation_id)} is not running', simulation_id)
        return simulation

    def stop_all(self) -> None:
        """The server is stopping: end the running simulations' children."""
        with self._lock:
            running = list(self._processes)
        for child in running:
            child.stop()

    def _simulate(self, simulation: Simulation, job: Job, robot: RobotSystem, simulator: str):
        """Run ``simulation`` of ``job`` on ``robot`` in its child process (web/simulation_process.py,
        its function ``simulator``: the robot view's), following it. The child gets the system's
        files as read here, not a path to read them again, and the machine as its tree."""
        request, started = job.request, time.monotonic()
        child = SimulationProcess({
            'machine': job.finished_outcome.machine,
            'ltl_specification': job.finished_outcome.ltl_specification,
            'system': robot.name, 'files': dict(robot.files), 'config_file': robot.config_file,
            'initial_conditions': list(request.initial_conditions), 'goals': list(request.goals),
            'ordered': not request.unordered, 'fail_first': list(simulation.fail_first),
            'record_dir': str(self._record_dir(simulation.id)), 'max_robot_time': 300.0, 'max_wall_time': 300.0,
            'autonomy': simulation.operator['autonomy'], 'automaton': job.finished_outcome.automaton,
            'sensors': dict(simulation.sensors)}, simulator)
        with self._lock:
            self._processes.add(child)
            self._children[simulation.id] = child
        if self.stopping.is_set():
            child.stop()

        def progress(update):
            simulation.robot_time = update['robot_time']
            update_record(simulation, self._lock, steps=update['steps'],
                          frames=[Path(path) for path in update['frames']],
                          operator=update.get('operator') or simulation.operator)

        try:
            final = child.run(progress)
        finally:
            with self._lock:
                self._processes.discard(child)
                self._children.pop(simulation.id, None)
        if 'result' in final:
            result = final['result']
            simulation.robot_time = result['robot_time']
            update_record(simulation, self._lock, outcome=result['outcome'], check=result['check'],
                          steps=result['steps'], timeline_png=Path(result['timeline']) if result['timeline'] else None,
                          frames=[Path(path) for path in result['frames']],
                          operator_events=result.get('operator_events', []))
        else:
            update_record(simulation, self._lock, error=final['error'],
                          steps=simulation.steps if final['steps'] is None else final['steps'],
                          frames=[Path(path) for path in final['frames']] if final.get('frames')
                          else simulation.frames)
        update_record(simulation, self._lock, state='finished', wall_seconds=time.monotonic() - started,
                      operator={**simulation.operator, 'waiting': None, 'paused': False})
