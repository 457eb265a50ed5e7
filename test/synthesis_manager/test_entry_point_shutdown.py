"""SIGINT and SIGTERM stop every long-running entry point within 3 s, even mid-synthesis.

Each test starts the entry point as its own process, waits until it is provably in the
middle of a synthesis (or, for the simulator, of an action), waits a second more, sends
the signal and measures how long the process takes to exit. It also checks the exit code
(0 for the node scripts; 128 + the signal number for every ``behavior-synthesis`` command,
servers included, and gr1synth, after a client has cancelled its goal) and that the process left nothing behind: no child
process, and no suite still burning CPU on a goal nobody waits for.

The runaway syntheses are real requests: through ROS and gr1synth a specification whose
strategy extraction would take hours (``RUNAWAY_SPEC``); through the GUI and the
in-process commands, which take only a robot system and goals, a system whose goal needs
300 parts assembled at once (``many_parts_config``), whose BDD operations run for seconds
each. The builtin synthesizer runs each synthesis in a child process, which a stop kills
(respec.child_processes); one test uses gr1synth as the external synthesizer instead.
"""

import contextlib
import json
import os
import signal
import subprocess
import threading
import time
from pathlib import Path

import httpx
import pytest
from rclpy.node import Node

from respec.parsing import spec_from_text_sections

from synthesis_manager.client import SynthesisClient
from synthesis_manager.ros.harness import RosHarness
from respec.robot import robot_system
from atlas_sim_client import Client as SimClient
from runaway_requests import RUNAWAY_SPEC, many_parts_config, runaway_gui_job, runaway_goal
from suite_processes import (BIN, GUI_URL, assert_busy_synthesizing, cpu_seconds, descendants, loopback_domain,
                             stacks, started, synthesis_processes)
from waiting import wait_until

pytestmark = pytest.mark.ros

STOP_WITHIN = 3.0  # seconds from the signal to the process's exit
STOP_SIGNALS = pytest.mark.parametrize('stop_signal', [signal.SIGINT, signal.SIGTERM], ids=['SIGINT', 'SIGTERM'])
NODE_SCRIPTS = ('ltl-compilation-node', 'ltl-synthesis-node', 'sm-generation-node', 'behavior-synthesis-server')
EXTERNAL_SYNTHESIZER = ['--backend', 'slugs', '--slugs-executable', BIN / 'gr1synth']


# --- processes ------------------------------------------------------------------------------

def assert_busy(pid: int, cpu: float = 0.3, deadline_s: float = 30.0):
    """``pid`` is computing: it uses ``cpu`` seconds of CPU from now (an idle process uses none;
    a third of a core in a fixed second failed at load 7: 0.32 s)."""
    before = cpu_seconds(pid)
    wait_until(lambda: cpu_seconds(pid) - before >= cpu, deadline_s, f'process {pid} using {cpu:g} s of CPU')


def assert_idle(pid: int, within: float = 1.0):
    """``pid`` has gone back to idle: under a fifth of a core over ``within`` seconds (a synthesis
    uses a whole one; an idle server beside a CPU-bound job on this 2-core machine used 0.11-0.13 s
    in 1 s, over the tenth this asked before)."""
    def quiet():  # the last moments of a stopped synthesis are over
        before = cpu_seconds(pid)
        time.sleep(0.2)
        return cpu_seconds(pid) - before <= 0.2 / 5
    wait_until(quiet, 10, f'process {pid} quiet for 0.2 s')
    before = cpu_seconds(pid)
    time.sleep(within)  # the measurement window
    used = cpu_seconds(pid) - before
    assert used < within / 5, f'process {pid} still used {used:.2f} s CPU in {within} s'


def assert_no_synthesis_running(pid: int, within: float = 1.0):
    """Every synthesis process of ``pid`` left is idle (a stopped one is replaced by an idle one)."""
    before = {child: cpu_seconds(child) for child in synthesis_processes(pid)}
    time.sleep(within)  # the measurement window
    for child, seconds in before.items():
        with contextlib.suppress(OSError):
            assert cpu_seconds(child) - seconds < within / 10, f'synthesis process {child} still computing'


def stop(process, stop_signal, name: str) -> float:
    """Send ``stop_signal``; assert exit within STOP_WITHIN leaving no descendant; returns the seconds."""
    return stop_all({name: process}, stop_signal)[name]


