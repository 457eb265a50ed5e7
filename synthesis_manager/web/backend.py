"""``SynthesisBackend``: the GUI's jobs, simulations and downloads, behind the routes."""

from __future__ import annotations

import dataclasses
import itertools
import logging
import queue
import shutil
import tempfile
import threading
import time
import uuid
from collections import OrderedDict
from pathlib import Path
from typing import Callable

from atlas_sim.executive.runtime_control import AUTONOMY_LEVELS, FULL, CommandError, checked_command
from ltl_specification.diagnosis import goal_findings
from ltl_specification.repair_process import RepairSearch, RepairSearchError, repair_settings
from respec.errors import INTERNAL_ERROR, CodedError, ErrorCode, quoted
from respec.robot import RobotSystem, SystemCatalog
from sm_generation.state_machine import StateMachine
from synthesis_manager.limits import BusyError
from synthesis_manager.web.artifacts import ARTIFACTS, Artifact, download_filename
from synthesis_manager.web.errors import (ArtifactFailedError, InvalidJobRequestError, NotAvailableError,
                                          NotFoundError)
from synthesis_manager.web.jobs import Job, JobRequest, ProgressNote, checked_body, names_field
from synthesis_manager.web.outcome import JobOutcome
from synthesis_manager.web.robot_views import common_choices, robot_view
from synthesis_manager.web.plays import Plays, play_body_moves
from synthesis_manager.web.simulation_process import SimulationProcess
from synthesis_manager.web.simulations import Simulation, simulation_available

logger = logging.getLogger(__name__)


SIMULATION_RETRY_AFTER = 10  # seconds: a short simulation's run time
GOAL_CHECK_RETRY_AFTER = 1  # seconds: a goal check of a shipped system takes milliseconds
REPAIR_TIME_BUDGET = 10.0   # seconds a "Suggest fixes" search may take (ltl_specification.repair's default)
REPAIR_MAX_PROPOSALS = 5

GoalRunner = Callable[[JobRequest, Callable[[str, float], None], threading.Event], JobOutcome]



@dataclasses.dataclass
class RepairRun:
    """A running repair search (``SynthesisBackend.start_repair``): its answers, and a stop."""

    answers: queue.Queue = dataclasses.field(default_factory=queue.Queue)
    stopped: threading.Event = dataclasses.field(default_factory=threading.Event)
    search: RepairSearch | None = None

    def stop(self) -> None:
        """End the search now (its child is killed); no answer comes after."""
        self.stopped.set()
        if self.search is not None:
            self.search.stop()

