"""Every command in README.md's ``sh`` blocks pastes and runs as written.

The commands are taken from the README itself, in order, in one scratch directory (so a
later command can use a file an earlier one wrote). Each ``behavior-synthesis`` command line
is first parsed by the real parser (so every option it names exists); then the quick ones
run to exit status 0, the servers (``serve``, ``gui``) start, say they are ready and stop
within 3 s of Ctrl-C with status 130, ``send-goal`` talks to a ``serve`` of its own, and our other programs
answer ``--help``. Commands for other environments (a ROS installation, FlexBE's onboard
processes in several shells, make targets that build the venv) are listed in ``ELSEWHERE``
with the test that covers them; any other command fails this test. The commands of the section
"Use it from FlexBE" run in order in test/integration/test_readme_flexbe.py instead.
"""

import os
import re
import shlex
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from synthesis_manager.programs.cli import SUBCOMMANDS, build_parser
from synthesis_manager.ros.env import prepare_ros_environment

from readme_sections import flexbe_section, readme_commands

pytestmark = [pytest.mark.ros, pytest.mark.slow]

REPOSITORY = Path(__file__).resolve().parents[2]
README = REPOSITORY / 'README.md'
BIN = Path(sys.executable).parent
# Programs the README shows for other settings, and where they are exercised instead.
ELSEWHERE = {
    'make': 'the Makefile targets build the venv (CI runs them)',
    'mkdir': 'colcon workspace setup (needs a ROS installation)',
    'cd': 'colcon workspace setup (needs a ROS installation)',
    'cp': 'colcon workspace setup (needs a ROS installation)',
    'source': 'a ROS installation',
    'colcon': 'a ROS installation',
    'ros2': 'a ROS installation (its `action send_goal` lines run here with the pinned ros2cli)',
    'pip': 'a ROS installation',
}
SERVERS = {'serve': 'suite up', 'gui': 'behavior synthesis GUI: http://'}
QUICK = {'compile', 'repair', 'generate-sm', 'export-behavior', 'execute', 'demo'}


def program(argv: list[str]) -> str:
    first = argv[0].split('=', 1)[0] if '=' in argv[0] and not argv[0].startswith('.') else argv[0]
    return Path(first).name


def test_the_readme_has_commands_and_no_synopsis_brackets():
    commands = readme_commands(README.read_text())
    assert len(commands) >= 10
    for command in commands:
        words = shlex.split(command, comments=True)
        # a synopsis ([--x | --y], ...) belongs in --help: a pasted one fails
        assert not any(w.startswith('[') and w.endswith(']') and w.startswith('[-') for w in words), command
        assert '|' not in words and '...' not in words, command


@pytest.fixture(scope='module')
def scratch(tmp_path_factory):
    return tmp_path_factory.mktemp('readme')


@pytest.fixture(scope='module')
def environment():
    from synthesis_manager.ros.harness import reserve_domain_id

    with reserve_domain_id() as domain:
        env = prepare_ros_environment(domain, environ=dict(os.environ))
        env['MUJOCO_GL'] = 'egl'
        yield env


