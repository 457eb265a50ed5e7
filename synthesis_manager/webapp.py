"""The synthesis web GUI as a FastAPI app (ROS-free): pages, JSON API, progress stream, downloads.

``create_app(backend)`` serves ``web/`` and these routes::

    GET  /                                   the page (web/index.html; app.js, style.css under /static)
    GET  /api/systems                        {"systems": [...]}
    GET  /api/systems/{system}               what a request may name: control modes, actions
    POST /api/jobs                           start a synthesis job -> 202 {"id": ..., ...}
    GET  /api/jobs/{id}                      its status, progress timeline, result and summary
    GET  /api/jobs/{id}/events               the same as server-sent events until the job ends
    POST /api/jobs/{id}/cancel               cancel it (the result becomes PREEMPTED)
    GET  /api/jobs/{id}/artifacts/{name}     a download (see ARTIFACTS); ?inline=1 to display it
    POST /api/jobs/{id}/simulations          run the job's state machine on the simulated robot
    GET  /api/simulations/{id}               its trace so far, frames, outcome and trace check
    GET  /api/simulations/{id}/events        the same as server-sent events until the run ends
    GET  /api/simulations/{id}/frames/{n}    key frame n (PNG); .../timeline.png the timeline plot

Bad input is answered with a 4xx JSON body ``{"error", "item", "message"}`` whose ``item``
names the offending system, field, job or artifact; the server keeps serving.

The backend does the work. :class:`SynthesisBackend` here keeps the jobs, validates
requests and builds the downloads; the synthesis itself is a ``run_goal`` callable given to
it (``gui.RosGoalRunner`` sends the goal to ``/behavior_synthesis``).
"""

from __future__ import annotations

import asyncio
import dataclasses
import itertools
import json
import re
import tempfile
import threading
import time
import uuid
from collections import OrderedDict
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable

from fastapi import Body, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, JSONResponse, Response, StreamingResponse
from fastapi.staticfiles import StaticFiles

from respec.systems import SystemConfigError, available_systems, load_section
from synthesis_manager.requests import parse_names

WEB_DIR = Path(__file__).with_name('web')
# The stop-early options the page offers (ltl_synthesis_only needs a whole specification).
JOB_OPTIONS = ('ltl_compilation_only', 'ltl_steps_only')
REQUEST_FIELDS = ('system', 'initial_conditions', 'goals', 'sm_outcomes', 'option', 'unordered', 'name')
_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')


# --- errors -------------------------------------------------------------------------------

class GuiRequestError(Exception):
    """A request the GUI cannot serve; ``item`` names what was wrong."""

    status = 400
    code = 'BAD_REQUEST'

    def __init__(self, message: str, item: str):
        super().__init__(message)
        self.item = item

    def to_dict(self) -> dict:
        return {'error': self.code, 'item': self.item, 'message': str(self)}


class NotFoundError(GuiRequestError):
    """An unknown system, job or artifact name."""

    status = 404
    code = 'NOT_FOUND'


class InvalidJobRequestError(GuiRequestError):
    """A job request with a missing, mistyped or malformed field."""

    status = 422
    code = 'INVALID_REQUEST'


class NotAvailableError(GuiRequestError):
    """The item exists but not in this state (e.g. no state machine to download yet)."""

    status = 409
    code = 'NOT_AVAILABLE'


class ArtifactFailedError(GuiRequestError):
    """Building a download failed (e.g. Graphviz is not installed)."""

    status = 500
    code = 'ARTIFACT_FAILED'


# --- requests -----------------------------------------------------------------------------

