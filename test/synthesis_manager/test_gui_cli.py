"""``behavior-synthesis gui`` as a process: loopback by default, Ctrl-C stops it, --connect."""

import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import httpx
import pytest

from synthesis_manager.ros.env import prepare_ros_environment

pytestmark = pytest.mark.ros

REPOSITORY = Path(__file__).resolve().parents[2]
URL_LINE = re.compile(r'behavior synthesis GUI: (http://\S+/)')


def start(*arguments, env=None):
    return subprocess.Popen([sys.executable, '-m', 'synthesis_manager', *arguments], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def wait_for_line(process, pattern, timeout=60.0):
    """The first stdout line matching ``pattern`` (the process prints it once it serves)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        line = process.stdout.readline()
        if not line and process.poll() is not None:
            raise AssertionError(f'exited with {process.returncode}: {process.stderr.read()}')
        match = re.search(pattern, line)
        if match:
            return match
    raise AssertionError(f'no line matching {pattern!r} within {timeout} s')


def stop(process):
    """Ctrl-C, as a user would; returns the exit code."""
    process.send_signal(signal.SIGINT)
    try:
        return process.wait(timeout=20)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()


def wait_for_job(url, job_id, timeout=60.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        job = httpx.get(f'{url}api/jobs/{job_id}').json()
        if job['state'] == 'finished':
            return job
        time.sleep(0.1)
    raise AssertionError(f'job {job_id} did not finish within {timeout} s')


def test_gui_serves_on_loopback_by_default_and_stops_on_ctrl_c():
    gui = start('gui', '--port', '0')
    try:
        url = wait_for_line(gui, URL_LINE).group(1)
        assert url.startswith('http://127.0.0.1:')
        page = httpx.get(url)
        assert page.status_code == 200 and '<title>Behavior synthesis</title>' in page.text
        assert httpx.get(f'{url}static/app.js').status_code == 200
        assert 'atlas' in httpx.get(f'{url}api/systems').json()['systems']
        assert 'in-process suite' in httpx.get(f'{url}api/info').json()['description']
        # A body nested 100,000 deep once ended this process with SIGSEGV (JSON decoded on the
        # main thread's 8 MB stack under the formulas' recursion limit): refused, still serving.
        deep = httpx.post(f'{url}api/jobs', content=b'[' * 100_000 + b']' * 100_000,
                          headers={'Content-Type': 'application/json'})
        assert (deep.status_code, deep.json()['error']) == (400, 'TOO_DEEP')
        assert gui.poll() is None and httpx.get(f'{url}api/systems').status_code == 200
    finally:
        assert stop(gui) == 130  # README: stopped by SIGINT


def test_gui_reports_a_port_in_use():
    first = start('gui', '--port', '0')
    try:
        port = wait_for_line(first, URL_LINE).group(1).rsplit(':', 1)[1].strip('/')
        second = subprocess.run([sys.executable, '-m', 'synthesis_manager', 'gui', '--port', port],
                                capture_output=True, text=True, timeout=60)
        assert second.returncode == 5  # ExitStatus.UNAVAILABLE
        assert f'cannot listen on 127.0.0.1:{port}' in second.stderr
    finally:
        assert stop(first) == 130


@pytest.fixture
def reserved_domain():
    from synthesis_manager.ros.harness import reserve_domain_id

    with reserve_domain_id() as domain:
        yield domain


def test_connect_joins_a_running_suite(reserved_domain, tmp_path):
    # The suite's systems, not this machine's: the GUI reads none of config/ itself.
    shutil.copy(REPOSITORY / 'config' / 'atlas.yaml', tmp_path / 'atlas.yaml')
    (tmp_path / 'arm_only.yaml').write_text(
        'abstraction:\n  control_modes: {rest: [reach], reach: [rest]}\n  actions: {wave: [reach]}\n'
        'flexbe:\n  states: {}\n')
    env = prepare_ros_environment(reserved_domain, dict(os.environ))
    suite = start('serve', '--config-dir', str(tmp_path), env=env)
    gui = None
    try:
        wait_for_line(suite, r'suite up')
        gui = start('gui', '--connect', '--port', '0', env=env)
        url = wait_for_line(gui, URL_LINE).group(1)
        assert f'ROS_DOMAIN_ID {reserved_domain}' in httpx.get(f'{url}api/info').json()['description']
        assert httpx.get(f'{url}api/systems').json()['systems'] == ['arm_only', 'atlas', 'delivery_rover',
                                                                    'mobile_manipulator', 'shelf_picker']
        arm = httpx.get(f'{url}api/systems/arm_only').json()
        assert [mode['name'] for mode in arm['control_modes']] == ['rest', 'reach']
        check = httpx.post(f'{url}api/goal-check', json={'system': 'arm_only', 'initial_conditions': ['rest'],
                                                          'goals': ['wave']}).json()
        assert check['findings'] == []
        job = httpx.post(f'{url}api/jobs', json={
            'system': 'atlas', 'initial_conditions': 'stand_prep', 'goals': 'look_down',
            'option': 'ltl_compilation_only'}).json()
        finished = wait_for_job(url, job['id'])
        assert finished['outcome']['error_name'] == 'SUCCESS', finished['outcome']['message']
        assert 'look_down_a' in finished['outcome']['ltl_specification']['sys_props']
    finally:
        if gui is not None:
            assert stop(gui) == 130
        stop(suite)