@pytest.fixture(scope='module')
def suite(environment, scratch):
    """`behavior-synthesis serve` for the README's send-goal examples."""
    server = subprocess.Popen([str(BIN / 'behavior-synthesis'), 'serve', '--byproducts-dir', str(scratch / 'byproducts')],
                              env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    assert 'suite up' in server.stdout.readline()
    yield environment
    server.send_signal(signal.SIGINT)
    server.wait(20)


def check_ros2_send_goal(argv: list[str], environment: dict, flexbe_prefix: Path, scratch: Path) -> None:
    """A ``ros2 action send_goal`` line, run with the ros2cli `make flexbe` installs (a user's own
    ROS 2 ``ros2`` takes the same arguments): the goal succeeds and the result holds a machine."""
    ros2 = Path(sys.prefix) / 'ros2cli' / 'ros2'
    assert ros2.exists(), f'no {ros2}: run `make flexbe` (it installs the pinned ros2cli)'
    result = subprocess.run([str(ros2), *argv[1:]], env=dict(environment, AMENT_PREFIX_PATH=str(flexbe_prefix)),
                            cwd=scratch, capture_output=True, text=True, timeout=120)
    output = result.stdout
    assert result.returncode == 0 and 'Goal finished with status: SUCCEEDED' in output, (argv, output[-1500:],
                                                                                         result.stderr[-1500:])
    if '--feedback' in argv:
        assert 'Feedback:' in output and 'status: Synthesizing an automaton' in output
    result_part = output[output.index('Result:'):]
    assert re.search(r'error_code:\s+value: 1\b', result_part), result_part[:500]   # SUCCESS
    assert result_part.count('state_path:') >= 5


def as_run(argv: list[str]) -> list[str]:
    """The command with .venv/bin/ meaning this interpreter's bin directory."""
    first = argv[0]
    if first.startswith('.venv/bin/'):
        first = str(BIN / first[len('.venv/bin/'):])
    elif '/' not in first and (BIN / first).exists():  # as typed in a shell where the venv is on PATH
        first = str(BIN / first)
    return [first, *argv[1:]]


def start_and_stop(argv, environment, cwd, ready: str):
    process = subprocess.Popen(argv, env=environment, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True)
    try:
        deadline = time.monotonic() + 60
        line = ''
        while ready not in line and time.monotonic() < deadline:
            line = process.stdout.readline()
            assert line or process.poll() is None, f'{argv} ended before it was ready'
        assert ready in line, argv
        stopped = time.monotonic()
        process.send_signal(signal.SIGINT)
        assert process.wait(10) == 130, argv  # README: stopped by SIGINT
        return time.monotonic() - stopped
    finally:
        if process.poll() is None:
            process.kill()


def outside_the_flexbe_section(text: str) -> str:
    """The README without its "Use it from FlexBE" section (test_readme_flexbe.py runs that one in order)."""
    return text.replace(flexbe_section(text), '\n')


# Not 2x faster (issue 50): each README command runs as written; the slowest, `execute --ros-sim`, is a whole
# synthesis and simulated run (3.4 s).
@pytest.mark.parametrize('command', readme_commands(outside_the_flexbe_section(README.read_text())))
def test_a_readme_command_runs_as_written(command, scratch, environment, request):
    argv = shlex.split(command, comments=True)
    background = argv[-1] == '&'
    argv = [word for word in argv if word != '&']
    if argv[0] == 'AMENT_PREFIX_PATH=$PWD/.venv/flexbe':  # FlexBE's state packages, as `make flexbe` indexes them
        environment = dict(environment, AMENT_PREFIX_PATH=str(request.getfixturevalue('flexbe')))
        argv = argv[1:]
    name = program(argv)
    if name == 'ros2' and argv[1:3] == ['action', 'send_goal']:  # the terminal route, through the pinned ros2cli
        check_ros2_send_goal(argv, request.getfixturevalue('suite'), request.getfixturevalue('flexbe'), scratch)
        return
    if name in ELSEWHERE:
        return  # see ELSEWHERE: exercised by the named tests, not pasteable on this machine
    if name == 'behavior-synthesis':
        subcommand = next((w for w in argv[1:] if not w.startswith('-')), None)
        if subcommand is None:
            assert argv[1:] == ['--help'], command
        else:
            assert subcommand in SUBCOMMANDS, command
            build_parser(only=subcommand).parse_args(argv[1:])  # every option exists, values fit
        if subcommand in SERVERS:
            seconds = start_and_stop(as_run(argv), environment, scratch, SERVERS[subcommand])
            assert seconds < 3.0, (command, seconds)
            return
        if subcommand == 'send-goal':
            system = argv[argv.index('--system') + 1] if '--system' in argv else 'atlas'
            if not (REPOSITORY / 'config' / f'{system}.yaml').exists():
                return  # an example system the reader writes first (the README shows its file)
            environment = request.getfixturevalue('suite')
        elif subcommand is not None and subcommand not in QUICK:
            pytest.fail(f'{command}: say in this test how to check `{subcommand}`')
        result = subprocess.run(as_run(argv), env=environment, cwd=scratch, capture_output=True, text=True,
                                timeout=300)
        assert result.returncode == 0, (command, result.stdout[-1500:], result.stderr[-1500:])
        return
    executable = BIN / name
    assert executable.exists(), f'{command}: {name} is neither ours nor listed in ELSEWHERE'
    if background or name.endswith('-node') or name.endswith('-operator'):
        result = subprocess.run([str(executable), '--help'], env=environment, capture_output=True, text=True,
                                timeout=60)
        assert result.returncode == 0, (command, result.stderr[-1500:])
        return
    result = subprocess.run(as_run(argv), env=environment, cwd=scratch, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, (command, result.stdout[-1500:], result.stderr[-1500:])