@dataclass(frozen=True)
class JobRequest:
    """What the page asks for; ``goals`` in the order they must be achieved."""

    system: str
    initial_conditions: tuple[str, ...]
    goals: tuple[str, ...]
    sm_outcomes: tuple[str, ...] = ('finished', 'failed')
    option: str | None = None
    unordered: bool = False
    name: str = ''

    @classmethod
    def from_json(cls, body, systems: list[str]) -> 'JobRequest':
        """Validate a decoded JSON body; names may be lists or comma/space-separated text.

        Goal and initial-condition names are not checked against the system here: the
        pipeline does that and explains unknown names itself (UNKNOWN_PROPOSITION).
        """
        if not isinstance(body, dict):
            raise InvalidJobRequestError('the request body must be a JSON object', 'body')
        unknown = sorted(set(body) - set(REQUEST_FIELDS))
        if unknown:
            raise InvalidJobRequestError(
                f'unknown field {unknown[0]!r} (fields: {", ".join(REQUEST_FIELDS)})', unknown[0])
        system = body.get('system')
        if not isinstance(system, str) or not system:
            raise InvalidJobRequestError('field "system" must name a system', 'system')
        if system not in systems:
            raise NotFoundError(f'unknown system {system!r} (known systems: {", ".join(systems)})', system)
        goals = _names(body, 'goals')
        if not goals:
            raise InvalidJobRequestError('field "goals" must name at least one goal', 'goals')
        sm_outcomes = _names(body, 'sm_outcomes') or ('finished', 'failed')
        option = body.get('option') or None
        if option is not None and option not in JOB_OPTIONS:
            raise InvalidJobRequestError(
                f'unknown option {option!r} (options: {", ".join(JOB_OPTIONS)})', str(option))
        unordered = body.get('unordered', False)
        if not isinstance(unordered, bool):
            raise InvalidJobRequestError('field "unordered" must be true or false', 'unordered')
        name = body.get('name') or ''
        if not isinstance(name, str) or (name and not _NAME.match(name)):
            raise InvalidJobRequestError(
                f'behavior name {name!r} must start with a letter and contain only letters, '
                'digits and underscores', str(name))
        return cls(system=system, initial_conditions=_names(body, 'initial_conditions'), goals=goals,
                   sm_outcomes=sm_outcomes, option=option, unordered=unordered, name=name)


def _names(body: dict, key: str) -> tuple[str, ...]:
    value = body.get(key) or []
    if isinstance(value, list) and not all(isinstance(v, str) for v in value):
        raise InvalidJobRequestError(f'field {key!r} must be a list of names', key)
    if not isinstance(value, (str, list)):
        raise InvalidJobRequestError(f'field {key!r} must be a list of names or comma-separated text', key)
    names = tuple(parse_names(value))
    for name in names:
        if not _NAME.match(name):
            raise InvalidJobRequestError(f'{key}: {name!r} is not a proposition name', name)
    return names


# --- jobs ---------------------------------------------------------------------------------

@dataclass
class Job:
    """One synthesis request and everything that happened to it."""

    id: str
    request: JobRequest
    state: str = 'queued'              # queued -> running -> finished
    status: str = 'waiting to be sent'
    progress: float = 0.0
    timeline: list[dict] = field(default_factory=list)  # {'seconds', 'status', 'progress'}
    outcome: dict | None = None        # SynthesisOutcome.to_dict() once finished
    cancel_requested: threading.Event = field(default_factory=threading.Event, repr=False)
    created: float = field(default_factory=time.monotonic, repr=False)
    revision: int = 0                  # bumped on every change, so streams send only news
    finished_after: float = 0.0        # seconds from creation to the result

    @property
    def finished(self) -> bool:
        return self.state == 'finished'

    def to_dict(self) -> dict:
        return {'id': self.id, 'state': self.state, 'status': self.status,
                'progress': round(self.progress, 4), 'request': asdict(self.request),
                'cancel_requested': self.cancel_requested.is_set(),
                'timeline': list(self.timeline), 'outcome': self.outcome,
                'summary': result_summary(self.outcome) if self.outcome else None,
                'stages': stage_timings(self.timeline, self.finished_after) if self.outcome else [],
                'artifacts': available_artifacts(self.outcome) if self.outcome else []}


# Values of synthesis_msgs/SynthesisErrorCodes for the outcomes the GUI makes itself.
LOCAL_ERROR_CODES = {'PREEMPTED': -9, 'FAILURE': 99999}


def local_outcome(error_name: str, message: str, job: Job) -> dict:
    """An outcome (SynthesisOutcome.to_dict() shape) for a job that never got a result."""
    return {'error_code': LOCAL_ERROR_CODES[error_name], 'error_name': error_name, 'message': message,
            'states': [], 'ltl_specification': {}, 'automaton': {},
            'seconds': round(time.monotonic() - job.created, 4)}


