"""The synthesis web GUI's routes as a FastAPI app (ROS-free): page, JSON API, progress streams, downloads.

``create_app(backend)`` serves ``static/`` and these routes::

    GET  /                                   the page (static/index.html; its ES modules, style.css under /static)
    GET  /api/vocabulary                     the Python names the page needs (web.vocabulary)
    GET  /api/systems                        {"systems": [...]}
    GET  /api/systems/{system}               what a request may name: control modes, actions
    POST /api/jobs                           start a synthesis job -> 202 {"id": ..., ...}
    GET  /api/jobs/{id}                      its status, progress timeline, result and summary
    GET  /api/jobs/{id}/events               the same as server-sent events until the job ends
    GET  /api/jobs/{id}/state-machine        its state machine as a tree (sm_generation.StateMachine.to_dict)
    POST /api/jobs/{id}/cancel               cancel it (the result becomes PREEMPTED)
    GET  /api/jobs/{id}/artifacts/{name}     a download (see ARTIFACTS); ?inline=1 to display it
                                             (a browser asking for a forgotten one gets a page saying so)
    POST /api/goal-check                     goals that cannot be achieved / cannot come next, and why
    POST /api/repair                         verified changes that make a refused request possible
                                             (Accept: application/x-ndjson: each proposal as it is found)
    POST /api/jobs/{id}/play                 a play of a finished job: {"moves": [...]} -> the turn
    POST /api/jobs/{id}/simulations          run the job's state machine on the simulated robot
    GET  /api/simulations/{id}               its trace so far, frames, outcome and trace check
    GET  /api/simulations/{id}/events        the same as server-sent events until the run ends
    POST /api/simulations/{id}/control       an operator command to the running run (Runtime Control)
    GET  /api/simulations/{id}/frames/{n}    key frame n (PNG); .../timeline.png the timeline plot

Bad input is answered with a 4xx JSON body ``{"error", "item", "message"}`` whose ``item``
names the offending system, field, job or artifact; the server keeps serving. Requests with
a foreign Host header (421), a body over 1 MB (413), a POST whose body is not declared JSON
(415: what a cross-site form can send) or one nested too deeply (400 TOO_DEEP) are refused first
(web.guards); a control character or lone surrogate in any string is 422 INVALID_CHARACTER
naming the field (web.jobs.checked_body); a new job while too many are unfinished is 503 BUSY,
a simulation, goal check, repair search or play while too many run is 429 BUSY with Retry-After.

The backend does the work: :class:`synthesis_manager.web.backend.SynthesisBackend` holds one
object per concern (``backend.jobs``, ``.downloads``, ``.simulations``, ``.repairs``, ``.plays``,
``.form``; see web/backend.py), and each route calls one of them. They validate requests and
return records (Job with its web.outcome.JobOutcome, Simulation, the job's sm_generation
StateMachine); the routes turn them into JSON with their ``to_dict``. The synthesis itself is a
``run_goal`` callable given to the backend (``gui.RosGoalRunner`` sends the goal to
``/behavior_synthesis``). A new route: its URL and answer here, its work in the concern's
module (a new concern: a module of its own, held by the backend); docs/design.md has an example.
"""

from __future__ import annotations

import asyncio
import html
import json
import mimetypes
import queue
from pathlib import Path
from typing import Callable

from fastapi import Body, FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import FileResponse, HTMLResponse, JSONResponse, Response, StreamingResponse
from fastapi.staticfiles import StaticFiles

from synthesis_manager.web.artifacts import Artifact
from synthesis_manager.limits import BusyError
from synthesis_manager.web.errors import GuiRequestError, InvalidJobRequestError, NotFoundError, http_answer
from synthesis_manager.web.guards import RequestGuard
from synthesis_manager.web.vocabulary import vocabulary

STATIC_DIR = Path(__file__).with_name('static')
NDJSON = 'application/x-ndjson'
# The page is ES modules, which a browser runs only when served with a JavaScript media type;
# the host's mime.types (which StaticFiles reads) might map .js to something else.
mimetypes.add_type('text/javascript', '.js')