def stop_all(processes: dict, stop_signal) -> dict:
    """``stop`` for several processes signalled at once: {name: seconds to exit}.

    A process's seconds leave out the time its main thread waited for a CPU (the scheduler's
    run-queue wait, /proc/PID/schedstat): at load 7 on the 2 cores a node that stops in under a
    second took 3.6 s of wall time. A process that hangs still fails; the wall time is printed too.
    """
    children = {name: descendants(process.pid) for name, process in processes.items()}
    waited_before = {name: cpu_wait_seconds(process.pid) for name, process in processes.items()}
    signalled = time.monotonic()
    for process in processes.values():
        process.send_signal(stop_signal)
    wall, seconds = {}, {}
    while len(wall) < len(processes) and time.monotonic() - signalled < 30:
        for name, process in processes.items():
            if name not in wall and exited(process.pid):
                wall[name] = time.monotonic() - signalled
                seconds[name] = wall[name] - (cpu_wait_seconds(process.pid) - waited_before[name])
                process.wait()  # reaps it: only now, its schedstat was still to be read
        time.sleep(0.01)
    for name, process in processes.items():
        assert name in wall, f'{name} still running 30 s after {stop_signal.name}; its stacks:\n{stacks(process.pid)}'
        print(f'{name}: {stop_signal.name} -> exit {process.returncode} in {seconds[name]:.2f} s '
              f'({wall[name]:.2f} s with waits for a CPU)')
    for name, process in processes.items():
        left = {pid for pid in children[name] if Path(f'/proc/{pid}').exists()}
        assert not left, f'{name} left processes {sorted(left)} behind'
        assert seconds[name] < STOP_WITHIN, f'{name} took {seconds[name]:.2f} s to stop after {stop_signal.name}'
    return seconds


def exited(pid: int) -> bool:
    """``pid``, a child of this process, has exited; it stays unreaped (its /proc entry readable)."""
    return os.waitid(os.P_PID, pid, os.WEXITED | os.WNOHANG | os.WNOWAIT) is not None


def cpu_wait_seconds(pid: int) -> float:
    """Seconds the main thread of ``pid`` has spent runnable but waiting for a CPU."""
    return int(Path(f'/proc/{pid}/schedstat').read_text().split()[1]) / 1e9


def signal_exit_code(stop_signal) -> int:
    """A command stopped by a signal exits with 128 + its number (README's status table)."""
    return 128 + stop_signal


# --- runaway requests -------------------------------------------------------------------------

MANY_PARTS_TASK = ['--system', 'many_parts', '--initial-conditions', 'idle', '--goals', 'assemble']


def start_runaway_goal(ros):
    """Send ``runaway_goal()`` to /behavior_synthesis from a client in ``ros``; return once it synthesizes."""
    client = SynthesisClient(ros.add_node(Node, 'shutdown_client'))
    assert client.wait_for_server(timeout=30)
    synthesizing = threading.Event()

    def send():
        try:
            client.run(runaway_goal(), timeout=60,
                       feedback=lambda status, _: status.startswith('Synthesizing') and synthesizing.set())
        except Exception:  # noqa: BLE001 - the test stops the server under this goal: its result never comes
            pass

    threading.Thread(target=send, daemon=True).start()
    assert synthesizing.wait(30), 'the runaway goal did not reach the synthesis'


# --- servers and nodes --------------------------------------------------------------------------

@STOP_SIGNALS
def test_serve_stops_within_three_seconds_in_the_middle_of_a_runaway_synthesis(tmp_path, stop_signal):
    with loopback_domain() as (domain, environment):
        with started([BIN / 'behavior-synthesis', 'serve', '--byproducts-dir', tmp_path], environment) as (
                process, output):
            output.wait_for('suite up')
            with RosHarness(domain_id=domain) as ros:
                start_runaway_goal(ros)
                assert_busy_synthesizing(process.pid)  # a second well into the synthesis
                stop(process, stop_signal, 'serve')
                assert process.returncode == signal_exit_code(stop_signal), output.text()


