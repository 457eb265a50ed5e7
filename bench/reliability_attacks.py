"""The attacks of issue 25 at full size, against ``serve`` and ``gui`` (used by bench_reliability.py).

Each function returns a dict of figures: what came back, how long after the attack's limit it
came, and the peak growth of the server's RSS (with its synthesis processes) while it lasted.
"""

from __future__ import annotations

import json
import threading
import time
import urllib.error
import urllib.request
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager

PAPER = ('atlas', ['stand_prep'], ['look_down', 'pickup_object'])


def alias_bomb(levels: int = 9) -> str:
    lines = ['a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol]']
    lines += [f'a{i}: &a{i} [' + ', '.join([f'*a{i - 1}'] * 9) + ']' for i in range(1, levels)]
    return '\n'.join(lines)


@contextmanager
def sampled_maximum(read):
    """Yields a dict whose 'KiB' is, afterwards, the largest value ``read()`` gave (every 20 ms)."""
    peak, done = [read()], threading.Event()

    def sample():
        while not done.wait(0.02):
            peak[0] = max(peak[0], read())
    sampler = threading.Thread(target=sample, daemon=True)
    sampler.start()
    figures = {}
    try:
        yield figures
    finally:
        done.set()
        sampler.join()
        figures['KiB'] = peak[0]


@contextmanager
def peak_rss_growth(pid: int, rss_kib):
    """Yields a dict whose 'MiB' is, afterwards, the peak RSS growth of ``pid`` (with children)."""
    baseline, figures = rss_kib(pid), {}
    with sampled_maximum(lambda: rss_kib(pid)) as peak:
        yield figures
    figures['MiB'] = max(0, peak['KiB'] - baseline) / 1024


def simulation_processes_peak_kib(gui_pid: int, children) -> int:
    """The highest peak RSS (VmHWM) of the GUI's running simulation processes (web/simulation_process.py)."""
    peak = 0
    for child in children(gui_pid):
        try:
            with open(f'/proc/{child}/cmdline', 'rb') as cmdline:
                if b'simulation_process' not in cmdline.read():
                    continue
            with open(f'/proc/{child}/status') as status:
                peak = max(peak, next(int(line.split()[1]) for line in status if line.startswith('VmHWM:')))
        except (OSError, StopIteration):  # ended meanwhile
            continue
    return peak


def timed(run, goal, timeout=120.0):
    started = time.monotonic()
    try:
        outcome = run(goal, timeout=timeout)
        return outcome, time.monotonic() - started
    except TimeoutError:
        return None, time.monotonic() - started


def hostile_goals(client, flexbe_client, server_pid: int, rss_kib) -> dict:
    """The alias bomb and deeply nested custom LTL: code, seconds, message length, RSS growth."""
    from synthesis_manager.client import make_flexbe_goal, make_goal

    figures = {}
    bomb = make_flexbe_goal(*PAPER)
    bomb.synthesis_options = alias_bomb(9)
    attacks = {'YAML alias bomb (9 levels, %d B)' % len(bomb.synthesis_options): (flexbe_client, bomb)}
    for label, formula in (('5,000 parentheses', '(' * 5000 + 'look_down_a' + ')' * 5000),
                           ('30,000 !', '!' * 30000 + 'look_down_a'),
                           ('10,001 parentheses', '(' * 10001 + 'look_down_a' + ')' * 10001)):
        attacks[label] = (client, make_goal(*PAPER, option='ltl_compilation_only',
                                            ltl_specification={'sys_trans': [formula]}))
    for label, (sender, goal) in attacks.items():
        with peak_rss_growth(server_pid, rss_kib) as rss:
            outcome, seconds = timed(sender.run, goal)
        code = 'NO RESULT' if outcome is None else (
            outcome.error_name if outcome.error_name not in ('BEHAVIOR_SYNTHESIS_FAILED', 'FAILURE')
            else outcome.message.split(':', 1)[0])
        figures[label] = (f'{code} after {seconds:.2f} s, message {len(outcome.message) if outcome else 0} B, '
                          f'peak RSS +{rss["MiB"]:.0f} MiB')
    _, seconds = timed(client.run, make_goal(*PAPER))
    figures['next ordinary goal, s'] = seconds
    return figures


