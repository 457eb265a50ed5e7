"""The suite's commands run as processes of their own: started in a session of their own, their
output watched, on a reserved loopback ROS domain, and their synthesis processes found and measured."""

import contextlib
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from synthesis_manager.ros.env import prepare_ros_environment
from waiting import wait_until
from synthesis_manager.ros.harness import reserve_domain_id

BIN = Path(sys.executable).parent
GUI_URL = r'behavior synthesis GUI: (http://\S+/)'


class Output:
    """Collects a process's output in a thread; ``wait_for`` a pattern in it.

    Read in chunks, not lines: progress bars end their updates with a carriage return only.
    """

    def __init__(self, process):
        self.process, self.chunks = process, []
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        while chunk := os.read(self.process.stdout.fileno(), 65536):
            self.chunks.append(chunk.decode(errors='replace'))

    def wait_for(self, pattern: str, timeout: float = 60.0) -> re.Match:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            exited = self.process.poll() is not None
            match = re.search(pattern, self.text())
            if match or exited:
                break
            time.sleep(0.05)
        assert match, f'no {pattern!r} from {self.process.args}:\n{self.text()}'
        return match

    def text(self) -> str:
        return ''.join(self.chunks)


@contextlib.contextmanager
def started(command, env=None, cwd=None):
    """``command`` running in a session of its own (output collected); on leaving, whatever is
    still running of it (its process group, and descendants in groups of their own, such as
    an external synthesizer) is killed."""
    process = subprocess.Popen([str(part) for part in command], env=env, cwd=cwd, stdout=subprocess.PIPE,
                               stderr=subprocess.STDOUT, start_new_session=True)
    try:
        yield process, Output(process)
    finally:
        for pid in descendants(process.pid):
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()


@contextlib.contextmanager
def loopback_domain():
    """A reserved ROS domain and an environment for processes on it (DDS on loopback)."""
    with reserve_domain_id() as domain:
        yield domain, prepare_ros_environment(domain, environ=dict(os.environ))


def descendants(pid: int) -> set[int]:
    """Process ids of ``pid``'s children, grandchildren, ... (from /proc)."""
    parents = {}
    for entry in Path('/proc').iterdir():
        if entry.name.isdigit():
            with contextlib.suppress(OSError):
                # the command name (field 2) may hold spaces and parentheses: split after it
                fields = (entry / 'stat').read_text().rsplit(')', 1)[1].split()
                parents[int(entry.name)] = int(fields[1])
    found, frontier = set(), {pid}
    while frontier:
        frontier = {child for child, parent in parents.items() if parent in frontier} - found
        found |= frontier
    return found


def stacks(pid: int) -> str:
    """The Python and native stacks of every thread of ``pid`` and its descendants, for the
    failure message of a process that did not stop: a hang is then told by where it waits.
    py-spy (a test dependency) reads them from outside; without it, gdb's native stacks."""
    spy = Path(sys.executable).parent / 'py-spy'
    dumps = []
    for process in [pid, *sorted(descendants(pid))]:
        command = ([str(spy), 'dump', '--native', '--pid', str(process)] if spy.exists()
                   else ['gdb', '-p', str(process), '-batch', '-ex', 'thread apply all bt 30'])
        try:
            dumped = subprocess.run(command, capture_output=True, text=True, timeout=60)
            dumps.append(f'--- process {process}:\n{dumped.stdout}{dumped.stderr}')
        except (OSError, subprocess.TimeoutExpired) as error:
            dumps.append(f'--- process {process}: no stacks ({error})')
    return '\n'.join(dumps)


def cpu_seconds(pid: int) -> float:
    """User + system CPU time of process ``pid`` so far."""
    fields = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf('SC_CLK_TCK')


def assert_busy_synthesizing(pid: int, cpu: float = 0.3, deadline_s: float = 30.0):
    """One of ``pid``'s synthesis processes (builtin or gr1synth) is computing: it has used
    ``cpu`` seconds of CPU since it was first seen. An idle or stalled child uses none; a
    share of a core in a fixed window failed on a loaded machine (0.12 s in 1 s at load 7)."""
    synthesizers = wait_until(lambda: synthesis_processes(pid), deadline_s, f'a synthesis process of {pid}')
    before = {child: cpu_seconds(child) for child in synthesizers}

    def computing() -> bool:
        used = []
        for child, seconds in before.items():
            with contextlib.suppress(OSError):  # a child that ended is not the one computing
                used.append(cpu_seconds(child) - seconds)
        return max(used, default=0.0) >= cpu

    wait_until(computing, deadline_s, f'a synthesis process of {pid} using {cpu:g} s of CPU')


def synthesis_processes(pid: int) -> list[int]:
    return [child for child in descendants(pid) if _runs_a_synthesis(child)]


def _runs_a_synthesis(pid: int) -> bool:
    try:
        command = Path(f'/proc/{pid}/cmdline').read_bytes()
    except OSError:
        return False
    return b'gr1synth' in command or b'respec.child_processes.runner' in command


@contextlib.contextmanager
def serve_with_clients(tmp_path, *actions: str):
    """``serve`` in a process of its own, and a SynthesisClient here for each action name
    (``behavior_synthesis``, ``flexbe_synthesis``), each of its own client, its server up."""
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient
    from synthesis_manager.ros.harness import RosHarness

    with loopback_domain() as (domain, environment):
        with started([BIN / 'behavior-synthesis', 'serve', '--byproducts-dir', tmp_path / 'byproducts'],
                     environment) as (server, output):
            output.wait_for('suite up')
            with RosHarness(domain_id=domain) as ros:
                clients = [SynthesisClient(ros.add_node(Node, f'client_{index}'), action)
                           for index, action in enumerate(actions or ('behavior_synthesis',))]
                for client in clients:
                    assert client.wait_for_server(30)
                yield server, clients
