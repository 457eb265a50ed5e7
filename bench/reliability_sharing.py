"""Issue 48's attacks at full size: a server a team shares (used by bench_reliability.py --sections sharing).

Each attack starts its own ``serve`` (or ``gui``, or command) as a separate process on a reserved
ROS domain and returns its figures: when the answer came against its limit, the server's and the
tree's RSS peaks, another client's normal goal latency beside it, and how long SIGTERM took.
"""

from __future__ import annotations

import contextlib
import os
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path

from reliability_attacks import PAPER, peak_rss_growth, sampled_maximum, timed

BIN = Path(sys.executable).parent
ROOT = Path(__file__).resolve().parents[1]
#: A 12 KB robot file with a 10^9-leaf alias bomb (the shipped atlas.yaml with 9 nested aliases).
ALIAS_BOMB = 'l0: &l0 [x]\n' + ''.join(f'l{i}: &l{i} [{", ".join([f"*l{i - 1}"] * 10)}]\n' for i in range(1, 10))


def _serve(domain: int, byproducts: str, *arguments: str, stdout=subprocess.DEVNULL) -> subprocess.Popen:
    from synthesis_manager.ros.env import prepare_ros_environment

    return subprocess.Popen([str(BIN / 'behavior-synthesis'), 'serve', '--byproducts-dir', byproducts, *arguments],
                            env=prepare_ros_environment(domain, environ=dict(os.environ)), stdout=stdout,
                            stderr=subprocess.STDOUT)


def _sigterm_seconds(process: subprocess.Popen) -> float:
    signalled = time.monotonic()
    process.send_signal(signal.SIGTERM)
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()
        return float('inf')
    return time.monotonic() - signalled


@contextlib.contextmanager
def _clients(domain: int, *actions: str):
    """SynthesisClients on ``domain`` (one per action name, each its own client), servers up."""
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient, make_goal
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness(domain_id=domain) as ros:
        clients = [SynthesisClient(ros.add_node(Node, f'bench_sharing_{index}'), action)
                   for index, action in enumerate(actions)]
        for client in clients:
            assert client.wait_for_server(timeout=60.0), 'serve did not come up'
        for _ in range(2):  # imports, discovery, the first synthesis process
            timed(clients[0].run, make_goal(*PAPER))
        yield ros, clients