def result_summary(outcome: dict) -> dict:
    """Realizability and sizes of a finished job, as the result page shows them."""
    sections = outcome.get('ltl_specification') or {}
    automaton_states = len((outcome.get('automaton') or {}).get('states') or [])
    states = outcome.get('states') or []
    if outcome.get('error_name') == 'SPEC_UNSYNTHESIZABLE':
        realizable = False
    elif automaton_states:
        realizable = True
    else:
        realizable = None  # synthesis did not run (compile only, or an earlier failure)
    return {
        'succeeded': outcome.get('error_name') == 'SUCCESS',
        'realizable': realizable,
        'input_propositions': len(sections.get('env_props', [])),
        'output_propositions': len(sections.get('sys_props', [])),
        'formulas': sum(len(lines) for name, lines in sections.items() if not name.endswith('_props')),
        'automaton_states': automaton_states,
        # the root entry '/' is the machine itself, not one of its states
        'state_machine_states': sum(1 for s in states if s['state_path'] != '/'),
        'state_instantiations': len(states),
        'concurrency_containers': sum(1 for s in states if s['state_class'] == ':CONCURRENCY'),
        'seconds': outcome.get('seconds', 0.0),
    }


def stage_timings(timeline: list[dict], total_seconds: float) -> list[dict]:
    """How long each pipeline stage took, from the feedback timeline.

    A stage starts with a status whose first word is a gerund ("Compiling ...",
    "Synthesizing ...") and lasts until the next status (or the end of the job).
    """
    stages = []
    for index, entry in enumerate(timeline):
        first_word = entry['status'].split(' ', 1)[0]
        if not first_word.endswith('ing'):
            continue
        end = timeline[index + 1]['seconds'] if index + 1 < len(timeline) else total_seconds
        stages.append({'stage': entry['status'], 'seconds': round(max(0.0, end - entry['seconds']), 4)})
    return stages


# --- simulation ---------------------------------------------------------------------------

@dataclass
class Simulation:
    """One closed-loop run of a job's state machine on the simulated robot (atlas_sim)."""

    id: str
    job_id: str
    fail_first: tuple[str, ...] = ()   # capabilities whose first attempt fails
    state: str = 'running'             # running -> finished
    steps: list[dict] = field(default_factory=list)  # atlas_sim TraceStep dicts so far
    robot_time: float = 0.0
    frames: list[Path] = field(default_factory=list, repr=False)
    timeline_png: Path | None = field(default=None, repr=False)
    outcome: str | None = None         # the SM outcome reached
    error: dict | None = None          # {'code', 'item', 'message'} if the run broke off
    check: dict | None = None          # atlas_sim trace check report
    wall_seconds: float = 0.0
    revision: int = 0

    def to_dict(self) -> dict:
        return {'id': self.id, 'job_id': self.job_id, 'fail_first': list(self.fail_first),
                'state': self.state, 'steps': list(self.steps), 'robot_time': round(self.robot_time, 3),
                'frames': [{'index': i, 'label': p.stem} for i, p in enumerate(self.frames)],
                'timeline': self.timeline_png is not None, 'outcome': self.outcome,
                'error': self.error, 'check': self.check, 'wall_seconds': round(self.wall_seconds, 3)}


def simulation_available() -> bool:
    """Whether atlas_sim (MuJoCo) can be imported in this installation."""
    try:
        import atlas_sim.executor  # noqa: F401
    except ImportError:
        return False
    return True


# --- downloads ----------------------------------------------------------------------------

@dataclass(frozen=True)
class Artifact:
    content: bytes
    media_type: str
    filename: str


def _state_list(outcome):
    from sm_generation import StateInstantiation

    return [StateInstantiation.from_dict(s) for s in outcome['states']]


def _export(kind):
    def build(outcome) -> bytes:
        from sm_generation import export

        return getattr(export, kind)(_state_list(outcome)).encode()
    return build


def _picture(fmt):
    def build(outcome) -> bytes:
        from sm_generation.export import render, to_dot

        with tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-') as directory:
            path = render(to_dot(_state_list(outcome)), Path(directory) / f'state_machine.{fmt}')
            return path.read_bytes()
    return build


def _specification(method):
    def build(outcome) -> bytes:
        from respec.parsing import spec_from_text_sections

        return getattr(spec_from_text_sections(outcome['ltl_specification']), method)().encode()
    return build