# Not 2x faster (issue 50): each node is a process of its own, stopped by the signal under test mid-synthesis (3.5 s).
@STOP_SIGNALS
def test_each_node_process_stops_within_three_seconds_in_the_middle_of_a_runaway_synthesis(
        tmp_path, stop_signal):
    """The four node scripts as separate processes; all are signalled while one synthesizes."""
    with loopback_domain() as (domain, environment), contextlib.ExitStack() as stack:
        nodes = {}
        for script in NODE_SCRIPTS:
            arguments = ['--ros-args', '-p', f'byproducts_dir:={tmp_path}'] if script == 'ltl-synthesis-node' else []
            nodes[script] = stack.enter_context(started([BIN / script, *arguments], environment))
        for process, output in nodes.values():
            output.wait_for('ready')
        with RosHarness(domain_id=domain) as ros:
            start_runaway_goal(ros)
            assert_busy_synthesizing(nodes['ltl-synthesis-node'][0].pid)
            stop_all({script: process for script, (process, _) in nodes.items()}, stop_signal)
        for script, (process, output) in nodes.items():
            assert process.returncode == 0, f'{script}:\n{output.text()}'



@STOP_SIGNALS
def test_gui_stops_within_three_seconds_in_the_middle_of_a_runaway_job_with_its_page_watching(
        tmp_path, stop_signal):
    """The GUI with its in-process suite; the job's event stream (the page) stays open."""
    config = many_parts_config(tmp_path / 'config')
    with started([BIN / 'behavior-synthesis', 'gui', '--port', '0', '--config-dir', config,
                  '--byproducts-dir', tmp_path / 'byproducts']) as (process, output):
        url = output.wait_for(GUI_URL).group(1)
        with runaway_gui_job(url) as job:
            assert_busy_synthesizing(process.pid)
            assert httpx.get(f'{url}api/jobs/{job}').json()['state'] == 'running'
            stop(process, stop_signal, 'gui')
        assert process.returncode == signal_exit_code(stop_signal), output.text()


# Not 2x faster (issue 50): serve and the gui are processes of their own, stopped by the signal under test after a
# runaway job starts (5.2-5.3 s).
@STOP_SIGNALS
def test_a_connected_gui_stops_within_three_seconds_and_cancels_its_running_job(tmp_path, stop_signal):
    """``gui --connect`` to a ``serve`` elsewhere: stopping the GUI cancels its goal there."""
    config = many_parts_config(tmp_path / 'config')
    with loopback_domain() as (_, environment):
        with started([BIN / 'behavior-synthesis', 'serve', '--config-dir', config, '--byproducts-dir', tmp_path,
                      *EXTERNAL_SYNTHESIZER], environment) as (server, server_output):
            server_output.wait_for('suite up')
            with started([BIN / 'behavior-synthesis', 'gui', '--port', '0', '--connect', '--config-dir', config],
                         environment) as (gui, output):
                with runaway_gui_job(output.wait_for(GUI_URL).group(1)):
                    assert_busy_synthesizing(server.pid)
                    stop(gui, stop_signal, 'gui --connect')
                assert gui.returncode == signal_exit_code(stop_signal), output.text()
            assert_idle(server.pid)
            assert_no_synthesis_running(server.pid)
            stop(server, signal.SIGINT, 'serve')


@STOP_SIGNALS
def test_the_simulator_node_stops_within_three_seconds_in_the_middle_of_an_action(stop_signal):
    with loopback_domain() as (domain, environment):
        with started([BIN / 'atlas-sim-node', '--ros-args', '-p', 'speed:=0.5', '-p', 'state_rate:=20.0'],
                     environment) as (process, output):
            output.wait_for('atlas_sim ready')
            with RosHarness(domain_id=domain) as ros:
                client = SimClient(ros, 'shutdown_sim_client')
                client.send('stand')
                client.wait_for_state(lambda state: 'stand' in state.running or state.pending_mode == 'stand',
                                      timeout=30)
                time.sleep(1.0)  # the scenario: a second into the action (it runs for many more)
                assert 'stand' in client.states[-1].running or client.states[-1].pending_mode == 'stand'
                stop(process, stop_signal, 'atlas-sim-node')
                assert process.returncode == 0, output.text()


# --- clients ------------------------------------------------------------------------------------

