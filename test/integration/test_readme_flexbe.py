"""README's "Use it from FlexBE" section runs as written, in order, against the pinned FlexBE.

Its commands are taken from the README, in order, and run in one bash shell from the
repository, as a user pastes them, on the section's test case (the pinned FlexBE, ros2cli and
``ros2 launch`` of `make flexbe`, its ``export PATH=...`` line): the behavior package is
exported and installed, the suite (``ros2 launch ... suite.launch.py``) and the WebUI (``make
webui``) start, then the robot, the operator and FlexBE's onboard engine (``ros2 launch ...
atlas_onboard.launch.py``), and ``start-behavior`` starts the behavior and must print
``finished``. What a user runs in a terminal of its own (the launches, the WebUI) runs in the
background here. The lines of a user's own ROS installation (``source``, the workspace's
``colcon build``) are test/integration/test_colcon_route.py's, with the same packages. The test
changes only where things go: ``/tmp/`` becomes its scratch folder and ``ROS_DOMAIN_ID`` a
reserved domain. It checks that the suite and the WebUI come up (the WebUI on port 8000, as the
section says) and that the behavior ends ``finished`` on ``flexbe/status``. The section's WebUI
clicks (synthesize, the manual imports, save) are test/integration/test_flexbe_webui.py's.
"""

import contextlib
import os
import re
import signal
import subprocess
import time
import urllib.request
from pathlib import Path

import pytest

from flexbe_onboard_system import Operator
from flexbe_webui_port import WEBUI_PORT, port_for_this_run
from flexbe_workspace import WORKSPACE_PACKAGES
from readme_sections import flexbe_section, readme_commands

pytestmark = [pytest.mark.ros, pytest.mark.mujoco, pytest.mark.slow]

REPOSITORY = Path(__file__).resolve().parents[2]
README = REPOSITORY / 'README.md'
# Commands a user leaves running (a terminal of their own, or until Ctrl-C): run in the background.
LONG_RUNNING = (re.compile(r'^ros2 launch\b'), re.compile(r'^make webui\b'))
# A user's own ROS installation and workspace (no ROS installation here; test_colcon_route.py
# builds the same packages with colcon).
USERS_OWN_INSTALL = re.compile(r'^(source |mkdir -p ~/flexbe_ws|cp -r .* ~/flexbe_ws/src/$|\(cd ~/flexbe_ws )')


def section_commands() -> list[str]:
    return readme_commands(flexbe_section(README.read_text(encoding='utf-8')))


def as_script(commands: list[str], scratch: Path, domain: int) -> str:
    """The commands as one bash script: stop at the first failing one, long-running ones in the background."""
    lines = ['set -e']
    for command in commands:
        if USERS_OWN_INSTALL.search(command):
            continue
        command = re.sub(r'\bROS_DOMAIN_ID=\d+', f'ROS_DOMAIN_ID={domain}', command.replace('/tmp/', f'{scratch}/'))
        if any(pattern.search(command) for pattern in LONG_RUNNING) and not command.endswith('&'):
            command = f'{command} &'
        lines.append(command)
    lines.append('wait')
    return '\n'.join(lines) + '\n'


def test_the_section_names_every_step_in_order():
    """The steps the section promises are there, in the order that works."""
    commands = section_commands()
    order = ['source /opt/ros/jazzy', 'colcon build', 'source ~/flexbe_ws/install', 'ROS_DOMAIN_ID=',
             '.venv/ros2cli', 'export-behavior', 'pip install', 'PYTHONPATH=', 'suite.launch.py', 'make webui',
             'atlas_onboard.launch.py', 'start-behavior']
    positions = [next((i for i, c in enumerate(commands) if step in c), None) for step in order]
    assert None not in positions, dict(zip(order, positions))
    assert positions == sorted(positions), dict(zip(order, positions))
    assert not any('python3.' in command or 'third_party' in command for command in commands), commands
    # the workspace holds what the colcon route builds
    (copy,) = [command for command in commands if command.startswith('cp -r ')]
    assert copy.split()[2:-1] == list(WORKSPACE_PACKAGES), copy


