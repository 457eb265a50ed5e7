"""A fleet across hosts on one machine: four network namespaces joined by a bridge of their own.

Issue 36 item 3: the suite's nodes split over four "hosts" (Linux network namespaces, each
with its own loopback and one veth link into a bridge that lives in a fifth, private "switch"
namespace), DDS discovery on that private subnet only, clients on every host, and faults
(a link down and back, a host's processes killed, a host restarted). Nothing is added to the
machine's own network namespace: the bridge and every address exist only inside the
namespaces, which are deleted (with their links) on leaving, whatever happened.

    host 1: behavior_synthesis_server        (serve --nodes behavior_synthesis_server)
    host 2: ltl_compilation, sm_generation   (serve --nodes ltl_compilation,sm_generation)
    host 3: ltl_synthesis                    (serve --nodes ltl_synthesis)
    host 4: ltl_synthesis                    (serve --nodes ltl_synthesis)

Two synthesis nodes offer the same service: ROS delivers each request to every server of a
name and the caller takes the first answer, so the second worker is a hot standby (each
synthesis runs on both), not a share of the load.

Needs root and ``ip`` (Debian: iproute2). Used by test/synthesis_manager/test_fleet_hosts.py
(small size) and bench/bench_fleet.py (the issue's size). ``python bench/fleet_network.py
clients ...`` is the client process run on each host.
"""

from __future__ import annotations

import argparse
import contextlib
import faulthandler
import json
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

REPOSITORY = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
SUBNET = '10.213.7'  # /24, private, present only inside the namespaces
TASK = ('atlas', ['stand_prep'], ['look_down', 'pickup_object'])
ROLES = {  # host -> the suite nodes it runs
    1: 'behavior_synthesis_server',
    2: 'ltl_compilation,sm_generation',
    3: 'ltl_synthesis',
    4: 'ltl_synthesis',
}
SERVER_HOST, COMPILE_HOST, SYNTHESIS_HOSTS = 1, 2, (3, 4)


def network_namespaces_available() -> bool:
    """Root and ``ip``: what building the private network needs (CI runs as root)."""
    return os.geteuid() == 0 and shutil.which('ip') is not None


def ip(*arguments: str) -> None:
    subprocess.run(['ip', *arguments], check=True, capture_output=True, text=True, timeout=30)


class PrivateNetwork:
    """``hosts`` network namespaces on a bridge in a switch namespace; all removed on exit.

    Host ``i`` has the address ``SUBNET.i`` on its ``eth0``; its only routes are that /24 and
    multicast (DDS discovery) on the same link. The link's other end, ``port<i>``, sits on the
    switch's bridge: taking it down cuts host ``i`` off, as a pulled cable would.
    """

    def __init__(self, hosts: int = 4, prefix: str | None = None):
        self.hosts = hosts
        self.prefix = prefix or f'bsfleet{os.getpid()}'
        self.switch = f'{self.prefix}sw'
        self.processes: list[subprocess.Popen] = []

    def namespace(self, host: int) -> str:
        return f'{self.prefix}h{host}'

    def address(self, host: int) -> str:
        return f'{SUBNET}.{host}'

    def __enter__(self) -> 'PrivateNetwork':
        try:
            ip('netns', 'add', self.switch)
            ip('-n', self.switch, 'link', 'set', 'lo', 'up')
            ip('-n', self.switch, 'link', 'add', 'br0', 'type', 'bridge')
            ip('-n', self.switch, 'link', 'set', 'br0', 'up')
            for host in range(1, self.hosts + 1):
                namespace = self.namespace(host)
                ip('netns', 'add', namespace)
                # both ends are created inside the private namespaces, never in the machine's own
                ip('-n', self.switch, 'link', 'add', f'port{host}', 'type', 'veth', 'peer', 'name', 'eth0',
                   'netns', namespace)
                ip('-n', self.switch, 'link', 'set', f'port{host}', 'master', 'br0', 'up')
                ip('-n', namespace, 'link', 'set', 'lo', 'up')
                ip('-n', namespace, 'addr', 'add', f'{self.address(host)}/24', 'dev', 'eth0')
                ip('-n', namespace, 'link', 'set', 'eth0', 'up', 'multicast', 'on')
                ip('-n', namespace, 'route', 'add', '224.0.0.0/4', 'dev', 'eth0')
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc_info):
        for process in self.processes:
            kill_group(process)
        for host in range(1, self.hosts + 1):
            subprocess.run(['ip', 'netns', 'del', self.namespace(host)], capture_output=True, timeout=30)
        subprocess.run(['ip', 'netns', 'del', self.switch], capture_output=True, timeout=30)
        return False

    def link(self, host: int, up: bool) -> None:
        """Plug (``up``) or pull host ``host``'s cable (its port on the switch)."""
        ip('-n', self.switch, 'link', 'set', f'port{host}', 'up' if up else 'down')

    def start(self, host: int, command: list, environment: dict, log: Path) -> subprocess.Popen:
        """``command`` on host ``host`` (in a session of its own), output appended to ``log``."""
        with open(log, 'ab') as output:
            process = subprocess.Popen(['ip', 'netns', 'exec', self.namespace(host), *map(str, command)],
                                       env=environment, stdout=output, stderr=subprocess.STDOUT,
                                       start_new_session=True)
        self.processes.append(process)
        return process

    def routes(self, host: int) -> list[str]:
        result = subprocess.run(['ip', '-n', self.namespace(host), 'route', 'show', 'table', 'all'],
                                capture_output=True, text=True, check=True, timeout=30)
        return [line for line in result.stdout.splitlines() if line.strip()]


