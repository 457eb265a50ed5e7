"""The attacks of issue 34 at full size (used by bench_reliability.py, section 'service').

Each attack against ``serve`` runs twice on a fresh server: once to its end, giving what came
back and when (against its limit), the server's peak RSS alone and with its child processes,
and how long a normal goal sent right after it takes; and once more, stopped by SIGTERM two
seconds into it, giving the seconds to exit. The GUI's deep body, ``gr1synth``'s large input
and ``kill -9`` during a goal have their own processes.

    .venv/bin/python bench/bench_reliability.py --sections service
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request
from collections import Counter
from concurrent.futures import ThreadPoolExecutor

from reliability_attacks import PAPER, peak_rss_growth, timed

BIN = os.path.dirname(sys.executable)
SIGTERM_AFTER = 2.0  # seconds into an attack
STRATEGY_INPUTS = 9


def custom_formulas(total_bytes: int, formula_bytes: int = 56_000, clause: str = '(look_down_a | !stand_prep_a)'):
    formula = ' & '.join([clause] * (formula_bytes // (len(clause) + 3)))
    return [formula] * max(1, total_bytes // len(formula))


def free_inputs_spec(inputs: int) -> dict:
    return {'env_props': [f'e{i}' for i in range(inputs)], 'sys_props': ['p'], 'sys_liveness': ['p']}


def bdd_bomb_spec(pairs: int) -> dict:
    """next(y_i) <-> x_i with every x ordered before every y: a BDD of 2**pairs nodes."""
    xs, ys = [f'x{i}' for i in range(pairs)], [f'y{i}' for i in range(pairs)]
    return {'env_props': xs, 'sys_props': ys,
            'sys_trans': [' | '.join(xs + ys + ['!x0']), ' & '.join(f"(y{i}' <-> x{i})" for i in range(pairs))]}


# --- the attacks on serve: each takes (client, flexbe_client) and returns its figures --------

def compile_freeze(client, _flexbe):
    """20 goals of 3.9 MB custom formulas (70 of 56 KB: the 4 MiB message cap allows no more)
    with 5 s limits, all at once; and one of the original 11 MB."""
    from synthesis_manager.client import make_goal
    goals = [make_goal(*PAPER, name=f'freeze{i}', timeout=5.0,
                       ltl_specification={'sys_trans': custom_formulas(3_900_000)}) for i in range(20)]
    with ThreadPoolExecutor(len(goals)) as pool:
        answers = list(pool.map(lambda goal: timed(client.run, goal, timeout=300), goals))
    original, seconds = timed(client.run, make_goal(*PAPER, timeout=5.0, ltl_specification={
        'sys_trans': custom_formulas(11_000_000)}))
    late = [seconds - 5.0 for _, seconds in answers]
    return {'codes': _codes(answers), 'answered after the 5 s limit, s (max)': max(late),
            'answered after the 5 s limit, s (median)': sorted(late)[len(late) // 2],
            'the original 11 MB goal': f'{_code(original)} after {seconds:.2f} s'}


def synthesis_freeze(client, _flexbe):
    """20 ``ltl_synthesis_only`` goals of 3.9 MB specifications with 5 s limits, all at once."""
    from synthesis_manager.client import make_goal
    spec = {'env_props': ['look_down_a'], 'sys_props': ['stand_prep_a'], 'sys_liveness': ['stand_prep_a'],
            'sys_trans': custom_formulas(3_900_000, clause="(stand_prep_a' | !look_down_a)")}
    goals = [make_goal('atlas', [], [], option='ltl_synthesis_only', name=f'large{i}', timeout=5.0,
                       ltl_specification=spec) for i in range(20)]
    with ThreadPoolExecutor(len(goals)) as pool:
        answers = list(pool.map(lambda goal: timed(client.run, goal, timeout=300), goals))
    late = sorted(seconds - 5.0 for _, seconds in answers)
    return {'codes': _codes(answers), 'answered after the 5 s limit, s (max)': late[-1],
            'answered after the 5 s limit, s (median)': late[len(late) // 2]}


def huge_strategy(client, _flexbe):
    """A specification of a few hundred bytes with STRATEGY_INPUTS free inputs (9: 524,288 strategy
    transitions; the issue's 11, 8.4 M, take minutes to extract in the child before they are counted)."""
    from synthesis_manager.client import make_goal
    outcome, seconds = timed(client.run, make_goal('atlas', [], [], option='ltl_synthesis_only',
                                                   ltl_specification=free_inputs_spec(STRATEGY_INPUTS)), timeout=300)
    return {'answer': f'{_code(outcome)} after {seconds:.2f} s: {outcome.message[:120] if outcome else ""}'}


def bdd_bombs(client, _flexbe):
    """Two BDD bombs in a row (the synthesis node's memory limit, 2,048 MB): each grows about
    13 MB a second, so a 300 s limit lets the memory limit end both (at 120 s, 1.5 GB)."""
    from synthesis_manager.client import make_goal
    figures = {}
    for index in (1, 2):
        outcome, seconds = timed(client.run, make_goal('atlas', [], [], option='ltl_synthesis_only', timeout=300.0,
                                                       ltl_specification=bdd_bomb_spec(40)), timeout=400)
        figures[f'bomb {index}'] = f'{_code(outcome)} after {seconds:.2f} s: {outcome.message[:90] if outcome else ""}'
    return figures


def huge_list(_client, flexbe):
    """A FlexBE goal whose goal list is 10,000 names of 5 KB (50 MB)."""
    from synthesis_manager.client import make_flexbe_goal
    outcome, seconds = timed(flexbe.run, make_flexbe_goal('atlas', ['stand_prep'], ['g' * 5000] * 10_000))
    return {'answer': f'{_code(outcome)} after {seconds:.2f} s: {outcome.message[:100] if outcome else ""}'}


def mixed_burst(client, _flexbe, count: int = 200):
    """200 goals at once with 1 s limits: half whole pipelines, half runaway syntheses."""
    from synthesis_manager.client import make_goal
    runaway = {'sys_props': [f'p{i}' for i in range(200)], 'env_props': ['e'], 'sys_liveness': ['p0']}
    goals = [make_goal(*PAPER, name=f'mixed{i}', timeout=1.0) if i % 2 else
             make_goal('atlas', [], [], option='ltl_synthesis_only', ltl_specification=runaway, timeout=1.0)
             for i in range(count)]
    with ThreadPoolExecutor(count) as pool:
        answers = list(pool.map(lambda goal: timed(client.run, goal, timeout=120), goals))
    late = sorted(seconds - 1.0 for _, seconds in answers)
    return {'codes': _codes(answers), 'answered after the 1 s limit, s (max)': late[-1],
            'answered after the 1 s limit, s (median)': late[len(late) // 2],
            'answered after the 1 s limit, s (95th percentile)': late[int(0.95 * (len(late) - 1))]}


SERVE_ATTACKS = {'compile freeze (20 x 3.9 MB custom LTL, 5 s limits)': compile_freeze,
                 'synthesis freeze (20 x 3.9 MB specifications, 5 s limits)': synthesis_freeze,
                 'huge strategy (9 free inputs)': huge_strategy,
                 'two BDD bombs in a row': bdd_bombs,
                 '50 MB goal list': huge_list,
                 '200-goal mixed burst, 1 s limits': mixed_burst}


def _code(outcome) -> str:
    return 'NO RESULT' if outcome is None else outcome.error_name


def _codes(answers) -> str:
    return ', '.join(f'{code} {count}' for code, count in sorted(Counter(_code(o) for o, _ in answers).items()))


# --- running them --------------------------------------------------------------------------

def serve_attacks(domain: int, rss_kib, serve_class, only=None) -> dict:
    """Every attack of SERVE_ATTACKS (or ``only`` those names) on fresh servers: {title: figures}."""
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient, make_goal
    from synthesis_manager.ros.harness import RosHarness

    report = {}
    with RosHarness(domain_id=domain) as ros:
        client = SynthesisClient(ros.add_node(Node, 'bench_service_client'))
        flexbe = SynthesisClient(ros.add_node(Node, 'bench_service_flexbe_client'), 'flexbe_synthesis')
        for title, attack in SERVE_ATTACKS.items():
            if only and title not in only:
                continue
            print(f'service attack: {title}', flush=True)
            with tempfile.TemporaryDirectory(prefix='bench-service-') as byproducts:
                serve = _started(serve_class, domain, byproducts, client, flexbe)
                pid = serve.process.pid
                with peak_rss_growth(pid, lambda p: rss_kib(p, with_children=False)) as alone:
                    with peak_rss_growth(pid, rss_kib) as together:
                        baseline_alone = rss_kib(pid, with_children=False)
                        figures = attack(client, flexbe)
                _, normal_seconds = timed(client.run, make_goal(*PAPER))
                figures.update({'server RSS before MiB': baseline_alone / 1024,
                                'server peak RSS growth MiB': alone['MiB'],
                                'server peak RSS MiB': baseline_alone / 1024 + alone['MiB'],
                                'server with its children: peak RSS growth MiB': together['MiB'],
                                'a normal goal right after it, s': normal_seconds})
                serve.process.send_signal(signal.SIGINT)
                serve.process.wait(timeout=30)
                figures['SIGTERM 2 s into it: exit after s'] = _sigterm_during(
                    serve_class, domain, byproducts, client, flexbe, attack)
            report[title] = figures
    return report


def _started(serve_class, domain, byproducts, client, flexbe):
    from synthesis_manager.client import make_goal
    serve = serve_class(domain, byproducts)
    assert client.wait_for_server(timeout=60.0) and flexbe.wait_for_server(timeout=60.0), 'serve did not come up'
    for _ in range(2):  # imports, discovery
        timed(client.run, make_goal(*PAPER))
    return serve


def _sigterm_during(serve_class, domain, byproducts, client, flexbe, attack) -> float:
    serve = _started(serve_class, domain, byproducts, client, flexbe)
    threading.Thread(target=lambda: _quietly(attack, client, flexbe), daemon=True).start()
    time.sleep(SIGTERM_AFTER)
    signalled = time.monotonic()
    serve.process.send_signal(signal.SIGTERM)
    try:
        serve.process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        serve.process.kill()
        serve.process.wait()
        return float('inf')
    seconds = time.monotonic() - signalled
    time.sleep(SERVER_GONE_SECONDS)  # the attack's clients see the server gone and return
    return seconds


SERVER_GONE_SECONDS = 4.0


def _quietly(attack, client, flexbe):
    try:
        attack(client, flexbe)
    except Exception:  # noqa: BLE001 -- the server was stopped under it
        pass


def killed_server(domain: int, serve_class) -> dict:
    """kill -9 of serve during a long goal: when send-goal notices, and its exit status."""
    from synthesis_manager.ros.env import prepare_ros_environment
    environment = prepare_ros_environment(domain, environ=dict(os.environ))
    with tempfile.TemporaryDirectory(prefix='bench-killed-') as directory:
        spec = os.path.join(directory, 'runaway.json')
        with open(spec, 'w') as stream:
            json.dump({'sys_props': [f'p{i}' for i in range(200)], 'env_props': ['e'], 'sys_liveness': ['p0']},
                      stream)
        server = subprocess.Popen([os.path.join(BIN, 'behavior-synthesis'), 'serve', '--byproducts-dir', directory],
                                  env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                  start_new_session=True)
        client = subprocess.Popen([os.path.join(BIN, 'behavior-synthesis'), 'send-goal', '--synthesis-only', spec],
                                  env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(15.0)  # the server up, the goal synthesizing
        os.killpg(server.pid, signal.SIGKILL)
        killed = time.monotonic()
        status = client.wait(timeout=300)
        server.wait()
    return {'send-goal exit status': status, 'send-goal ended after the kill, s': time.monotonic() - killed}


def gr1synth_large_input(size_mb: int = 192, limit_mb: int = 200) -> dict:
    """gr1synth --memory-limit 200 on a 192 MB input: exit status, seconds, peak RSS."""
    line = '| a & b | ! a ' * 20 + 'b\n'
    with tempfile.TemporaryDirectory(prefix='bench-gr1synth-') as directory:
        path = os.path.join(directory, 'large.slugsin')
        with open(path, 'w') as stream:
            stream.write('[INPUT]\na\n\n[OUTPUT]\nb\n\n[SYS_TRANS]\n')
            stream.write(line * (size_mb * 2**20 // len(line)))
        launcher = ('import resource, subprocess, sys, time; started = time.monotonic(); '
                    'status = subprocess.run(sys.argv[1:], stderr=subprocess.DEVNULL).returncode; '
                    'print(status, time.monotonic() - started, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)')
        done = subprocess.run([sys.executable, '-c', launcher, os.path.join(BIN, 'gr1synth'), '--memory-limit',
                               str(limit_mb), path], capture_output=True, text=True, timeout=600)
    status, seconds, peak_kib = done.stdout.split()
    return {f'{size_mb} MB input at --memory-limit {limit_mb}': f'exit {status} after {float(seconds):.2f} s, '
                                                                f'peak RSS {int(peak_kib) / 1024:.0f} MiB'}


def gui_deep_body(url: str, gui_pid: int, rss_kib) -> dict:
    """A 200 KB body nested 100,000 deep POSTed to /api/jobs: the answer, the GUI alive after."""
    body = b'[' * 100_000 + b']' * 100_000
    request = urllib.request.Request(url + 'api/jobs', method='POST', data=body,
                                     headers={'Content-Type': 'application/json'})
    started = time.monotonic()
    try:
        with urllib.request.urlopen(request, timeout=60) as response:
            status = response.status
    except urllib.error.HTTPError as error:
        status = error.code
    seconds = time.monotonic() - started
    with urllib.request.urlopen(url + 'api/systems', timeout=60) as response:
        alive = response.status == 200
    return {'answer': f'HTTP {status} after {seconds:.2f} s', 'GUI serving after it': alive,
            'GUI RSS MiB': rss_kib(gui_pid, with_children=False) / 1024}