def webui_answers() -> bool:
    with contextlib.suppress(OSError):
        with urllib.request.urlopen(f'http://127.0.0.1:{WEBUI_PORT}/', timeout=2) as response:
            return response.status == 200
    return False


# Not 2x faster (issue 50): every step of the section runs once, as written: export, pip install, the suite's, the
# WebUI's and FlexBE's launches, a behavior run (30.6 s).
@pytest.mark.flexbe
def test_the_section_runs_in_order_to_a_finished_behavior(ros, flexbe, flexbe_sources, tmp_path):
    from flexbe_msgs.msg import BEStatus

    script = tmp_path / 'use_it_from_flexbe.sh'
    script.write_text(as_script(section_commands(), tmp_path, ros.domain_id), encoding='utf-8')
    log_path = tmp_path / 'shell.log'
    environment = dict(os.environ, ROS_DOMAIN_ID=str(ros.domain_id), FLEXBE_SOURCES=str(flexbe_sources))
    operator = Operator(ros)
    ended = (BEStatus.FINISHED, BEStatus.FAILED, BEStatus.ERROR)
    with port_for_this_run(WEBUI_PORT), open(log_path, 'w', encoding='utf-8') as log:
        shell = subprocess.Popen(['bash', str(script)], cwd=REPOSITORY, env=environment, stdout=log,
                                 stderr=subprocess.STDOUT, start_new_session=True)

        def output() -> str:
            return log_path.read_text(encoding='utf-8', errors='replace')

        try:
            deadline = time.monotonic() + 600
            up = {'suite': False, 'webui': False}
            status = None
            while status is None:
                assert time.monotonic() < deadline, f'no end of the behavior within 600 s\n{output()[-4000:]}'
                assert shell.poll() is None, f'the shell ended ({shell.returncode})\n{output()[-4000:]}'
                up['suite'] = up['suite'] or 'suite up' in output()
                up['webui'] = up['webui'] or webui_answers()
                with operator.lock:
                    status = next((s for s in operator.statuses if s.code in ended), None)
                time.sleep(0.5)
            assert status.code == BEStatus.FINISHED and list(status.args) == ['finished'], output()[-4000:]
            # What the section tells the user to look for in the onboard log.
            deadline_for_log = time.monotonic() + 10
            finished_line = re.compile(r'Behavior execution finished for Look Down Pickup: \d+ with result finished')
            while not finished_line.search(output()) and time.monotonic() < deadline_for_log:
                time.sleep(0.2)
            assert finished_line.search(output()), output()[-4000:]
            assert 'suite up' in output(), output()[-4000:]
            # start-behavior's own word: the outcome on its stdout
            while not re.search(r'^finished$', output(), flags=re.M) and time.monotonic() < deadline_for_log:
                time.sleep(0.2)
            assert re.search(r'^finished$', output(), flags=re.M), output()[-4000:]
            while not up['webui'] and time.monotonic() < deadline:
                up['webui'] = webui_answers()
                time.sleep(0.5)
            assert up['webui'], f'the WebUI never answered on port {WEBUI_PORT}\n{output()[-4000:]}'
            assert 'FlexBE WebUI Server started!' in output()
        finally:
            stop_group(shell)


def stop_group(shell: subprocess.Popen) -> None:
    """Stop the shell and everything it started (its own session): SIGINT, then SIGTERM (a
    non-interactive shell's background jobs ignore SIGINT), then SIGKILL."""
    for signal_number, grace in ((signal.SIGINT, 5), (signal.SIGTERM, 15), (signal.SIGKILL, 5)):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(shell.pid, signal_number)
        deadline = time.monotonic() + grace
        while time.monotonic() < deadline:
            try:
                os.killpg(shell.pid, 0)
            except ProcessLookupError:
                shell.wait()
                return
            time.sleep(0.2)
    shell.wait()