def kill_group(process: subprocess.Popen) -> None:
    """SIGKILL ``process``'s session (it and its synthesis children); reap it."""
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGKILL)
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(timeout=10)


def host_environment(domain_id: int) -> dict:
    """DDS on the private subnet: discovery by multicast on the hosts' one link, UDP only
    (Fast DDS would otherwise pass data between processes of one machine through shared
    memory, past the links the test pulls)."""
    environment = {key: value for key, value in os.environ.items()
                   if not key.startswith(('ROS_', 'FASTRTPS_', 'FASTDDS_'))}
    environment.update(BEHAVIOR_SYNTHESIS_DDS_SCOPE='network', ROS_AUTOMATIC_DISCOVERY_RANGE='SUBNET',
                       FASTDDS_BUILTIN_TRANSPORTS='UDPv4', ROS_DOMAIN_ID=str(domain_id),
                       PYTHONPATH=os.pathsep.join(filter(None, [str(REPOSITORY), os.environ.get('PYTHONPATH')])))
    return environment


@dataclass
class Fleet:
    """The suite's nodes running on the private network's hosts (see the module docstring)."""

    network: PrivateNetwork
    workdir: Path
    domain_id: int = 17
    nodes: dict = field(default_factory=dict)  # host -> its serve process

    def start_host(self, host: int) -> subprocess.Popen:
        command = [BIN / 'behavior-synthesis', 'serve', '--nodes', ROLES[host],
                   '--byproducts-dir', self.workdir / f'byproducts{host}']
        self.nodes[host] = self.network.start(host, command, host_environment(self.domain_id), self.log(host))
        return self.nodes[host]

    def log(self, host: int) -> Path:
        return self.workdir / f'host{host}.log'

    def wait_until_up(self, host: int, timeout: float = 60.0) -> float:
        """Seconds until host ``host``'s serve said it is up."""
        started = time.monotonic()
        while time.monotonic() - started < timeout:
            if 'suite up' in self.log(host).read_text(errors='replace')[-20000:]:
                return time.monotonic() - started
            if self.nodes[host].poll() is not None:
                break
            time.sleep(0.05)
        raise RuntimeError(f'host {host} did not come up:\n{self.log(host).read_text(errors="replace")[-3000:]}')

    def start(self) -> None:
        for host in ROLES:
            self.start_host(host)
        for host in ROLES:
            self.wait_until_up(host)

    def kill(self, host: int) -> None:
        kill_group(self.nodes[host])
        # a fresh log line count: the next 'suite up' is the restarted one's
        self.log(host).write_text('')

    def restart(self, host: int) -> float:
        """Kill host ``host``'s nodes and start them again; seconds until they said they are up."""
        self.kill(host)
        self.start_host(host)
        return self.wait_until_up(host)

    def start_clients(self, host: int, clients: int, goals: int, interval: float, tag: str) -> tuple:
        """A client process on ``host`` running ``clients`` clients of ``goals`` goals each."""
        results = self.workdir / f'results-{tag}-host{host}.jsonl'
        command = [sys.executable, Path(__file__), 'clients', '--host', host, '--clients', clients,
                   '--goals', goals, '--interval', interval, '--output', results]
        process = self.network.start(host, command, host_environment(self.domain_id),
                                     self.workdir / f'clients-{tag}-host{host}.log')
        return process, results


# --- faults and rounds ------------------------------------------------------------------------