def _has_states(outcome):
    return bool(outcome.get('states'))


def _has_specification(outcome):
    return bool(outcome.get('ltl_specification'))


def _has_automaton(outcome):
    return bool((outcome.get('automaton') or {}).get('states'))


# name -> (media type, is it there for this outcome?, build bytes from the outcome)
ARTIFACTS = {
    'state_machine.yaml': ('application/yaml', _has_states, _export('to_yaml')),
    'state_machine.json': ('application/json', _has_states, _export('to_json')),
    'state_machine.dot': ('text/vnd.graphviz', _has_states, _export('to_dot')),
    'state_machine.svg': ('image/svg+xml', _has_states, _picture('svg')),
    'state_machine.png': ('image/png', _has_states, _picture('png')),
    'specification.structuredslugs': ('text/plain', _has_specification, _specification('to_structuredslugs')),
    'specification.slugsin': ('text/plain', _has_specification, _specification('to_slugsin')),
    'automaton.json': ('application/json', _has_automaton,
                       lambda outcome: (json.dumps(outcome['automaton'], indent=1) + '\n').encode()),
    'result.json': ('application/json', lambda outcome: True,
                    lambda outcome: (json.dumps(outcome, indent=1) + '\n').encode()),
}


def available_artifacts(outcome: dict) -> list[str]:
    return [name for name, (_, present, _) in ARTIFACTS.items() if present(outcome)]


# --- the backend --------------------------------------------------------------------------

GoalRunner = Callable[[JobRequest, Callable[[str, float], None], threading.Event], dict]