def limits_under_load(client, slow_goal, count: int = 20) -> dict:
    """Invalid limits and 3 s limits sent in a burst while slow syntheses fill the workers."""
    from synthesis_manager.client import make_goal

    cancel = threading.Event()
    slow = [threading.Thread(target=client.run, args=(slow_goal,), kwargs={'cancel': cancel}) for _ in range(8)]
    for thread in slow:
        thread.start()
    time.sleep(3.0)
    try:
        goals = ([(0.0, make_goal(*PAPER, timeout=-1.0)), (0.0, make_goal(*PAPER, timeout=float('nan')))]
                 + [(3.0, make_goal(*PAPER, name=f'limit{i}', timeout=3.0)) for i in range(count)])
        with ThreadPoolExecutor(len(goals)) as pool:
            answers = list(pool.map(lambda limit_goal: (limit_goal[0], *timed(client.run, limit_goal[1])), goals))
    finally:
        cancel.set()
        for thread in slow:
            thread.join(timeout=60)
    invalid = [seconds for limit, _, seconds in answers if limit == 0.0]
    # A 3 s limit counts from acceptance: the answer is due 3 s after the goal was sent.
    limited = [seconds - limit for limit, _, seconds in answers if limit > 0]
    return {'codes': Counter(outcome.error_name if outcome else 'NO RESULT' for _, outcome, _ in answers),
            'invalid limits answered after s (max)': max(invalid),
            '3 s limits: answered after the limit, s (max)': max(limited),
            '3 s limits: answered after the limit, s (median)': sorted(limited)[len(limited) // 2]}


def plain_client(node, deep_queues: bool = False):
    """A plain rclpy ActionClient: rclpy's default depth-10 queues (as the ros2 CLI and FlexBE
    WebUI make it), or the queues docs/limits.md asks of a client sending bursts."""
    from rclpy.action import ActionClient

    from synthesis_manager.ros.qos import action_client_qos
    from synthesis_msgs.action import BehaviorSynthesis
    client = ActionClient(node, BehaviorSynthesis, 'behavior_synthesis', **(action_client_qos() if deep_queues else {}))
    assert client.wait_for_server(timeout_sec=60)
    return client


def plain_client_burst(client, count: int, wait: float = 120.0) -> dict:
    """``count`` compile-only goals sent at once by a plain rclpy client (:func:`plain_client`), each result asked
    for when its goal is accepted (as the ros2 CLI does); exact counts of what the client hears.

    A result with status UNKNOWN is rclpy's answer for a goal the server does not know (its
    result expired after ``result_retention``, or it was never accepted): an empty result whose
    error code is 0, no code of ours; it is counted apart, not as a code."""
    from action_msgs.msg import GoalStatus

    from synthesis_manager.client import GOAL_STATUS_NAMES, make_goal
    from synthesis_manager.ros.conversions import error_name

    started = time.monotonic()
    results, lock = [], threading.Lock()

    def accepted(future):
        handle = future.result()
        if handle.accepted:
            with lock:
                results.append(handle.get_result_async())

    sent = []
    for index in range(count):
        sent.append(client.send_goal_async(make_goal(*PAPER, name=f'plain{index % 100}', option='ltl_compilation_only')))
        sent[-1].add_done_callback(accepted)
    deadline = time.monotonic() + wait
    while time.monotonic() < deadline and not (all(f.done() for f in sent)
                                               and all(f.done() for f in list(results))):
        time.sleep(0.1)
    responses = [f.result() for f in sent if f.done()]
    heard = [f.result() for f in list(results) if f.done()]
    known = [response for response in heard if response.status != GoalStatus.STATUS_UNKNOWN]
    return {'goals': count, 'goal responses heard': len(responses),
            'goals never answered': count - len(responses),
            'accepted': sum(1 for handle in responses if handle.accepted),
            'rejected (flood)': sum(1 for handle in responses if not handle.accepted),
            'results heard': len(heard), 'results never heard': len(results) - len(heard),
            'results for goals the server no longer knew (status UNKNOWN)': len(heard) - len(known),
            'statuses': Counter(GOAL_STATUS_NAMES.get(response.status, str(response.status))
                                for response in known),
            'codes': Counter(error_name(response.result.error_code.value) for response in known),
            'seconds': time.monotonic() - started}


def gui_simulation_flood(url: str, gui_pid: int, rss_kib, children, attempts: int = 40) -> dict:
    """40 simulations requested at once for one finished job; then a cross-site-style form POST."""
    def post(path, body, content_type='application/json'):
        request = urllib.request.Request(url + path, method='POST', data=body, headers={'Content-Type': content_type})
        try:
            with urllib.request.urlopen(request, timeout=60) as response:
                return response.status, dict(response.headers), json.load(response)
        except urllib.error.HTTPError as error:
            return error.code, {'Retry-After': error.headers.get('Retry-After')}, json.load(error)

    status, _, job = post('api/jobs', json.dumps(dict(zip(('system', 'initial_conditions', 'goals'), PAPER))).encode())
    while job['state'] != 'finished':
        time.sleep(0.2)
        with urllib.request.urlopen(f'{url}api/jobs/{job["id"]}', timeout=60) as response:
            job = json.load(response)
    def finish(simulation_id):
        while True:
            with urllib.request.urlopen(f'{url}api/simulations/{simulation_id}', timeout=60) as response:
                if json.load(response)['state'] == 'finished':
                    return
            time.sleep(0.5)

    def gui_alone(pid):
        return rss_kib(pid, with_children=False)

    # One run alone first (when simulations ran in the GUI process, MuJoCo and its renderer
    # loaded there on the first run); the GUI process alone, and with its simulation processes.
    before = gui_alone(gui_pid)
    def simulation_peak():  # a run's own peak: VmHWM, read until the process ends
        return simulation_processes_peak_kib(gui_pid, children)

    with peak_rss_growth(gui_pid, gui_alone) as first, peak_rss_growth(gui_pid, rss_kib) as first_all, \
            sampled_maximum(simulation_peak) as first_child:
        answer = post(f'api/jobs/{job["id"]}/simulations', b'{}')
        assert answer[0] == 202, (answer, job.get('outcome'))
        finish(answer[2]['id'])
    with peak_rss_growth(gui_pid, gui_alone) as rss, peak_rss_growth(gui_pid, rss_kib) as rss_all, \
            sampled_maximum(simulation_peak) as child:
        started = time.monotonic()
        with ThreadPoolExecutor(attempts) as pool:
            answers = list(pool.map(lambda _: post(f'api/jobs/{job["id"]}/simulations', b'{}'), range(attempts)))
        answered = time.monotonic() - started
        for simulation_id in [body['id'] for status, _, body in answers if status == 202]:
            finish(simulation_id)
        all_done = time.monotonic() - started
    form = post(f'api/jobs/{job["id"]}/simulations', b'x=1', 'application/x-www-form-urlencoded')[0]
    retry = sorted({headers.get('Retry-After') for status, headers, _ in answers if status == 429})
    return {'requests at once': attempts, 'statuses': Counter(status for status, _, _ in answers),
            'all answered after s': answered, 'Retry-After': ', '.join(map(str, retry)),
            'accepted runs finished after s': all_done,
            'GUI process RSS before MiB': before / 1024,
            'GUI process peak RSS growth, first run MiB': first['MiB'],
            'GUI process peak RSS growth, the 40 requests MiB': rss['MiB'],
            'with its simulation processes, first run MiB': first_all['MiB'],
            'with its simulation processes, the 40 requests MiB': rss_all['MiB'],
            'simulation process peak RSS, first run MiB': first_child['KiB'] / 1024,
            'simulation process peak RSS, the 40 requests (highest) MiB': child['KiB'] / 1024,
            'GUI process RSS after them MiB': gui_alone(gui_pid) / 1024,
            'form-encoded POST status': form}