def pulled_cable(host: int, seconds: float = 5.0):
    """A fault: host ``host``'s link down for ``seconds``, then back."""
    def fault(fleet: Fleet) -> dict:
        began = time.time()
        fleet.network.link(host, up=False)
        time.sleep(seconds)
        fleet.network.link(host, up=True)
        return {'fault': f'host {host} link down {seconds:g} s', 'host': host, 'began': began, 'ended': time.time()}
    return fault


def killed_host(host: int):
    """A fault: every process of host ``host``'s nodes killed (SIGKILL), not restarted."""
    def fault(fleet: Fleet) -> dict:
        began = time.time()
        fleet.kill(host)
        return {'fault': f'host {host} killed', 'host': host, 'began': began, 'ended': began}
    return fault


def restarted_host(host: int):
    """A fault: host ``host``'s nodes killed (SIGKILL) and started again; ends when they are up."""
    def fault(fleet: Fleet) -> dict:
        began = time.time()
        up = fleet.restart(host)
        return {'fault': f'host {host} restarted', 'host': host, 'began': began, 'ended': time.time(),
                'restart_seconds': round(up, 2)}
    return fault


@dataclass
class Round:
    """One round's goals (one entry per answer) and its fault's times, with what they show."""

    tag: str
    results: list
    expected: int
    fault: dict | None = None
    #: Hosts whose client process, every answer written, did not exit within CLIENT_EXIT_GRACE
    #: (its threads' stacks are in its log; it was killed).
    hung_exits: list = field(default_factory=list)

    def duplicates(self) -> list:
        seen, repeated = set(), []
        for entry in self.results:
            key = (entry['host'], entry['client'], entry['goal'])
            if key in seen:
                repeated.append(key)
            seen.add(key)
        return repeated

    def codes(self) -> dict:
        counts: dict = {}
        for entry in self.results:
            counts[entry['error_name']] = counts.get(entry['error_name'], 0) + 1
        return dict(sorted(counts.items()))

    def failures(self) -> dict:
        """How many non-SUCCESS answers said what (code and message, node names kept)."""
        counts: dict = {}
        for entry in self.results:
            if entry['error_name'] != 'SUCCESS':
                said = f"{entry['error_name']}: {entry['message'][:140]}"
                counts[said] = counts.get(said, 0) + 1
        return dict(sorted(counts.items(), key=lambda item: -item[1]))

    def latencies(self) -> list:
        return sorted(entry['answered'] - entry['sent'] for entry in self.results
                      if entry['error_name'] == 'SUCCESS')

    def recovery_seconds(self) -> float | None:
        """From the fault's end (cable back, host killed, restarted host up) to the next SUCCESS
        answer (for a pulled cable: to that host's clients, the ones it cut off)."""
        if self.fault is None:
            return None
        cable = 'link down' in self.fault['fault']
        answers = [entry['answered'] for entry in self.results
                   if entry['error_name'] == 'SUCCESS' and entry['answered'] >= self.fault['ended']
                   and (not cable or entry['host'] == self.fault['host'])]
        return round(max(0.0, min(answers) - self.fault['ended']), 2) if answers else None

    def summary(self) -> dict:
        latencies = self.latencies()
        figures = {'round': self.tag, 'goals': self.expected, 'answers': len(self.results),
                   'duplicates': len(self.duplicates()), 'codes': self.codes(),
                   'median_s': round(latencies[len(latencies) // 2], 2) if latencies else None,
                   'max_s': round(latencies[-1], 2) if latencies else None,
                   'wall_s': round(max(e['answered'] for e in self.results) - min(e['sent'] for e in self.results), 2)
                   if self.results else None}
        if self.hung_exits:
            figures['client processes that hung on exit'] = self.hung_exits
        if self.fault is not None:
            figures.update(fault=self.fault['fault'], recovery_s=self.recovery_seconds(),
                           **({'restart_s': self.fault['restart_seconds']} if 'restart_seconds' in self.fault else {}))
        return figures


def clients_on_each_host(clients: int) -> dict:
    """``clients`` spread over the hosts as evenly as they go (50 -> 13, 13, 12, 12)."""
    hosts = list(ROLES)
    return {host: clients // len(hosts) + (index < clients % len(hosts)) for index, host in enumerate(hosts)}


def run_round(fleet: Fleet, tag: str, clients: int, goals: int, interval: float,
              fault=None, fault_after: float = 0.2, timeout: float = 600.0) -> Round:
    """``clients`` clients of ``goals`` goals, spread over every host; ``fault`` ``fault_after`` s after
    they all found the server and began their goals.

    Clients are connected before a fault: a client process whose discovery was still under way
    when its host's cable was pulled once stayed without the server after the cable was back
    (Fast DDS 2.14; see docs/deployment.md), a case of its own, not the one measured here."""
    started = [(host, *fleet.start_clients(host, count, goals, interval, tag))
               for host, count in clients_on_each_host(clients).items() if count]
    ready_by = time.monotonic() + 60.0
    while not all(ready_marker(path).exists() for _, _, path in started) and time.monotonic() < ready_by:
        time.sleep(0.02)
    fault_times = None
    if fault is not None:
        time.sleep(fault_after)
        fault_times = fault(fleet)
    deadline = time.monotonic() + timeout
    hung = []
    for host, process, path in started:
        while process.poll() is None and not done_marker(path).exists() and time.monotonic() < deadline:
            time.sleep(0.05)
        try:
            process.wait(timeout=CLIENT_EXIT_GRACE if done_marker(path).exists() else 1.0)
        except subprocess.TimeoutExpired:
            if done_marker(path).exists():  # every answer is in: its exit hangs, say where
                hung.append(host)
                with contextlib.suppress(ProcessLookupError):
                    os.kill(process.pid, signal.SIGUSR1)
                time.sleep(0.5)
            kill_group(process)
    results = [entry for _, _, path in started for entry in read_results(path)]
    return Round(tag, results, clients * goals, fault_times, hung)


#: Seconds a client process may take to exit once it has written every answer.
CLIENT_EXIT_GRACE = 10.0


def done_marker(results: Path) -> Path:
    """The file a client process writes once every one of its goals has its answer written."""
    return results.with_suffix('.done')


def ready_marker(results: Path) -> Path:
    """The file a client process writes once its clients have found the server."""
    return results.with_suffix('.ready')


def read_results(path: Path) -> list[dict]:
    if not path.exists():
        return []
    return [json.loads(line) for line in path.read_text().splitlines() if line.strip()]


# --- the client process -----------------------------------------------------------------------


def run_clients(host: int, clients: int, goals: int, interval: float, output: Path,
                server_wait: float = 15.0, goal_timeout: float = 120.0) -> int:
    """``clients`` clients, each sending ``goals`` goals one after another (a new one every
    ``interval`` s at most); one JSON line per goal and answer: who, when, what came back."""
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient, make_goal
    from synthesis_manager.ros.harness import RosHarness, environment_domain_id

    lock = threading.Lock()

    def record(entry: dict) -> None:
        with lock, open(output, 'a') as stream:
            stream.write(json.dumps(entry) + '\n')

    def one_client(index: int, client) -> None:
        for goal in range(goals):
            started = time.time()
            entry = {'host': host, 'client': index, 'goal': goal, 'sent': started}
            if not client.wait_for_server(timeout=server_wait):
                entry.update(error_name='SERVICE_UNAVAILABLE', by='client',
                             message=f'no behavior_synthesis action server within {server_wait:g} s')
            else:
                try:
                    outcome = client.run(make_goal(*TASK, name=f'h{host}c{index}g{goal}'), timeout=goal_timeout)
                    entry.update(error_name=outcome.error_name, by='server', message=outcome.message[:300],
                                 states=len(outcome.states))
                except TimeoutError as error:
                    entry.update(error_name='CLIENT_TIMEOUT', by='client', message=str(error))
            entry['answered'] = time.time()
            record(entry)
            time.sleep(max(0.0, started + interval - time.time()))

    with RosHarness(domain_id=environment_domain_id(), num_threads=8) as ros:
        node = ros.add_node(Node, f'fleet_clients_host{host}')
        synthesis_clients = [SynthesisClient(node) for _ in range(clients)]
        for client in synthesis_clients:  # connected clients, before the round (and its fault) begins
            client.wait_for_server(timeout=server_wait)
        ready_marker(output).write_text(str(time.time()))
        threads = [threading.Thread(target=one_client, args=(index, client), daemon=True)
                   for index, client in enumerate(synthesis_clients)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        done_marker(output).write_text(str(time.time()))
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description='the client process of the fleet across hosts')
    subparsers = parser.add_subparsers(dest='command', required=True)
    clients = subparsers.add_parser('clients')
    clients.add_argument('--host', type=int, required=True)
    clients.add_argument('--clients', type=int, default=2)
    clients.add_argument('--goals', type=int, default=2)
    clients.add_argument('--interval', type=float, default=0.0)
    clients.add_argument('--output', type=Path, required=True)
    args = parser.parse_args(argv)
    faulthandler.register(signal.SIGUSR1, all_threads=True)  # run_round asks where an exit hangs
    return run_clients(args.host, args.clients, args.goals, args.interval, args.output)


if __name__ == '__main__':
    sys.path.insert(0, str(REPOSITORY))
    sys.exit(main())
