"""The web GUI under load and against hostile requests (real uvicorn, in-process suite)."""

import http.client
import json
import os
import signal
import sys
import threading
import time
import urllib.parse
from concurrent.futures import ThreadPoolExecutor

import pytest

from waiting import wait_until

from synthesis_manager.programs.cli import build_parser
from synthesis_manager.programs.gui import background_server, ros_backend
from synthesis_manager.limits import MAX_BODY_BYTES
from synthesis_manager.web import request_form as request_form_module
from synthesis_manager.web.guards import json_nesting_exceeds
from synthesis_manager.web.routes import create_app
from synthesis_manager.web.simulation_process import CHILD_ENVIRONMENT, SimulationProcess

pytestmark = pytest.mark.ros

PAPER_TASK = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'pickup_object']}


@pytest.fixture(scope='module')
def gui(tmp_path_factory):
    """(backend, base URL) of a GUI whose suite runs in this process."""
    args = build_parser(only='gui').parse_args(
        ['gui', '--byproducts-dir', str(tmp_path_factory.mktemp('gui-reliability')),
         '--synthesis-timeout', '60', '--goal-timeout', '120'])
    with ros_backend(args) as backend:
        with background_server(create_app(backend)) as url:
            yield backend, url


def request(url, method, path, body=None, headers=None, chunks=None, announced=None):
    """One HTTP request; returns (status, decoded JSON or None).

    ``chunks``: send the body chunked; ``announced``: only announce a body of that many bytes
    (the server must answer without reading it).
    """
    parts = urllib.parse.urlsplit(url)
    connection = http.client.HTTPConnection(parts.hostname, parts.port, timeout=60)
    try:
        if announced is not None:
            connection.putrequest(method, path)
            connection.putheader('Content-Type', 'application/json')
            connection.putheader('Content-Length', str(announced))
            connection.endheaders()
        elif chunks is not None:
            connection.putrequest(method, path)
            for name, value in (headers or {}).items():
                connection.putheader(name, value)
            connection.putheader('Transfer-Encoding', 'chunked')
            connection.putheader('Content-Type', 'application/json')
            connection.endheaders()
            try:
                for chunk in chunks:
                    connection.send(b'%x\r\n%s\r\n' % (len(chunk), chunk))
                connection.send(b'0\r\n\r\n')
            except (BrokenPipeError, ConnectionResetError):
                pass  # the server answered and closed before reading it all
        else:
            data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
            connection.request(method, path, body=data,
                               headers={'Content-Type': 'application/json', **(headers or {})})
        response = connection.getresponse()
        payload = response.read()
        return response.status, json.loads(payload) if payload.startswith(b'{') else None
    finally:
        connection.close()