class SynthesisBackend:
    """Jobs run by ``run_goal(request, feedback, cancel) -> outcome dict`` in worker threads.

    ``run_goal`` calls ``feedback(status, progress)`` as the pipeline advances and stops
    (returning a PREEMPTED outcome) once ``cancel`` is set.

    Test hook: ``job_gate`` is a set Event; while a test clears it, new jobs wait in the
    ``queued`` state before anything is sent, which makes cancelling them deterministic.
    """

    def __init__(self, run_goal: GoalRunner, config_dir: str | Path | None = None,
                 max_jobs: int = 100, description: str = ''):
        self.run_goal = run_goal
        self.config_dir = config_dir or None
        self.max_jobs = max_jobs
        self.description = description
        self.job_gate = threading.Event()
        self.job_gate.set()
        self._jobs: OrderedDict[str, Job] = OrderedDict()
        self._lock = threading.Lock()
        self._artifacts: dict[tuple[str, str], Artifact] = {}
        self._counter = itertools.count(1)
        self._simulations: dict[str, Simulation] = {}
        self._simulation_dir = tempfile.TemporaryDirectory(prefix='behavior-synthesis-gui-')
        self.can_simulate = simulation_available()

    # systems ---------------------------------------------------------------------------

    def systems(self) -> list[str]:
        return available_systems(self.config_dir)

    def choices(self, system: str) -> dict:
        """The control modes and actions of ``system``, in file order, with their relations."""
        if system not in self.systems():
            raise NotFoundError(f'unknown system {system!r} (known systems: {", ".join(self.systems())})',
                                system)
        try:
            abstraction = load_section(system, 'abstraction', self.config_dir)
        except SystemConfigError as error:
            raise NotAvailableError(str(error), error.item or system) from error
        modes = abstraction.get('control_modes') or {}
        actions = abstraction.get('actions') or {}
        return {
            'system': system,
            'control_modes': [{'name': m, 'next': list(n or [])} for m, n in modes.items()],
            'actions': [{'name': a, 'preconditions': list(p or [])} for a, p in actions.items()],
            'default_initial_conditions': list(modes)[:1],
            'sm_outcome_choices': [['finished', 'failed'], ['finished']],
            'options': list(JOB_OPTIONS),
        }

    # jobs ------------------------------------------------------------------------------

    def start_job(self, body) -> dict:
        request = JobRequest.from_json(body, self.systems())
        job = Job(id=f'{next(self._counter)}-{uuid.uuid4().hex[:8]}', request=request)
        with self._lock:
            self._jobs[job.id] = job
            self._forget_old_jobs()
        threading.Thread(target=self._work, args=(job,), name=f'gui-job-{job.id}', daemon=True).start()
        return job.to_dict()

    def cancel_job(self, job_id: str) -> dict:
        job = self._job(job_id)
        if job.finished:
            raise NotAvailableError(f'job {job_id!r} has already finished '
                                    f'({job.outcome["error_name"]})', job_id)
        job.cancel_requested.set()
        self._update(job, status='cancelling')
        return job.to_dict()

    def job_status(self, job_id: str) -> dict:
        return self._job(job_id).to_dict()

    def job_revision(self, job_id: str) -> int:
        return self._job(job_id).revision

    def artifact(self, job_id: str, name: str) -> Artifact:
        job = self._job(job_id)
        if name not in ARTIFACTS:
            raise NotFoundError(f'unknown artifact {name!r} (artifacts: {", ".join(ARTIFACTS)})', name)
        if not job.finished:
            raise NotAvailableError(f'job {job_id!r} has not finished yet', job_id)
        media_type, present, build = ARTIFACTS[name]
        if not present(job.outcome):
            raise NotAvailableError(
                f'job {job_id!r} ({job.outcome["error_name"]}) has no {name}', name)
        key = (job_id, name)
        if key not in self._artifacts:
            try:
                content = build(job.outcome)
            except Exception as error:  # e.g. RenderError when Graphviz is missing
                raise ArtifactFailedError(f'cannot make {name}: {error}',
                                          getattr(error, 'item', '') or name) from error
            self._artifacts[key] = Artifact(content, media_type, f'{job.request.name or "behavior"}_{name}')
        return self._artifacts[key]

    # simulations ------------------------------------------------------------------------

    def start_simulation(self, job_id: str, body) -> dict:
        """Run the state machine of a finished job on atlas_sim's simulated robot."""
        job = self._job(job_id)
        body = {} if body is None else body
        if not isinstance(body, dict):
            raise InvalidJobRequestError('the request body must be a JSON object', 'body')
        unknown = sorted(set(body) - {'fail_first'})
        if unknown:
            raise InvalidJobRequestError(f'unknown field {unknown[0]!r} (fields: fail_first)', unknown[0])
        fail_first = _names(body, 'fail_first')
        if not self.can_simulate:
            raise NotAvailableError('simulation needs atlas_sim and MuJoCo, which are not installed',
                                    'atlas_sim')
        if not (job.finished and job.outcome.get('states')):
            raise NotAvailableError(f'job {job_id!r} has no state machine to simulate', job_id)
        try:
            load_section(job.request.system, 'simulation', self.config_dir)
        except SystemConfigError as error:
            raise NotAvailableError(f'system {job.request.system!r} cannot be simulated: {error}',
                                    job.request.system) from error
        simulation = Simulation(id=f'{job_id}-sim{next(self._counter)}', job_id=job_id, fail_first=fail_first)
        with self._lock:
            self._simulations[simulation.id] = simulation
        threading.Thread(target=self._simulate, args=(simulation, job), name=f'gui-{simulation.id}',
                         daemon=True).start()
        return simulation.to_dict()

    def simulation_status(self, simulation_id: str) -> dict:
        return self._simulation(simulation_id).to_dict()

    def simulation_revision(self, simulation_id: str) -> int:
        return self._simulation(simulation_id).revision

    def simulation_frame(self, simulation_id: str, index: int) -> Artifact:
        simulation = self._simulation(simulation_id)
        if not 0 <= index < len(simulation.frames):
            raise NotFoundError(f'simulation {simulation_id!r} has no frame {index}', str(index))
        path = simulation.frames[index]
        return Artifact(path.read_bytes(), 'image/png', path.name)

    def simulation_timeline(self, simulation_id: str) -> Artifact:
        simulation = self._simulation(simulation_id)
        if simulation.timeline_png is None:
            raise NotAvailableError(f'simulation {simulation_id!r} has no timeline yet', simulation_id)
        return Artifact(simulation.timeline_png.read_bytes(), 'image/png', f'{simulation_id}_timeline.png')

    def _simulation(self, simulation_id: str) -> Simulation:
        with self._lock:
            simulation = self._simulations.get(simulation_id)
        if simulation is None:
            raise NotFoundError(f'unknown simulation {simulation_id!r}', simulation_id)
        return simulation

    def _simulate(self, simulation: Simulation, job: Job):
        import os

        os.environ.setdefault('MUJOCO_GL', 'egl')  # off-screen rendering, before mujoco loads
        from atlas_sim.executor import Executive, SimulatedRobot, StateMapping, make_simulator, parse_faults
        from atlas_sim.rendering import KeyFrameRecorder
        from atlas_sim.timeline import plot_timeline
        from atlas_sim.trace_check import check_trace
        from respec.parsing import spec_from_text_sections

        request, started = job.request, time.monotonic()
        directory = Path(self._simulation_dir.name) / simulation.id
        recorder = executive = None

        def watch(_robot):  # every control tick: publish only when a step or frame was added
            simulation.robot_time = simulator.time
            steps = executive.trace.steps
            if len(steps) != len(simulation.steps) or len(recorder.paths) != len(simulation.frames):
                self._update(simulation, steps=[dataclasses.asdict(step) for step in steps],
                             frames=list(recorder.paths))

        try:
            simulator = make_simulator(request.system, self.config_dir, request.initial_conditions,
                                       faults=parse_faults(fail_first=[f'{c}:1' for c in simulation.fail_first]))
            recorder = KeyFrameRecorder(simulator, directory / 'frames', width=480, height=360)
            recorder.capture('start')
            executive = Executive(job.outcome['states'], SimulatedRobot(simulator),
                                  StateMapping(request.system, self.config_dir),
                                  max_robot_time=300.0, max_wall_time=300.0, on_tick=watch)
            run = executive.run()
            recorder.capture('end')
            check = check_trace(run.trace, spec_from_text_sections(job.outcome['ltl_specification']),
                                goals=list(request.goals), ordered=not request.unordered)
            timeline = plot_timeline(run.trace, directory / 'timeline.png',
                                     f'{", ".join(request.goals)}: {run.outcome}')
            self._update(simulation, outcome=run.outcome, check=check.to_dict(), timeline_png=timeline,
                         steps=[dataclasses.asdict(step) for step in run.trace.steps])
        except Exception as error:  # ExecutionError, bad faults, rendering: report, keep serving
            trace = getattr(error, 'trace', None)
            self._update(simulation, error={
                'code': getattr(error, 'code', type(error).__name__), 'item': getattr(error, 'item', ''),
                'message': str(error)},
                steps=[dataclasses.asdict(step) for step in trace.steps] if trace else simulation.steps)
        finally:
            if recorder is not None:
                recorder.close()
                self._update(simulation, frames=list(recorder.paths))
            self._update(simulation, state='finished', wall_seconds=time.monotonic() - started)

    def _job(self, job_id: str) -> Job:
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise NotFoundError(f'unknown job {job_id!r}', job_id)
        return job

    def _forget_old_jobs(self):
        finished = [job_id for job_id, job in self._jobs.items() if job.finished]
        for job_id in finished[:max(0, len(self._jobs) - self.max_jobs)]:
            del self._jobs[job_id]
            for key in [k for k in self._artifacts if k[0] == job_id]:
                del self._artifacts[key]
            for run_id in [r for r, run in self._simulations.items() if run.job_id == job_id]:
                del self._simulations[run_id]

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
            self._finish(job, local_outcome('PREEMPTED', 'cancelled before it was sent', job))
            return
        self._update(job, state='running', status='sending the goal')

        def feedback(status: str, progress: float):
            entry = {'seconds': round(time.monotonic() - job.created, 4), 'status': status,
                     'progress': round(float(progress), 4)}
            self._update(job, status=status, progress=float(progress), timeline=job.timeline + [entry])

        try:
            outcome = self.run_goal(job.request, feedback, job.cancel_requested)
        except Exception as error:  # the GUI keeps serving whatever the runner does
            outcome = local_outcome('FAILURE', f'the GUI could not run the goal: {error}', job)
        self._finish(job, outcome)

    def _finish(self, job: Job, outcome: dict):
        self._update(job, state='finished', outcome=outcome, status=outcome['error_name'],
                     finished_after=round(time.monotonic() - job.created, 4),
                     progress=1.0 if outcome['error_name'] == 'SUCCESS' else job.progress)