def _usual_seconds(client, goal_of, count: int = 3) -> float:
    return sorted(timed(client.run, goal_of(index))[1] for index in range(count))[count // 2]


def one_clients_runaways(domain: int, rss_kib) -> dict:
    """Eight runaway syntheses asking 1e9 s from one client; another client's paper task (no cache)."""
    from synthesis_manager.client import make_goal

    runaway = {'sys_props': [f'p{i}' for i in range(200)], 'env_props': ['e'], 'sys_liveness': ['p0']}
    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as byproducts:
        serve = _serve(domain, byproducts, '--strategy-cache-mb', '0')
        try:
            with _clients(domain, 'behavior_synthesis', 'behavior_synthesis') as (_, (attacker, victim)):
                usual = _usual_seconds(victim, lambda i: make_goal(*PAPER, name=f'usual{i}'))
                cancel, statuses = threading.Event(), []
                threads = [threading.Thread(target=attacker.run, daemon=True, args=(make_goal(
                    'atlas', [], [], option='ltl_synthesis_only', ltl_specification=runaway, timeout=1e9),),
                    kwargs={'cancel': cancel, 'feedback': lambda status, _: statuses.append(status)})
                    for _ in range(8)]
                with peak_rss_growth(serve.pid, lambda pid: rss_kib(pid, with_children=False)) as alone, \
                        peak_rss_growth(serve.pid, rss_kib) as tree:
                    for thread in threads:
                        thread.start()
                    time.sleep(5.0)  # the runaways are long work now
                    outcome, beside = timed(victim.run, make_goal(*PAPER, name='beside', timeout=30.0))
                    sigterm = _sigterm_seconds(serve)
                    cancel.set()
        finally:
            if serve.poll() is None:
                serve.kill()
    return {'another client, usual s': usual, 'another client beside them, s': beside,
            'its answer': outcome.error_name if outcome else 'NO RESULT',
            'runaways told to wait (the last place told)': max(
                (int(m.group(1)) for s in statuses if (m := re.search(r'number (\d+) of', s))), default=0),
            'server peak RSS growth MiB': alone['MiB'], 'tree peak RSS growth MiB': tree['MiB'],
            'SIGTERM during them: exit after s': sigterm}


def refused_big_goals(domain: int, rss_kib) -> dict:
    """Five FlexBESynthesis goals of 10,000 names of 5 KB (50 MB) each, refused: RSS 5 s later."""
    from synthesis_manager.client import make_flexbe_goal

    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as byproducts:
        serve = _serve(domain, byproducts)
        try:
            with _clients(domain, 'behavior_synthesis', 'flexbe_synthesis') as (_, (client, flexbe)):
                before = rss_kib(serve.pid, with_children=False) / 1024
                seconds = []
                with peak_rss_growth(serve.pid, lambda pid: rss_kib(pid, with_children=False)) as peak:
                    for _ in range(5):
                        outcome, took = timed(flexbe.run, make_flexbe_goal('atlas', ['stand_prep'],
                                                                           ['g' * 5000] * 10_000), timeout=300)
                        seconds.append(took)
                time.sleep(5.0)  # the measure: what is kept 5 s later
                kept = rss_kib(serve.pid, with_children=False) / 1024 - before
                from synthesis_manager.client import make_goal
                _, normal = timed(client.run, make_goal(*PAPER))
                sigterm = _sigterm_seconds(serve)
        finally:
            if serve.poll() is None:
                serve.kill()
    return {'answers': f'{outcome.error_name if outcome else "NO RESULT"} x5, {min(seconds):.2f}-{max(seconds):.2f} s',
            'server RSS before MiB': before, 'server peak RSS growth MiB': peak['MiB'],
            'server RSS kept 5 s later MiB': kept, 'a normal goal right after, s': normal,
            'SIGTERM: exit after s': sigterm}


def alias_bomb_robot_file(domain: int, rss_kib) -> dict:
    """A copy of atlas.yaml with a 10^9-leaf alias bomb in a --config-dir: start-up, a goal, SIGTERM."""
    from synthesis_manager.client import make_goal

    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as folder:
        config = Path(folder) / 'config'
        config.mkdir()
        (config / 'bombed.yaml').write_text((ROOT / 'config' / 'atlas.yaml').read_text() + ALIAS_BOMB)
        log = Path(folder) / 'serve.log'
        started = time.monotonic()
        with open(log, 'wb') as output:
            serve = _serve(domain, str(Path(folder) / 'byproducts'), '--config-dir', str(config), stdout=output)
            try:
                with peak_rss_growth(serve.pid, rss_kib) as tree:
                    with _clients(domain, 'behavior_synthesis') as (_, (client,)):
                        up = time.monotonic() - started
                        bombed, bombed_seconds = timed(client.run, make_goal('bombed', ['stand_prep'], ['look_down'],
                                                                             timeout=10.0))
                        normal, normal_seconds = timed(client.run, make_goal(*PAPER, timeout=10.0))
                sigterm = _sigterm_seconds(serve)
            finally:
                if serve.poll() is None:
                    serve.kill()
        longest = max((len(line) for line in log.read_bytes().splitlines()), default=0)
    return {'serve up and answering after s': up, 'a goal on the bombed system': f'{bombed.error_name} after '
            f'{bombed_seconds:.2f} s' if bombed else 'NO RESULT', 'a normal goal (10 s limit), s': normal_seconds,
            'its answer': normal.error_name if normal else 'NO RESULT', 'tree peak RSS growth MiB': tree['MiB'],
            'longest log line, characters': longest, 'SIGTERM: exit after s': sigterm}


#: The sum limit the bombs' server gets: low enough that the three bombs together reach it (with
#: the structural variable order each grows to about 500 MiB in 300 s, under its own 2 GB).
BOMBS_SUM_LIMIT_MB = 1024


def three_bdd_bombs(domain: int, rss_kib) -> dict:
    """Three distinct BDD bombs at once (each under its own 2 GB limit): the tree against the sum limit."""
    from reliability_service import bdd_bomb_spec
    from synthesis_manager.client import make_goal

    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as byproducts:
        serve = _serve(domain, byproducts, '--memory-sum-limit-mb', str(BOMBS_SUM_LIMIT_MB))
        try:
            with _clients(domain, 'behavior_synthesis', 'behavior_synthesis', 'behavior_synthesis',
                          'behavior_synthesis') as (_, clients):
                answers = [None] * 3
                with sampled_maximum(lambda: rss_kib(serve.pid)) as tree:
                    threads = [threading.Thread(target=lambda i=i: answers.__setitem__(i, timed(
                        clients[i].run, make_goal('atlas', [], [], option='ltl_synthesis_only',
                                                  ltl_specification=bdd_bomb_spec(24 + i), timeout=300.0),
                        timeout=400))) for i in range(3)]
                    for thread in threads:
                        thread.start()
                    time.sleep(10.0)
                    _, normal = timed(clients[3].run, make_goal(*PAPER))
                    for thread in threads:
                        thread.join()
                sigterm = _sigterm_seconds(serve)
        finally:
            if serve.poll() is None:
                serve.kill()
    return {'answers': ', '.join(f'{o.error_name if o else "NO RESULT"} after {s:.1f} s' for o, s in answers),
            'tree peak RSS MiB': tree['KiB'] / 1024, 'sum limit MiB': BOMBS_SUM_LIMIT_MB,
            'another client beside them, s': normal, 'SIGTERM: exit after s': sigterm}


def gui_idle_connections(domain: int, _rss_kib) -> dict:
    """1,100 idle connections to a GUI whose open-files limit is 1,024: normal requests, the log."""
    from synthesis_manager.ros.env import prepare_ros_environment

    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as folder:
        log = Path(folder) / 'gui.log'
        with open(log, 'w') as output:
            gui = subprocess.Popen(['prlimit', '--nofile=1024:1024', '--', str(BIN / 'behavior-synthesis'), 'gui',
                                    '--port', '0', '--byproducts-dir', str(Path(folder) / 'byproducts')],
                                   env=prepare_ros_environment(domain, environ=dict(os.environ)), stdout=output,
                                   stderr=subprocess.STDOUT)
            try:
                deadline = time.monotonic() + 60
                while not (match := re.search(r'http://(\S+?):(\d+)/', log.read_text())):
                    assert time.monotonic() < deadline and gui.poll() is None, 'the GUI did not start'
                    time.sleep(0.1)
                host, port = match.group(1), int(match.group(2))
                idle = [socket.create_connection((host, port), timeout=5) for _ in range(1100)]
                answered = []
                for _ in range(5):
                    began = time.monotonic()
                    with urllib.request.urlopen(f'http://{host}:{port}/api/info', timeout=30) as response:
                        response.read()
                    answered.append(time.monotonic() - began)
                time.sleep(15.0)  # what the log gets meanwhile
                for connection in idle:
                    with contextlib.suppress(OSError):
                        connection.close()
                sigterm = _sigterm_seconds(gui)
            finally:
                if gui.poll() is None:
                    gui.kill()
        size = log.stat().st_size
    return {'normal requests beside them, s': ', '.join(f'{s:.2f}' for s in answered),
            'log after 15 s, bytes': size, 'SIGTERM: exit after s': sigterm}


def repair_bomb() -> dict:
    """``repair --time-budget 5`` on a BDD-bomb custom LTL: wall time and the tree's peak."""
    import json

    pairs = 26
    xs, ys = [f'x{i}' for i in range(pairs)], [f'y{i}' for i in range(pairs)]
    with tempfile.TemporaryDirectory(prefix='bench-sharing-') as folder:
        bomb = Path(folder) / 'bomb.json'
        bomb.write_text(json.dumps({'env_props': xs, 'sys_props': ys, 'sys_trans': [
            ' | '.join(xs + ys + ['!x0']), ' & '.join(f"(y{i}' <-> x{i})" for i in range(pairs))]}))
        began = time.monotonic()
        done = subprocess.run(['/usr/bin/time', '-f', '%M', str(BIN / 'behavior-synthesis'), 'repair', '--system',
                               'atlas', '--initial-conditions', 'stand_prep', '--goals', 'look_down,stand_prep',
                               '--custom-ltl', str(bomb), '--time-budget', '5'], capture_output=True, text=True)
        seconds = time.monotonic() - began
    peak_kib = int(done.stderr.strip().splitlines()[-1])
    return {'exit status': done.returncode, 'wall s (budget 5)': seconds, 'largest process peak RSS MiB': peak_kib / 1024,
            'said': ' '.join(done.stdout.split())[:160]}


SHARING_ATTACKS = {'one client, eight runaways asking 1e9 s': one_clients_runaways,
                   'five refused 50 MB goals': refused_big_goals,
                   'a 10^9-leaf alias bomb in a robot file': alias_bomb_robot_file,
                   'three BDD bombs at once': three_bdd_bombs,
                   'GUI: 1,100 idle connections, 1,024 open files': gui_idle_connections}


def sharing_attacks(domain: int, rss_kib, only=None) -> dict:
    """Every attack of SHARING_ATTACKS (or ``only`` those titles) and the repair bomb: {title: figures}."""
    report = {}
    for title, attack in SHARING_ATTACKS.items():
        if only and title not in only:
            continue
        print(f'sharing attack: {title}', flush=True)
        report[title] = attack(domain, rss_kib)
    if not only or 'repair --time-budget 5 on a BDD bomb' in only:
        print('sharing attack: repair on a BDD bomb', flush=True)
        report['repair --time-budget 5 on a BDD bomb'] = repair_bomb()
    return report