def wait_until_finished(url, job_id, timeout=180.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        status, job = request(url, 'GET', f'/api/jobs/{job_id}')
        assert status == 200
        if job['state'] == 'finished':
            return job
        time.sleep(0.2)
    raise AssertionError(f'job {job_id} unfinished after {timeout} s')


def test_twenty_jobs_at_once_all_finish(gui):
    _, url = gui
    with ThreadPoolExecutor(20) as pool:
        started = list(pool.map(lambda i: request(url, 'POST', '/api/jobs', {**PAPER_TASK, 'name': f'job{i}'}),
                                range(20)))
        assert [status for status, _ in started] == [202] * 20
        finished = list(pool.map(lambda answer: wait_until_finished(url, answer[1]['id']), started))
    assert [job['outcome']['error_name'] for job in finished] == ['SUCCESS'] * 20
    assert all(job['summary']['state_machine_states'] > 0 for job in finished)


def test_jobs_beyond_the_limit_are_busy(gui):
    backend, url = gui
    backend.jobs.gate.clear()  # new jobs wait unsent, so they stay unfinished
    limit = backend.jobs.max_unfinished
    try:
        backend.jobs.max_unfinished = 3
        ids = [request(url, 'POST', '/api/jobs', PAPER_TASK)[1]['id'] for _ in range(3)]
        status, error = request(url, 'POST', '/api/jobs', PAPER_TASK)
        assert status == 503
        assert error['error'] == 'BUSY'
    finally:
        backend.jobs.max_unfinished = limit
        for job_id in ids:
            request(url, 'POST', f'/api/jobs/{job_id}/cancel')
        backend.jobs.gate.set()
    assert all(wait_until_finished(url, job_id)['outcome']['error_name'] == 'PREEMPTED' for job_id in ids)


def test_bodies_over_a_megabyte_are_refused(gui):
    _, url = gui
    status, error = request(url, 'POST', '/api/jobs', announced=50 * MAX_BODY_BYTES)
    assert status == 413
    assert error['error'] == 'TOO_LARGE'
    status, error = request(url, 'POST', '/api/jobs', chunks=[b'{"name": "' + b'x' * 65536] * 20)
    assert status == 413
    assert error['error'] == 'TOO_LARGE'
    body = json.dumps({**PAPER_TASK, 'name': 'x' * (MAX_BODY_BYTES - 200)}).encode()  # just fits
    status, error = request(url, 'POST', '/api/jobs', body)
    assert (status, error['error'], error['item']) == (422, 'INVALID_REQUEST', 'body.name')
    assert len(error['message']) < 300  # the name is not echoed
    assert request(url, 'GET', '/api/systems')[0] == 200  # and it keeps serving


def test_a_foreign_host_header_is_refused(gui):
    _, url = gui
    port = urllib.parse.urlsplit(url).port
    for host in (f'evil.example:{port}', 'evil.example', f'127.0.0.1:{port + 1}'):
        status, error = request(url, 'GET', '/api/systems', headers={'Host': host})
        assert status == 421, host
        assert error['error'] == 'BAD_HOST'
    for host in (f'127.0.0.1:{port}', f'localhost:{port}'):
        assert request(url, 'GET', '/api/systems', headers={'Host': host})[0] == 200


def post_raw(url, path, body: bytes, content_type):
    """A POST with exactly this body and Content-Type (None: no header); (status, headers, JSON)."""
    parts = urllib.parse.urlsplit(url)
    connection = http.client.HTTPConnection(parts.hostname, parts.port, timeout=60)
    try:
        connection.request('POST', path, body=body, headers={'Content-Type': content_type} if content_type else {})
        response = connection.getresponse()
        payload = response.read()
        return response.status, dict(response.getheaders()), json.loads(payload) if payload.startswith(b'{') else None
    finally:
        connection.close()


def test_posts_a_cross_site_form_could_send_are_refused(gui):
    """Forms (urlencoded, multipart, text/plain) need no CORS preflight: no POST may act on them."""
    backend, url = gui
    jobs_before = len(backend.jobs._jobs)
    for content_type, body in [(None, b''), ('text/plain', b'{}'), ('application/x-www-form-urlencoded', b'a=1'),
                               ('multipart/form-data; boundary=x', b'--x--')]:
        for path in ('/api/jobs', '/api/jobs/any/simulations', '/api/jobs/any/cancel'):
            status, _, error = post_raw(url, path, body, content_type)
            assert (status, error['error'], error['item']) == (415, 'UNSUPPORTED_MEDIA_TYPE', 'content-type'), path
    assert len(backend.jobs._jobs) == jobs_before
    assert post_raw(url, '/api/goal-check', json.dumps({'system': 'atlas', 'goals': ['look_down']}).encode(),
                    'application/json; charset=utf-8')[0] == 200


# Not 2x faster (issue 50): a synthesized job and the two simulations the bound lets run, really started (5.3 s).
def test_simulations_are_bounded_at_once_and_per_job(gui):
    from synthesis_manager.web.simulations import Simulation

    backend, url = gui
    status, job = request(url, 'POST', '/api/jobs', PAPER_TASK)
    job = wait_until_finished(url, job['id'])
    assert job['outcome']['error_name'] == 'SUCCESS'
    # The job already ran as many simulations as it keeps: the oldest ones make room.
    old = [Simulation(id=f"{job['id']}-old{i}", job_id=job['id'], state='finished')
           for i in range(backend.simulations.max_per_job)]
    backend.simulations._runs.update({run.id: run for run in old})

    with ThreadPoolExecutor(6) as pool:
        answers = list(pool.map(lambda _: post_raw(url, f"/api/jobs/{job['id']}/simulations", b'{}',
                                                   'application/json'), range(6)))
    started = [body for status, _, body in answers if status == 202]
    refused = [(headers, body) for status, headers, body in answers if status == 429]
    assert len(started) == backend.simulations.max_running == 2
    assert len(refused) == 4
    assert all(int(headers['retry-after']) > 0 and body['error'] == 'BUSY' and body['item'] == 'simulations'
               for headers, body in refused)
    runs_of_job = [run.id for run in list(backend.simulations._runs.values()) if run.job_id == job['id']]
    assert len(runs_of_job) == backend.simulations.max_per_job
    assert request(url, 'GET', f"/api/simulations/{old[0].id}")[0] == 404  # the oldest were forgotten

    deadline = time.monotonic() + 300
    while any(request(url, 'GET', f"/api/simulations/{run['id']}")[1]['state'] != 'finished' for run in started):
        assert time.monotonic() < deadline
        time.sleep(0.5)
    status, _, run = post_raw(url, f"/api/jobs/{job['id']}/simulations", b'{}', 'application/json')
    assert status == 202  # room again once they have finished
    while request(url, 'GET', f"/api/simulations/{run['id']}")[1]['state'] != 'finished':
        assert time.monotonic() < deadline
        time.sleep(0.5)



def simulation_processes() -> set[int]:
    """This process's simulation children (web/simulation_process.py)."""
    found = set()
    for entry in filter(str.isdigit, os.listdir('/proc')):
        try:
            with open(f'/proc/{entry}/stat') as stat:
                parent = int(stat.read().rsplit(')', 1)[1].split()[1])
            with open(f'/proc/{entry}/cmdline', 'rb') as cmdline:
                if parent == os.getpid() and b'synthesis_manager.web.simulation_process' in cmdline.read():
                    found.add(int(entry))
        except (OSError, IndexError):  # ended meanwhile
            pass
    return found


def test_a_crashed_simulation_is_reported_and_the_gui_keeps_serving(gui):
    """Each simulation runs in a child process: killing it (as a crash in MuJoCo would) ends
    that run with an error naming the process; the GUI and the next run are unharmed."""
    _, url = gui
    job = wait_until_finished(url, request(url, 'POST', '/api/jobs', PAPER_TASK)[1]['id'])

    def finished(simulation_id):
        deadline = time.monotonic() + 300
        while (run := request(url, 'GET', f'/api/simulations/{simulation_id}')[1])['state'] != 'finished':
            assert time.monotonic() < deadline
            time.sleep(0.2)
        return run

    others = simulation_processes()  # earlier tests' runs on the module's GUI, still ending
    status, _, run = post_raw(url, f"/api/jobs/{job['id']}/simulations", b'{}', 'application/json')
    assert status == 202
    children = wait_until(lambda: simulation_processes() - others, 60, 'a simulation process')
    os.kill(children.pop(), signal.SIGKILL)
    crashed = finished(run['id'])
    assert crashed['error']['code'] == 'FAILURE' and crashed['error']['item'] == 'simulation process'
    assert 'ended (exit code -9) without a result' in crashed['error']['message']
    assert request(url, 'GET', '/api/info')[0] == 200
    status, _, run = post_raw(url, f"/api/jobs/{job['id']}/simulations", b'{}', 'application/json')
    assert finished(run['id'])['outcome'] == 'finished'
    assert not simulation_processes() - others  # none of this test's left behind


@pytest.mark.parametrize('path, body', [
    ('/api/jobs', {**PAPER_TASK, 'system': ['x' * 1000] * 800}),
    ('/api/jobs', {**PAPER_TASK, 'k' * 60_000: 1}),
    ('/api/jobs', {**PAPER_TASK, 'option': {'a': 'x' * 60_000}}),
    ('/api/jobs', {**PAPER_TASK, 'name': ['n' * 60_000]}),
    ('/api/goal-check', {'system': ['x' * 60_000] * 14}),
    ('/api/jobs/' + 'j' * 8000 + '/simulations', {}),
    ('/api/jobs/' + 'j' * 8000 + '/cancel', {}),
])
def test_refusals_never_echo_more_than_the_start_of_the_input(gui, path, body):
    _, url = gui
    status, error = request(url, 'POST', path, body)
    assert 400 <= status < 500 and error is not None
    assert len(json.dumps(error)) < 600, error


def test_an_unknown_job_id_in_a_get_is_not_echoed(gui):
    _, url = gui
    status, error = request(url, 'GET', '/api/jobs/' + 'j' * 8000)
    assert status == 404 and len(json.dumps(error)) < 600


def test_a_job_naming_a_huge_unknown_goal_is_answered_briefly(gui):
    _, url = gui
    status, job = request(url, 'POST', '/api/jobs', {**PAPER_TASK, 'goals': ['x' * 60_000]})
    assert status == 202
    outcome = wait_until_finished(url, job['id'])['outcome']
    assert outcome['error_name'] == 'UNKNOWN_PROPOSITION' and len(outcome['message']) < 600


def test_a_simulation_process_gets_the_lean_rendering_environment(monkeypatch):
    """The child renders with llvmpipe in its own thread and returns freed buffers at once
    (its peak RSS); what the GUI's own environment sets wins."""
    for name in CHILD_ENVIRONMENT:
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv('LP_NUM_THREADS', '2')
    run = SimulationProcess({'max_wall_time': 1.0})
    try:  # empty while the child is between exec's (the ROS wheels' .pth may re-exec it); it waits on stdin
        deadline, variables = time.monotonic() + 30, {}
        while not variables:
            assert time.monotonic() < deadline and run.process.poll() is None
            with open(f'/proc/{run.process.pid}/environ', 'rb') as environ:
                variables = dict(entry.split(b'=', 1) for entry in environ.read().split(b'\0') if b'=' in entry)
    finally:
        run.stop()
        run.process.wait()
        run.process.stdin.close()
        run.process.stdout.close()
    assert variables[b'LP_NUM_THREADS'] == b'2'
    assert variables[b'MALLOC_TRIM_THRESHOLD_'] == b'131072'
    assert variables[b'MUJOCO_GL'] == b'egl'


def test_a_body_nested_100000_deep_is_refused_before_it_is_parsed(gui):
    """The attack that once ended the GUI with SIGSEGV (issue 34, item 1), at the same depth."""
    _, url = gui
    started = time.monotonic()
    status, error = request(url, 'POST', '/api/jobs', b'[' * 100_000 + b']' * 100_000)
    assert (status, error['error'], error['code'], error['item']) == (400, 'TOO_DEEP', 'INVALID_REQUEST', 'body')
    assert time.monotonic() - started < 1.0
    status, error = request(url, 'POST', '/api/goal-check', b'{"goals": ' + b'{"a": ' * 1000)
    assert (status, error['error']) == (400, 'TOO_DEEP')
    assert request(url, 'GET', '/api/systems')[0] == 200  # and it keeps serving


def test_the_gui_process_never_raises_its_recursion_limit(gui):
    """Deep recursion only on the threads that read formulas (issue 34, item 1): after a job
    (compiled, synthesized, generated in this process) the limit is what it was, so a deep JSON
    document that got past the guard would be a RecursionError here, not a SIGSEGV."""
    _, url = gui
    limit = sys.getrecursionlimit()
    status, job = request(url, 'POST', '/api/jobs', PAPER_TASK)
    assert status == 202
    assert wait_until_finished(url, job['id'])['outcome']['error_name'] == 'SUCCESS'
    assert request(url, 'POST', '/api/jobs', b'[' * 100_000 + b']' * 100_000)[0] == 400
    assert sys.getrecursionlimit() == limit
    with pytest.raises(RecursionError):
        json.loads('[' * 100_000 + ']' * 100_000)
    assert request(url, 'GET', '/api/systems')[0] == 200


@pytest.mark.parametrize('body, deeper', [
    (b'[]', False), (b'[' * 32 + b']' * 32, False), (b'[' * 33, True),
    (b'{"a": "[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[[", "b": [[]]}', False),  # brackets in strings
    (b'["\\"' + b'[' * 40 + b'"]', False),  # an escaped quote does not end the string
    (b'["\\\\", ' + b'[' * 40 + b']', True),  # an escaped backslash does
])
def test_the_nesting_scan_counts_brackets_outside_strings(body, deeper):
    assert json_nesting_exceeds(body) is deeper


def test_goal_checks_beyond_the_limit_are_busy_with_retry_after(gui, monkeypatch):
    backend, url = gui
    running, release = threading.Semaphore(0), threading.Event()
    real_findings = request_form_module.goal_findings

    def slow_findings(*args):
        running.release()
        release.wait(30)
        return real_findings(*args)

    monkeypatch.setattr(request_form_module, 'goal_findings', slow_findings)
    check = {'system': 'atlas', 'initial_conditions': [], 'goals': ['look_down']}
    with ThreadPoolExecutor(backend.form.max_goal_checks) as pool:
        held = [pool.submit(request, url, 'POST', '/api/goal-check', check) for _ in range(backend.form.max_goal_checks)]
        try:
            for _ in held:
                assert running.acquire(timeout=30)
            status, headers, error = post_raw(url, '/api/goal-check', json.dumps(check).encode(), 'application/json')
        finally:
            release.set()
        assert [future.result()[0] for future in held] == [200] * backend.form.max_goal_checks
    assert (status, error['error'], error['code'], error['item']) == (429, 'BUSY', 'BUSY', 'goal-check')
    assert {name.lower(): value for name, value in headers.items()}['retry-after'] == '1'
    assert request(url, 'POST', '/api/goal-check', check)[0] == 200  # a slot is free again


@pytest.mark.parametrize('path, body, item', [
    ('/api/jobs', b'{"system": "atlas", "goals": ["look_down\\ud800"]}', 'goals'),
    ('/api/goal-check', b'{"system": "atlas", "goals": ["\\udc00"]}', 'goals'),
    ('/api/goal-check', b'{"system": "atlas\\ud800", "goals": []}', 'system'),
    ('/api/jobs', b'{"system": "atlas", "goals": ["look\\u0000down"]}', 'goals'),
    ('/api/jobs', b'{"system": "atlas", "goals": "look_down", "initial_conditions": "stand\\u0007"}',
     'initial_conditions'),
    ('/api/jobs', b'{"system": "atlas\\u0000", "goals": ["look_down"]}', 'system'),
    ('/api/jobs', b'{"system": "atlas", "goals": ["look_down"], "name": "pick\\u0000up"}', 'name'),
    ('/api/jobs', b'{"system": "atlas", "goals": ["look_down"], "name": "pickup\\n"}', 'name'),
    ('/api/jobs', b'{"system": "atlas", "goals": ["look_down"], "name\\ud800": 1}', 'body'),
])
def test_control_characters_and_lone_surrogates_are_refused_naming_the_field(gui, path, body, item):
    _, url = gui
    status, error = request(url, 'POST', path, body)
    assert (status, error['error'], error['code'], error['item']) == (422, 'INVALID_CHARACTER', 'INVALID_REQUEST', item)
    assert len(error['message']) < 200


def test_names_in_a_text_may_still_be_separated_by_newlines(gui):
    _, url = gui
    status, check = request(url, 'POST', '/api/goal-check',
                            {'system': 'atlas', 'initial_conditions': [], 'goals': 'look_down\nstand_prep'})
    assert status == 200 and [f['item'] for f in check['findings']] == ['stand_prep']