class SynthesisBackend:
    """Jobs run by ``run_goal(request, feedback, cancel) -> JobOutcome`` in worker threads.

    ``run_goal`` calls ``feedback(status, progress)`` as the pipeline advances and stops
    (returning a PREEMPTED outcome) once ``cancel`` is set.

    Jobs and simulations are returned as their records (Job, Simulation); the routes turn
    them into JSON.

    Test hook: ``job_gate`` is a set Event; while a test clears it, new jobs wait in the
    ``queued`` state before anything is sent, which makes cancelling them deterministic.
    """

    def __init__(self, run_goal: GoalRunner, config_dir: str | Path | None = None, systems=None,
                 max_jobs: int = 100, max_unfinished_jobs: int = 50, description: str = '',
                 max_running_simulations: int = 2, max_simulations_per_job: int = 5,
                 max_goal_checks: int = 2, max_repairs: int = 2, repair_time_budget: float = REPAIR_TIME_BUDGET):
        self.run_goal = run_goal
        # Where the robot systems come from: the suite's own (SuiteSystems, served over ROS)
        # when attached to a running suite, else the config directory's (SystemCatalog).
        self.catalog = systems if systems is not None else SystemCatalog(config_dir or None)
        self.max_jobs = max_jobs
        self.max_unfinished_jobs = max_unfinished_jobs
        # A simulation takes a process of ~225 MiB and a core for up to minutes: only a few run
        # at once, and a job keeps only its newest few runs (frames included).
        self.max_running_simulations = max_running_simulations
        self.max_simulations_per_job = max_simulations_per_job
        # The form's live goal check runs in the request's thread and costs CPU and memory with
        # the system's size: only a few at once (10 large ones once took 64 s of CPU, +636 MiB).
        self.max_goal_checks = max_goal_checks
        self._goal_check_slots = threading.BoundedSemaphore(max_goal_checks)
        # A repair search takes a child process and a core for up to its time budget; a play
        # (in the request's thread, like the goal check) solves the environment's game once.
        self.max_repairs = max_repairs
        self.repair_time_budget = repair_time_budget
        self._repair_slots = threading.BoundedSemaphore(max_repairs)
        self._repair_searches: set[RepairSearch] = set()
        self._play_slots = threading.BoundedSemaphore(max_goal_checks)
        self.plays = Plays(self.robot_system)
        self.description = description
        self.job_gate = threading.Event()
        self.job_gate.set()
        self.stopping = threading.Event()
        self._jobs: OrderedDict[str, Job] = OrderedDict()
        self._lock = threading.Lock()
        self._artifacts: dict[tuple[str, str], Artifact] = {}
        self._counter = itertools.count(1)
        self._simulations: dict[str, Simulation] = {}
        self._simulation_processes: set[SimulationProcess] = set()
        self._simulation_children: dict[str, SimulationProcess] = {}   # running simulation id -> its child
        self._simulation_dir = tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-')
        self.can_simulate = simulation_available()

    # systems ---------------------------------------------------------------------------

    def systems(self) -> list[str]:
        return self.catalog.names()

    def robot_system(self, system: str) -> RobotSystem:
        """The robot system of a request, as the suite synthesizes for it (NotFoundError if unknown)."""
        names = self.systems()
        if system not in names:
            raise NotFoundError(f'unknown system {quoted(system)} (known systems: {", ".join(names)})', str(system))
        return self.catalog.load(system)

    def choices(self, system: str) -> dict:
        """What the form offers for ``system`` and what the abstraction panel draws, as its view
        (web/robot_views.py) answers, with whether the GUI can simulate it."""
        try:
            robot = self.robot_system(system)
            view = robot_view(robot)
            choices = common_choices(robot, view)
        except NotFoundError:
            raise
        except CodedError as error:
            raise NotAvailableError(str(error), error.item or system) from error
        return {**choices, 'simulation': view.simulation_support(self.can_simulate)}

    def goal_check(self, body) -> dict:
        """The request form's live check: chosen goals that can never be achieved, and why each
        other action or mode cannot be the next goal (ltl_specification.diagnosis).

        Beyond max_goal_checks at once: BusyError (429, Retry-After), nothing is checked."""
        body = checked_body(body)
        if not self._goal_check_slots.acquire(blocking=False):
            raise BusyError(f'{self.max_goal_checks} goal checks are running (at most {self.max_goal_checks} at once); '
                            'try again in a moment', 'goal-check', retry_after=GOAL_CHECK_RETRY_AFTER)
        try:
            return self._check_goals(body)
        finally:
            self._goal_check_slots.release()

    def _check_goals(self, body: dict) -> dict:
        system = body.get('system')
        if system not in self.systems():
            raise NotFoundError(f'unknown system {quoted(system)}', str(system))
        initial_conditions = names_field(body, 'initial_conditions')
        goals = names_field(body, 'goals')
        strict_order = not body.get('unordered', False)
        try:
            robot = self.catalog.load(system)
            findings = goal_findings(robot, initial_conditions, goals, strict_order)
            impossible = robot_view(robot).impossible_next(initial_conditions, goals, strict_order)
        except CodedError as error:  # e.g. an invalid abstraction: the synthesis will say it
            raise NotAvailableError(str(error), error.item or system) from error
        return {'findings': [dataclasses.asdict(f) for f in findings], 'impossible_next': impossible}

    # repairs and plays ----------------------------------------------------------------

    def repair(self, body) -> dict:
        """Verified changes that make a job's request possible (``ltl_specification.repair``), as
        ``Repairs.to_dict()`` (see :meth:`start_repair`)."""
        answers = self.start_repair(body).answers
        while True:
            kind, value = answers.get()
            if kind == 'error':
                raise value
            if kind == 'result':
                return value

    def start_repair(self, body) -> RepairRun:
        """Start searching for fixes of a job's request: in a child process (ltl_specification.repair_process)
        on the robot system the GUI has (perhaps a remote suite's), for at most
        ``repair_time_budget`` seconds. Its ``answers`` queue gets ``('proposal', dict)`` as each
        proposal is verified, then ``('result', Repairs.to_dict())`` or ``('error', GuiRequestError)``;
        ``stop()`` ends it (a client that went away).

        Beyond max_repairs at once: BusyError (429, Retry-After), nothing is searched."""
        from ltl_specification.repair import TaskRequest

        if self.stopping.is_set():
            raise BusyError('the server is stopping', 'repairs')
        request = JobRequest.from_json(body, self.systems())
        robot = self.robot_system(request.system)
        if not self._repair_slots.acquire(blocking=False):
            raise BusyError(f'{self.max_repairs} repair searches are running (at most {self.max_repairs} at once); '
                            'try again when one has finished', 'repairs', retry_after=int(self.repair_time_budget))
        task = TaskRequest(request.system, request.initial_conditions, request.goals, request.sm_outcomes,
                           request.unordered)
        settings = repair_settings(robot, task.to_dict(), request.custom_ltl, self.repair_time_budget,
                                   REPAIR_MAX_PROPOSALS)
        run = RepairRun()
        threading.Thread(target=self._search_repairs, args=(settings, run), name='gui-repair',
                         daemon=True).start()
        return run

    def _search_repairs(self, settings: dict, run: RepairRun):
        """One search, its slot released when it ends, however it ends."""
        answers = run.answers
        search = None
        try:
            search = run.search = RepairSearch(settings)
            with self._lock:
                self._repair_searches.add(search)
            if self.stopping.is_set() or run.stopped.is_set():
                search.stop()
            answers.put(('result', search.run(lambda proposal: answers.put(('proposal', proposal)))))
        except CodedError as error:  # the system's files as the compiler refuses them
            answers.put(('error', NotAvailableError(str(error), error.item or settings['system'])))
        except Exception as error:  # RepairSearchError, or the child could not start
            if not isinstance(error, RepairSearchError):
                logger.exception('repair search failed')
            answers.put(('error', NotAvailableError(str(error), 'repair search')))
        finally:
            with self._lock:
                self._repair_searches.discard(search)
            self._repair_slots.release()

    def play(self, job_id: str, body) -> dict:
        """The turn of a play of a finished job after the body's ``moves`` (web/plays.py).

        Beyond max_goal_checks plays at once: BusyError (429, Retry-After)."""
        job = self._job(job_id)
        moves = play_body_moves(checked_body({} if body is None else body))
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        if not self._play_slots.acquire(blocking=False):
            raise BusyError(f'{self.max_goal_checks} plays are being computed (at most {self.max_goal_checks} at once); '
                            'try again in a moment', 'plays', retry_after=GOAL_CHECK_RETRY_AFTER)
        try:
            return self.plays.turn(job, moves)
        finally:
            self._play_slots.release()

    # jobs ------------------------------------------------------------------------------

    def stop(self):
        """The server is stopping: cancel every unfinished job (its goal too), end the running
        simulations and the event streams."""
        self.stopping.set()
        with self._lock:
            unfinished = [job for job in self._jobs.values() if not job.finished]
        for job in unfinished:
            job.cancel_requested.set()
        with self._lock:
            running = list(self._simulation_processes) + list(self._repair_searches)
        for child in running:
            child.stop()

    def start_job(self, body) -> Job:
        if self.stopping.is_set():
            raise BusyError('the server is stopping', 'jobs')
        request = JobRequest.from_json(body, self.systems())
        job = Job(id=f'{next(self._counter)}-{uuid.uuid4().hex[:8]}', request=request)
        with self._lock:
            unfinished = sum(1 for other in self._jobs.values() if not other.finished)
            if unfinished >= self.max_unfinished_jobs:
                raise BusyError(f'{unfinished} jobs are unfinished (at most {self.max_unfinished_jobs}); '
                                'try again when one has finished', 'jobs')
            self._jobs[job.id] = job
            self._forget_old_jobs()
        threading.Thread(target=self._work, args=(job,), name=f'gui-job-{job.id}', daemon=True).start()
        return job

    def cancel_job(self, job_id: str) -> Job:
        job = self._job(job_id)
        if job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has already finished '
                                    f'({job.outcome.error_name})', job_id)
        job.cancel_requested.set()
        self._note(job, 'Cancel requested', job.progress)
        return job

    def job_status(self, job_id: str) -> Job:
        return self._job(job_id)

    def job_revision(self, job_id: str) -> int:
        return self._job(job_id).revision

    def artifact(self, job_id: str, name: str) -> Artifact:
        job = self._job(job_id)
        if name not in ARTIFACTS:
            raise NotFoundError(f'unknown artifact {quoted(name)} (artifacts: {", ".join(ARTIFACTS)})', name)
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        kind = ARTIFACTS[name]
        if not kind.present(job.outcome):
            raise NotAvailableError(
                f'job {quoted(job_id)} ({job.outcome.error_name}) has no {name}', name)
        key = (job_id, name)
        if key not in self._artifacts:
            try:
                content = kind.build(job.outcome, job.request, self.catalog)
            except Exception as error:  # e.g. RenderError when Graphviz is missing; keep serving
                if not isinstance(error, CodedError):
                    logger.exception('building %s of job %s failed', name, job_id)
                raise ArtifactFailedError(f'cannot make {name}: {error}',
                                          getattr(error, 'item', '') or name) from error
            self._artifacts[key] = Artifact(content, kind.media_type, download_filename(job.request, name))
        return self._artifacts[key]

    def state_machine(self, job_id: str) -> StateMachine:
        """The job's state machine (its tree, as the job's outcome holds it)."""
        job = self._job(job_id)
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        if job.outcome.machine is None:
            raise NotAvailableError(f'job {quoted(job_id)} ({job.outcome.error_name}) has no state machine', job_id)
        return job.outcome.machine

    # simulations ------------------------------------------------------------------------

    def start_simulation(self, job_id: str, body) -> Simulation:
        """Run the state machine of a finished job on atlas_sim's simulated robot."""
        job = self._job(job_id)
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
        if not (job.finished and job.outcome.machine is not None):
            raise NotAvailableError(f'job {quoted(job_id)} has no state machine to simulate', job_id)
        try:
            robot = self.catalog.load(job.request.system)
        except CodedError as error:
            raise NotAvailableError(str(error), error.item or job.request.system) from error
        view = robot_view(robot)
        support = view.simulation_support(self.can_simulate)
        if not support['available']:
            raise NotAvailableError(support['note'], job.request.system)
        unknown = sorted(set(sensors) - set(support.get('sensors', ())))
        if unknown:
            raise InvalidJobRequestError(f'{quoted(unknown[0])} is no sensor of {job.request.system} '
                                         f'(sensors: {", ".join(support.get("sensors", ())) or "none"})', unknown[0])
        simulation = Simulation(id=f'{job_id}-sim{next(self._counter)}', job_id=job_id, fail_first=fail_first,
                                operator={'autonomy': autonomy, 'paused': False, 'waiting': None},
                                sensors=dict(sensors), sensor_names=tuple(support.get('sensors', ())))
        with self._lock:
            self._admit_simulation(job_id)
            self._simulations[simulation.id] = simulation
        threading.Thread(target=self._simulate, args=(simulation, job, robot, view.simulator),
                         name=f'gui-{simulation.id}', daemon=True).start()
        return simulation

    def _admit_simulation(self, job_id: str):
        """Refuse a run beyond max_running_simulations (429); make room for it among the job's
        max_simulations_per_job newest runs by forgetting its oldest finished one. Holds _lock."""
        running = [run for run in self._simulations.values() if run.state != 'finished']
        if len(running) >= self.max_running_simulations:
            raise BusyError(
                f'{len(running)} simulations are running (at most {self.max_running_simulations} at once); '
                'try again when one has finished', 'simulations', retry_after=SIMULATION_RETRY_AFTER)
        runs = [run for run in self._simulations.values() if run.job_id == job_id]
        finished = [run for run in runs if run.state == 'finished']
        for run in finished[:max(0, len(runs) + 1 - self.max_simulations_per_job)]:
            self._forget_simulation(run.id)

    def _forget_simulation(self, simulation_id: str):
        """Drop a finished simulation and its recorded frames. Holds _lock."""
        self._simulations.pop(simulation_id, None)
        shutil.rmtree(self._record_dir(simulation_id), ignore_errors=True)

    def _record_dir(self, simulation_id: str) -> Path:
        return Path(self._simulation_dir.name) / simulation_id

    def simulation_status(self, simulation_id: str) -> Simulation:
        return self._simulation(simulation_id)

    def simulation_revision(self, simulation_id: str) -> int:
        return self._simulation(simulation_id).revision

    def simulation_frame(self, simulation_id: str, index: int) -> Artifact:
        simulation = self._simulation(simulation_id)
        if not 0 <= index < len(simulation.frames):
            raise NotFoundError(f'simulation {quoted(simulation_id)} has no frame {index}', str(index))
        path = simulation.frames[index]
        return Artifact(path.read_bytes(), 'image/png', path.name)

    def simulation_timeline(self, simulation_id: str) -> Artifact:
        simulation = self._simulation(simulation_id)
        if simulation.timeline_png is None:
            raise NotAvailableError(f'simulation {quoted(simulation_id)} has no timeline yet', simulation_id)
        return Artifact(simulation.timeline_png.read_bytes(), 'image/png', f'{simulation_id}_timeline.png')

    def _simulation(self, simulation_id: str) -> Simulation:
        with self._lock:
            simulation = self._simulations.get(simulation_id)
        if simulation is None:
            raise NotFoundError(f'unknown simulation {quoted(simulation_id)}', simulation_id)
        return simulation

    def _simulate(self, simulation: Simulation, job: Job, robot: RobotSystem, simulator: str):
        """Run ``simulation`` of ``job`` on ``robot`` in its child process (web/simulation_process.py,
        its function ``simulator``: the robot view's), following it. The child gets the system's
        files as read here, not a path to read them again."""
        request, started = job.request, time.monotonic()
        child = SimulationProcess({
            'machine': job.outcome.machine,
            'ltl_specification': job.outcome.ltl_specification,
            'system': robot.name, 'files': dict(robot.files), 'config_file': robot.config_file,
            'initial_conditions': list(request.initial_conditions), 'goals': list(request.goals),
            'ordered': not request.unordered, 'fail_first': list(simulation.fail_first),
            'record_dir': str(self._record_dir(simulation.id)), 'max_robot_time': 300.0, 'max_wall_time': 300.0,
            'autonomy': simulation.operator['autonomy'], 'automaton': job.outcome.automaton,
            'sensors': dict(simulation.sensors)}, simulator)
        with self._lock:
            self._simulation_processes.add(child)
            self._simulation_children[simulation.id] = child
        if self.stopping.is_set():
            child.stop()

        def progress(update):
            simulation.robot_time = update['robot_time']
            self._update(simulation, steps=update['steps'], frames=[Path(path) for path in update['frames']],
                         operator=update.get('operator') or simulation.operator)

        try:
            final = child.run(progress)
        finally:
            with self._lock:
                self._simulation_processes.discard(child)
                self._simulation_children.pop(simulation.id, None)
        if 'result' in final:
            result = final['result']
            simulation.robot_time = result['robot_time']
            self._update(simulation, outcome=result['outcome'], check=result['check'], steps=result['steps'],
                         timeline_png=Path(result['timeline']) if result['timeline'] else None,
                         frames=[Path(path) for path in result['frames']],
                         operator_events=result.get('operator_events', []))
        else:
            self._update(simulation, error=final['error'],
                         steps=simulation.steps if final['steps'] is None else final['steps'],
                         frames=[Path(path) for path in final['frames']] if final.get('frames') else simulation.frames)
        self._update(simulation, state='finished', wall_seconds=time.monotonic() - started,
                     operator={**simulation.operator, 'waiting': None, 'paused': False})

    def simulation_command(self, simulation_id: str, body) -> Simulation:
        """Pass an operator command (atlas_sim.executive.runtime_control) to a running simulation."""
        simulation = self._simulation(simulation_id)
        try:
            command = checked_command(checked_body({} if body is None else body))
        except CommandError as error:
            raise InvalidJobRequestError(str(error), 'command') from None
        if command['command'] == 'sensor' and command['name'] not in simulation.sensor_names:
            raise InvalidJobRequestError(f'{quoted(command["name"])} is no sensor of this run\'s robot '
                                         f'(sensors: {", ".join(simulation.sensor_names) or "none"})', command['name'])
        with self._lock:
            child = self._simulation_children.get(simulation_id)
        if child is None or simulation.state == 'finished' or not child.command(command):
            raise NotAvailableError(f'simulation {quoted(simulation_id)} is not running', simulation_id)
        return simulation

    def _job(self, job_id: str) -> Job:
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise NotFoundError(f'unknown job {quoted(job_id)}', job_id)
        return job

    def _forget_old_jobs(self):
        finished = [job_id for job_id, job in self._jobs.items() if job.finished]
        for job_id in finished[:max(0, len(self._jobs) - self.max_jobs)]:
            del self._jobs[job_id]
            for key in [k for k in self._artifacts if k[0] == job_id]:
                del self._artifacts[key]
            for run_id in [r for r, run in self._simulations.items() if run.job_id == job_id]:
                self._forget_simulation(run_id)

    def _update(self, record, **changes):
        """Change a Job or Simulation and bump its revision (what the event streams watch)."""
        with self._lock:
            for name, value in changes.items():
                setattr(record, name, value)
            record.revision += 1

    def _work(self, job: Job):
        while not self.job_gate.wait(0.05):
            if job.cancel_requested.is_set():
                break
        if job.cancel_requested.is_set():  # never sent: nothing to cancel downstream
            self._finish(job, JobOutcome.local(ErrorCode.PREEMPTED, 'cancelled before it was sent',
                                               job.seconds_since_created()))
            return
        self._update(job, state='running', status='sending the goal')

        try:
            outcome = self.run_goal(job.request, lambda status, progress: self._note(job, status, progress),
                                    job.cancel_requested)
        except Exception as error:  # the GUI keeps serving whatever the runner does
            logger.exception('job %s failed', job.id)
            outcome = JobOutcome.local(INTERNAL_ERROR, f'the GUI could not run the goal: {error}',
                                       job.seconds_since_created())
        self._finish(job, outcome)

    def _note(self, job: Job, status: str, progress: float):
        """A new status of ``job``: shown now and kept in its timeline."""
        note = ProgressNote(job.seconds_since_created(), status, round(float(progress), 4))
        self._update(job, status=status, progress=float(progress), timeline=job.timeline + [note])

    def _finish(self, job: Job, outcome: JobOutcome):
        if outcome.cancelled:
            self._note(job, 'Cancelled', job.progress)
        self._update(job, state='finished', outcome=outcome, status=outcome.error_name,
                     finished_after=job.seconds_since_created(),
                     progress=1.0 if outcome.succeeded else job.progress)