# --- the app ------------------------------------------------------------------------------

def create_app(backend) -> FastAPI:
    """The GUI's FastAPI app around ``backend`` (a SynthesisBackend or the same methods)."""
    # No Swagger/ReDoc pages: they load third-party code from a CDN. The schema stays available.
    app = FastAPI(title='Behavior synthesis', docs_url=None, redoc_url=None, openapi_url='/api/openapi.json')
    app.mount('/static', StaticFiles(directory=WEB_DIR), name='static')

    @app.exception_handler(GuiRequestError)
    async def gui_error(_request, error: GuiRequestError):
        return JSONResponse(error.to_dict(), status_code=error.status)

    @app.exception_handler(RequestValidationError)
    async def malformed(_request, error: RequestValidationError):
        problem = error.errors()[0] if error.errors() else {'loc': ['body'], 'msg': 'malformed request'}
        item = '.'.join(str(part) for part in problem.get('loc', ['body']))
        return JSONResponse(InvalidJobRequestError(f'{item}: {problem.get("msg")}', item).to_dict(),
                            status_code=422)

    @app.get('/', include_in_schema=False)
    def index():
        return FileResponse(WEB_DIR / 'index.html', media_type='text/html')

    @app.get('/api/info')
    def info():
        return {'description': getattr(backend, 'description', ''),
                'simulation': bool(getattr(backend, 'can_simulate', False))}

    @app.get('/api/systems')
    def systems():
        return {'systems': backend.systems()}

    @app.get('/api/systems/{system}')
    def choices(system: str):
        return backend.choices(system)

    @app.post('/api/jobs', status_code=202)
    def start_job(body=Body(None)):
        return backend.start_job(body)

    @app.get('/api/jobs/{job_id}')
    def job_status(job_id: str):
        return backend.job_status(job_id)

    @app.post('/api/jobs/{job_id}/cancel', status_code=202)
    def cancel_job(job_id: str):
        return backend.cancel_job(job_id)

    @app.get('/api/jobs/{job_id}/events')
    async def job_events(job_id: str, request: Request):
        backend.job_status(job_id)  # unknown job: 404 now rather than an empty stream
        return _event_stream(request, lambda: backend.job_revision(job_id),
                             lambda: backend.job_status(job_id))

    @app.get('/api/jobs/{job_id}/artifacts/{name}')
    def artifact(job_id: str, name: str, inline: bool = False):
        return _file_response(backend.artifact(job_id, name), inline)

    @app.post('/api/jobs/{job_id}/simulations', status_code=202)
    def start_simulation(job_id: str, body=Body(None)):
        return backend.start_simulation(job_id, body)

    @app.get('/api/simulations/{simulation_id}')
    def simulation_status(simulation_id: str):
        return backend.simulation_status(simulation_id)

    @app.get('/api/simulations/{simulation_id}/events')
    async def simulation_events(simulation_id: str, request: Request):
        backend.simulation_status(simulation_id)
        return _event_stream(request, lambda: backend.simulation_revision(simulation_id),
                             lambda: backend.simulation_status(simulation_id))

    @app.get('/api/simulations/{simulation_id}/frames/{index}')
    def simulation_frame(simulation_id: str, index: int):
        return _file_response(backend.simulation_frame(simulation_id, index), inline=True)

    @app.get('/api/simulations/{simulation_id}/timeline.png')
    def simulation_timeline(simulation_id: str):
        return _file_response(backend.simulation_timeline(simulation_id), inline=True)

    return app


def _file_response(found: Artifact, inline: bool) -> Response:
    disposition = 'inline' if inline else 'attachment'
    return Response(found.content, media_type=found.media_type,
                    headers={'Content-Disposition': f'{disposition}; filename="{found.filename}"'})


def _event_stream(request: Request, revision: Callable[[], int], snapshot: Callable[[], dict]):
    """Server-sent events: ``progress`` with each new snapshot, then one ``finished``."""
    async def events():
        sent = -1
        while not await request.is_disconnected():
            current = revision()
            if current != sent:
                sent = current
                data = snapshot()
                kind = 'finished' if data['state'] == 'finished' else 'progress'
                yield f'event: {kind}\ndata: {json.dumps(data)}\n\n'
                if kind == 'finished':
                    return
            await asyncio.sleep(0.05)

    return StreamingResponse(events(), media_type='text/event-stream', headers={'Cache-Control': 'no-cache'})