# Not 2x faster (issue 50): serve and send-goal are processes of their own, stopped by the signal under test
# mid-synthesis, with the CPU windows it measures (4.6-5.0 s).
@STOP_SIGNALS
def test_send_goal_stops_within_three_seconds_and_cancels_its_runaway_goal(tmp_path, stop_signal):
    spec = tmp_path / 'runaway.json'
    spec.write_text(json.dumps(RUNAWAY_SPEC))
    with loopback_domain() as (_, environment):
        with started([BIN / 'behavior-synthesis', 'serve', '--byproducts-dir', tmp_path], environment) as (
                server, server_output):
            server_output.wait_for('suite up')
            with started([BIN / 'behavior-synthesis', 'send-goal', '--synthesis-only', spec],
                         environment) as (client, output):
                output.wait_for('Synthesizing')
                assert_busy_synthesizing(server.pid)
                stop(client, stop_signal, 'send-goal')
                assert client.returncode == signal_exit_code(stop_signal), output.text()
                assert 'result: PREEMPTED' in output.text()
            assert_idle(server.pid)  # the goal was cancelled: the suite stopped synthesizing
            assert_no_synthesis_running(server.pid)
            stop(server, signal.SIGINT, 'serve')


@pytest.mark.parametrize('command', ['execute', 'demo', 'export-behavior'])
@STOP_SIGNALS
def test_in_process_suite_commands_stop_within_three_seconds_in_the_middle_of_a_runaway_synthesis(
        tmp_path, command, stop_signal):
    config = many_parts_config(tmp_path / 'config')
    outputs = {'demo': ['--output-dir', tmp_path / 'out'], 'export-behavior': ['-o', tmp_path / 'out'],
               'execute': []}[command]
    with started([BIN / 'behavior-synthesis', command, *MANY_PARTS_TASK, '--config-dir', config,
                  '--byproducts-dir', tmp_path / 'byproducts', *outputs],
                 cwd=tmp_path) as (process, output):
        output.wait_for('Synthesizing')
        assert_busy_synthesizing(process.pid)
        stop(process, stop_signal, command)
        assert process.returncode == signal_exit_code(stop_signal), output.text()
        assert 'interrupted' in output.text()


@STOP_SIGNALS
def test_gr1synth_stops_within_three_seconds_in_the_middle_of_a_runaway_synthesis(tmp_path, stop_signal):
    """Killed by the signal, as a command-line tool should be (the shell reports 128 + its number)."""
    spec = tmp_path / 'runaway.slugsin'
    spec.write_text(spec_from_text_sections(RUNAWAY_SPEC).to_slugsin())
    with started([BIN / 'gr1synth', '--explicitStrategy', '--jsonOutput', '--sysInitRoboticsSemantics', spec,
                  tmp_path / 'strategy.json']) as (process, output):
        time.sleep(1.0)  # the scenario: a second into the run (gr1synth says nothing until its answer)
        assert_busy(process.pid)
        stop(process, stop_signal, 'gr1synth')
        assert process.returncode in (-stop_signal, signal_exit_code(stop_signal)), output.text()
        assert not (tmp_path / 'strategy.json').exists()


def test_gr1synth_time_limit_ends_a_synthesis_in_the_middle_of_long_bdd_operations(tmp_path):
    """The many-parts specification spends seconds inside single CUDD operations; --timeout
    still ends gr1synth on time, with its exit code 3 and no process left behind."""
    from ltl_specification import compile_task
    spec = tmp_path / 'many_parts.slugsin'
    robot = robot_system('many_parts', many_parts_config(tmp_path / 'config'))
    spec.write_text(compile_task(robot, ['idle'], ['assemble']).to_slugsin())
    began = time.monotonic()
    with subprocess.Popen([BIN / 'gr1synth', '--timeout', '2', spec], stdout=subprocess.PIPE,
                          stderr=subprocess.PIPE, text=True) as process:
        children_seen = set()
        while process.poll() is None and time.monotonic() - began < 30:
            children_seen |= descendants(process.pid)
            time.sleep(0.05)
        _, errors = process.communicate(timeout=30)
    assert process.returncode == 3, errors
    assert 'timeout' in errors
    assert time.monotonic() - began < 2 + 2.0  # the limit, plus start-up and parsing
    assert children_seen  # the synthesis ran in a child process ...
    assert not {pid for pid in children_seen if Path(f'/proc/{pid}').exists()}  # ... that is gone