def create_app(backend) -> FastAPI:
    """The GUI's FastAPI app around ``backend`` (a SynthesisBackend)."""
    # No Swagger/ReDoc pages: they load third-party code from a CDN. The schema stays available.
    app = FastAPI(title='Behavior synthesis', docs_url=None, redoc_url=None, openapi_url='/api/openapi.json')
    app.mount('/static', StaticFiles(directory=STATIC_DIR), name='static')
    app.add_middleware(RequestGuard)  # Host check and the body size limit, before any route

    @app.exception_handler(GuiRequestError)
    @app.exception_handler(BusyError)
    async def gui_error(_request, error):
        status, body, headers = http_answer(error)
        return JSONResponse(body, status_code=status, headers=headers)

    @app.exception_handler(RequestValidationError)
    async def malformed(_request, error: RequestValidationError):
        problem = error.errors()[0] if error.errors() else {'loc': ['body'], 'msg': 'malformed request'}
        item = '.'.join(str(part) for part in problem.get('loc', ['body']))
        return JSONResponse(InvalidJobRequestError(f'{item}: {problem.get("msg")}', item).to_dict(),
                            status_code=422)

    @app.get('/', include_in_schema=False)
    def index():
        return FileResponse(STATIC_DIR / 'index.html', media_type='text/html')

    @app.get('/api/info')
    def info():
        return {'description': backend.description, 'simulation': bool(backend.simulations.available),
                'repair_time_budget': backend.repairs.time_budget}

    @app.get('/api/vocabulary')
    def names():
        return vocabulary()

    @app.get('/api/systems')
    def systems():
        return {'systems': backend.systems()}

    @app.get('/api/systems/{system}')
    def choices(system: str):
        return backend.form.choices(system)

    @app.post('/api/jobs', status_code=202)
    def start_job(body=Body(None)):
        return backend.jobs.start(body).to_dict()

    @app.get('/api/jobs/{job_id}')
    def job_status(job_id: str):
        return backend.jobs.job(job_id).to_dict()

    @app.post('/api/jobs/{job_id}/cancel', status_code=202)
    def cancel_job(job_id: str):
        return backend.jobs.cancel(job_id).to_dict()

    @app.get('/api/jobs/{job_id}/events')
    async def job_events(job_id: str, request: Request):
        backend.jobs.job(job_id)  # unknown job: 404 now rather than an empty stream
        return _event_stream(request, lambda: backend.jobs.revision(job_id),
                             lambda: backend.jobs.job(job_id).to_dict(), _stopping(backend))

    @app.get('/api/jobs/{job_id}/state-machine')
    def state_machine(job_id: str):
        return backend.jobs.state_machine(job_id).to_dict()

    @app.get('/api/jobs/{job_id}/artifacts/{name}')
    def artifact(job_id: str, name: str, request: Request, inline: bool = False):
        try:
            return _file_response(backend.downloads.artifact(job_id, name), inline)
        except NotFoundError as error:
            if 'text/html' not in request.headers.get('accept', ''):
                raise
            return HTMLResponse(_download_gone_page(name, error), status_code=404)

    @app.post('/api/goal-check')
    def goal_check(body=Body(None)):
        return backend.form.goal_check(body)

    @app.post('/api/repair')
    def repair(request: Request, body=Body(None)):
        if NDJSON not in request.headers.get('accept', ''):
            return backend.repairs.repair(body)
        return _repair_stream(request, backend.repairs.start(body), _stopping(backend))

    @app.post('/api/jobs/{job_id}/play')
    def play(job_id: str, body=Body(None)):
        return backend.plays.play(job_id, body)

    @app.post('/api/jobs/{job_id}/simulations', status_code=202)
    def start_simulation(job_id: str, body=Body(None)):
        return backend.simulations.start(job_id, body).to_dict()

    @app.get('/api/simulations/{simulation_id}')
    def simulation_status(simulation_id: str):
        return backend.simulations.status(simulation_id).to_dict()

    @app.get('/api/simulations/{simulation_id}/events')
    async def simulation_events(simulation_id: str, request: Request):
        backend.simulations.status(simulation_id)
        return _event_stream(request, lambda: backend.simulations.revision(simulation_id),
                             lambda: backend.simulations.status(simulation_id).to_dict(), _stopping(backend))

    @app.post('/api/simulations/{simulation_id}/control', status_code=202)
    def simulation_command(simulation_id: str, body=Body(None)):
        return backend.simulations.command(simulation_id, body).to_dict()

    @app.get('/api/simulations/{simulation_id}/frames/{index}')
    def simulation_frame(simulation_id: str, index: int):
        return _file_response(backend.simulations.frame(simulation_id, index), inline=True)

    @app.get('/api/simulations/{simulation_id}/timeline.png')
    def simulation_timeline(simulation_id: str):
        return _file_response(backend.simulations.timeline(simulation_id), inline=True)

    return app


def _download_gone_page(name: str, error: NotFoundError) -> str:
    """What a browser shows for a download the server no longer has (old link, restarted server)."""
    return f'''<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Download no longer available</title>
<link rel="stylesheet" href="/static/style.css"></head>
<body><main class="gone"><h1>This download is no longer available</h1>
<p>The server keeps results only while it runs, and only the most recent ones: {html.escape(name)}
belonged to a job it no longer has ({html.escape(str(error))}). The server was probably restarted.</p>
<p><a href="/">Open the synthesis page</a> and run the synthesis again to get a fresh download.</p>
</main></body></html>
'''


def _file_response(found: Artifact, inline: bool) -> Response:
    disposition = 'inline' if inline else 'attachment'
    return Response(found.content, media_type=found.media_type,
                    headers={'Content-Disposition': f'{disposition}; filename="{found.filename}"'})


def _stopping(backend) -> Callable[[], bool]:
    """Whether ``backend`` is stopping."""
    return backend.stopping.is_set


def _repair_stream(request: Request, run, stopping: Callable[[], bool]):
    """A repair search's answers as JSON lines: ``{"proposal": ...}`` as each is verified, then
    ``{"result": ...}`` (Repairs.to_dict()) or ``{"error": {...}}`` (a 4xx/5xx answer's body).
    A client that goes away stops the search (``run``: web.repairs.RepairRun)."""
    async def lines():
        try:
            while not stopping() and not await request.is_disconnected():
                try:
                    kind, value = run.answers.get_nowait()
                except queue.Empty:
                    await asyncio.sleep(0.05)
                    continue
                yield json.dumps({kind: value.to_dict() if kind == 'error' else value}) + '\n'
                if kind != 'proposal':
                    return
        finally:
            run.stop()  # after its answer this does nothing; before it, nobody is left to hear it

    return StreamingResponse(lines(), media_type=NDJSON, headers={'Cache-Control': 'no-cache'})


def _event_stream(request: Request, revision: Callable[[], int], snapshot: Callable[[], dict],
                  stopping: Callable[[], bool]):
    """Server-sent events: ``progress`` with each new snapshot, then one ``finished``.

    A stream also ends when the server stops: an open stream would otherwise hold the
    server's shutdown until its grace period runs out.
    """
    async def events():
        sent = -1
        while not stopping() and not await request.is_disconnected():
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
