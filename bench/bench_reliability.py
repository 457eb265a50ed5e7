"""Reliability under load: bursts to ``serve`` and to the GUI, and a long soak with its RSS slope.

- burst: 50 goals sent at once to ``behavior-synthesis serve`` (10 compile-only "fast" goals
  among 40 whole pipelines); every goal must get an answer (a result or BUSY).
- gui: 20 jobs posted at once to ``behavior-synthesis gui``; every job must finish.
- soak: N goals (default 2,000) to ``serve``, ``--in-flight`` at a time, half whole
  pipelines and half compile-only; counts goals without a result and samples the RSS of the
  server with its synthesis child processes. The slope is fitted (least squares) over the
  samples after warm-up (the first ``--warmup`` goals, which also covers the server's 60 s
  result retention).

- attacks (issue 25, full sizes; small ones are in the tests): a 9-level YAML alias bomb
  in ``synthesis_options``, custom LTL nested 5,000 and 30,000 deep, negative/NaN and 3 s
  time limits in a burst behind slow syntheses, a plain rclpy client with the default depth-10
  queues sending 200 goals and then a 10,000-goal flood, and 40 GUI simulations at once. Each
  says what came back, how long after its limit, and the server's peak RSS growth; the
  simulations also the peak RSS of a simulation process itself (VmHWM).
- idle: the server's RSS (with its synthesis processes) after a burst and after they idled.
- service (issue 34, full sizes; reliability_service.py): 20 goals of 3.9 MB custom LTL with
  5 s limits (and one of 11 MB), a strategy of 8.4 M transitions, two BDD bombs in a row, a
  50 MB goal list, a 200-goal mixed burst with 1 s limits, each on a fresh ``serve``: what came
  back and when, the server's peak RSS, a normal goal's time right after, SIGTERM's time 2 s
  into it; ``kill -9`` of serve during a goal (when send-goal notices), gr1synth
  --memory-limit 200 on a 192 MB input, and a 100,000-deep body POSTed to the GUI.
- sharing (issue 48, full sizes; reliability_sharing.py): one client's eight runaways asking 1e9 s
  beside another client's goal, five refused 50 MB goals and what the server keeps 5 s later, a
  10^9-leaf alias bomb in a robot file, three BDD bombs at once against the sum limit, 1,100 idle
  connections to a GUI with 1,024 open files, `repair --time-budget 5` on a BDD bomb.

The server and GUI run as their real console entry points in separate processes on a
reserved ROS domain; the clients are in this process. Prints a table and writes the sections
run into bench/results/reliability.md (the others are kept).

    .venv/bin/python bench/bench_reliability.py [--sections burst,soak,gui,attacks,idle,service]
        [--goals 2000] [--in-flight 4] [--warmup 600] [--flood 10000]
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

RESULTS = Path(__file__).resolve().parent / 'results' / 'reliability.md'
BIN = Path(sys.executable).parent
TASK = ('atlas', ['stand_prep'], ['look_down', 'pickup_object'])
GUI_TASK = {'system': 'atlas', 'initial_conditions': ['stand_prep'], 'goals': ['look_down', 'pickup_object']}


def rss_kib(pid: int, with_children: bool = True) -> int:
    """Resident memory of ``pid`` and (``with_children``) its child processes (the synthesis
    processes, the GUI's simulations)."""
    total = 0
    for process in [pid, *(_children(pid) if with_children else [])]:
        try:
            status = Path(f'/proc/{process}/status').read_text()
        except OSError:  # ended meanwhile
            continue
        total += next((int(line.split()[1]) for line in status.splitlines() if line.startswith('VmRSS:')), 0)
    return total


def _children(pid: int) -> list[int]:
    """The child processes of every thread of ``pid`` (each thread's children are its own)."""
    children = []
    for task in Path(f'/proc/{pid}/task').glob('*'):
        try:
            children += [int(child) for child in (task / 'children').read_text().split()]
        except OSError:  # the thread ended meanwhile
            pass
    return children


def slope(points: list[tuple[float, float]]) -> float:
    """Least-squares slope of (x, y) points."""
    mean_x = statistics.fmean(x for x, _ in points)
    mean_y = statistics.fmean(y for _, y in points)
    spread = sum((x - mean_x) ** 2 for x, _ in points)
    return sum((x - mean_x) * (y - mean_y) for x, y in points) / spread if spread else 0.0


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(fraction * (len(ordered) - 1))))]


class Serve:
    """``behavior-synthesis serve`` in its own process on ``domain``."""

    def __init__(self, domain: int, byproducts: str):
        from synthesis_manager.ros.env import prepare_ros_environment

        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        self.process = subprocess.Popen([str(BIN / 'behavior-synthesis'), 'serve', '--byproducts-dir', byproducts],
                                        env=environment, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    def stop(self):
        self.process.send_signal(signal.SIGTERM)
        self.process.wait(timeout=30)


def timed_run(client, goal, timeout=300.0):
    started = time.monotonic()
    try:
        outcome = client.run(goal, timeout=timeout)
        return outcome.error_name, time.monotonic() - started
    except TimeoutError:
        return 'NO RESULT', time.monotonic() - started


def burst(client, count: int = 50) -> dict:
    from synthesis_manager.client import make_goal

    goals = [(i % 5 == 0, make_goal(*TASK, name=f'burst{i}',
                                    option='ltl_compilation_only' if i % 5 == 0 else None))
             for i in range(count)]
    started = time.monotonic()
    with ThreadPoolExecutor(count) as pool:
        answers = list(pool.map(lambda fast_goal: (fast_goal[0], *timed_run(client, fast_goal[1])), goals))
    return {'goals': count, 'codes': Counter(code for _, code, _ in answers),
            'all answered after s': time.monotonic() - started,
            'fast goals, slowest s': max(seconds for fast, _, seconds in answers if fast),
            'pipelines, median s': statistics.median(seconds for fast, _, seconds in answers if not fast)}


@contextlib.contextmanager
def gui_process(domain: int, byproducts: str):
    """``behavior-synthesis gui`` (with its suite) in its own process: yields (url, pid)."""
    from synthesis_manager.ros.env import prepare_ros_environment

    environment = prepare_ros_environment(domain, environ=dict(os.environ))
    process = subprocess.Popen([str(BIN / 'behavior-synthesis'), 'gui', '--port', '0',
                                '--byproducts-dir', byproducts], env=environment,
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        yield re.search(r'http://\S+?/', process.stdout.readline()).group(0), process.pid
    finally:
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)


def gui_burst(url: str, jobs: int = 20) -> dict:
    def post(index):
        request = urllib.request.Request(url + 'api/jobs', method='POST',
                                         data=json.dumps({**GUI_TASK, 'name': f'job{index}'}).encode(),
                                         headers={'Content-Type': 'application/json'})
        with urllib.request.urlopen(request, timeout=60) as response:
            return json.load(response)['id']

    def finish(job_id):
        deadline = time.monotonic() + 300
        while time.monotonic() < deadline:
            with urllib.request.urlopen(f'{url}api/jobs/{job_id}', timeout=60) as response:
                job = json.load(response)
            if job['state'] == 'finished':
                return job['outcome']['error_name']
            time.sleep(0.2)
        return 'UNFINISHED'

    started = time.monotonic()
    with ThreadPoolExecutor(jobs) as pool:
        codes = list(pool.map(finish, list(pool.map(post, range(jobs)))))
    return {'jobs': jobs, 'codes': Counter(codes), 'all finished after s': time.monotonic() - started}


def soak(client, server_pid: int, goals: int, in_flight: int, warmup: int) -> dict:
    from synthesis_manager.client import make_goal

    codes: Counter = Counter()
    samples = []  # (goals answered, seconds since start, RSS KiB)
    lock = threading.Lock()
    answered = 0
    started_wall, started_cpu = time.monotonic(), time.process_time()

    def one(index):
        nonlocal answered
        option = 'ltl_compilation_only' if index % 2 else None
        code, _ = timed_run(client, make_goal(*TASK, name=f'soak{index % 500}', option=option))
        with lock:
            codes[code] += 1
            answered += 1
            if answered % 50 == 0:
                samples.append((answered, time.monotonic() - started_wall, rss_kib(server_pid)))
                print(f'  {answered} goals, server RSS (with its synthesis processes) {samples[-1][2] / 1024:.1f} MiB', flush=True)

    with ThreadPoolExecutor(in_flight) as pool:
        list(pool.map(one, range(goals)))
    after_warmup = [sample for sample in samples if sample[0] > warmup] or samples
    return {'goals': goals, 'in flight': in_flight, 'codes': codes,
            'goals without a result': codes['NO RESULT'],
            'wall s': time.monotonic() - started_wall, 'client CPU s': time.process_time() - started_cpu,
            'RSS after warm-up MiB': after_warmup[0][2] / 1024, 'RSS at end MiB': samples[-1][2] / 1024,
            'RSS slope KiB per goal': slope([(n, rss) for n, _, rss in after_warmup]),
            'RSS slope KiB per minute': 60 * slope([(t, rss) for _, t, rss in after_warmup])}


def idle_release(client, server_pid: int, idle_seconds: float = 35.0) -> dict:
    """The server's RSS with its synthesis processes before a burst, after it, and after idling."""
    from synthesis_manager.client import make_goal

    before = rss_kib(server_pid)
    with ThreadPoolExecutor(8) as pool:
        list(pool.map(lambda i: timed_run(client, make_goal(*TASK, name=f'idle{i}')), range(64)))
    after = rss_kib(server_pid)
    time.sleep(idle_seconds)
    return {'RSS before the burst MiB': before / 1024, 'RSS after 64 goals, 8 at once MiB': after / 1024,
            f'RSS after {idle_seconds:g} s idle MiB': rss_kib(server_pid) / 1024}


SECTIONS = ('burst', 'soak', 'gui', 'attacks', 'idle', 'service', 'sharing')
#: The parts of 'attacks', each also selectable alone.
ATTACKS = ('hostile', 'limits', 'qos', 'simulations')


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--sections', default=','.join(SECTIONS),
                        help=f'comma-separated subset of {SECTIONS} (attacks: all of {ATTACKS}, each selectable)')
    parser.add_argument('--goals', type=int, default=2000, help='goals in the soak')
    parser.add_argument('--in-flight', type=int, default=4, help='soak goals in progress at once')
    parser.add_argument('--warmup', type=int, default=600, help='soak goals before the RSS slope counts')
    parser.add_argument('--flood', type=int, default=10_000, help='goals of the default-QoS flood')
    parser.add_argument('--service-attacks', default='',
                        help="with --sections service: only the attacks whose titles contain one of these "
                             "comma-separated words (e.g. 'burst,bombs'; 'kill', 'gr1synth', 'deep' for the others)")
    parser.add_argument('--sharing-attacks', default='',
                        help="with --sections sharing: only the attacks whose titles contain one of these words "
                             "(e.g. 'runaways,GUI,repair')")
    args = parser.parse_args(argv)
    sections = args.sections.split(',')
    if 'attacks' in sections:
        sections += ATTACKS

    from rclpy.node import Node

    import reliability_attacks as attacks
    from synthesis_manager.client import SynthesisClient, make_goal
    from synthesis_manager.ros.harness import RosHarness, reserve_domain_id

    report = {}
    if 'service' in sections:
        import reliability_service as service
        words = [word for word in args.service_attacks.split(',') if word]

        def chosen(title: str) -> bool:
            return not words or any(word in title for word in words)
        with reserve_domain_id() as domain:
            only = [title for title in service.SERVE_ATTACKS if chosen(title)]
            if only:
                report.update({f'service: {title}': figures
                               for title, figures in service.serve_attacks(domain, rss_kib, Serve, only).items()})
            if chosen('kill -9 of serve during a goal'):
                print('service: kill -9 of serve during a goal', flush=True)
                report['service: kill -9 of serve during a goal'] = service.killed_server(domain, Serve)
        if chosen('gr1synth --memory-limit'):
            print('service: gr1synth on a large input', flush=True)
            report['service: gr1synth --memory-limit'] = service.gr1synth_large_input()
        if chosen('GUI, 100,000-deep body'):
            with reserve_domain_id() as domain, tempfile.TemporaryDirectory(prefix='bench-gui-') as byproducts, \
                    gui_process(domain, byproducts) as (url, gui_pid):
                print('service: a 100,000-deep body to the GUI', flush=True)
                report['service: GUI, 100,000-deep body'] = service.gui_deep_body(url, gui_pid, rss_kib)
    if 'sharing' in sections:
        import reliability_sharing as sharing
        words = [word for word in args.sharing_attacks.split(',') if word]
        titles = [*sharing.SHARING_ATTACKS, 'repair --time-budget 5 on a BDD bomb']
        only = [title for title in titles if not words or any(word in title for word in words)]
        with reserve_domain_id() as domain:
            report.update({f'sharing: {title}': figures
                           for title, figures in sharing.sharing_attacks(domain, rss_kib, only).items()})
    on_serve = set(sections) & {'idle', 'burst', 'soak', 'hostile', 'limits', 'qos'}
    with tempfile.TemporaryDirectory(prefix='bench-reliability-') as byproducts:
        if on_serve:  # the sections on one shared serve
            with reserve_domain_id() as domain:
                serve = Serve(domain, byproducts)
                try:
                    with RosHarness(domain_id=domain) as ros:
                        client = SynthesisClient(ros.add_node(Node, 'bench_reliability_client'))
                        assert client.wait_for_server(timeout=60.0), 'serve did not come up'
                        for _ in range(3):  # warm-up: imports, discovery
                            timed_run(client, make_goal(*TASK))
                        if 'idle' in sections:
                            print('idle: RSS after a burst and after idling', flush=True)
                            report['idle synthesis processes'] = idle_release(client, serve.process.pid)
                        if 'burst' in sections:
                            print('burst: 50 goals at once to serve', flush=True)
                            report['burst'] = burst(client)
                        if 'hostile' in sections:
                            print('attacks: hostile goals', flush=True)
                            flexbe_client = SynthesisClient(ros.add_node(Node, 'bench_flexbe_client'),
                                                            'flexbe_synthesis')
                            assert flexbe_client.wait_for_server(timeout=60.0)
                            report['hostile goals'] = attacks.hostile_goals(client, flexbe_client,
                                                                            serve.process.pid, rss_kib)
                        if 'limits' in sections:
                            print('attacks: time limits under load', flush=True)
                            runaway = make_goal('atlas', [], [], option='ltl_synthesis_only', timeout=30.0,
                                                ltl_specification={'sys_props': [f'p{i}' for i in range(200)],
                                                                   'env_props': ['e'], 'sys_liveness': ['p0']})
                            report['time limits under load'] = attacks.limits_under_load(client, runaway)
                        if 'qos' in sections:
                            print('attacks: default-QoS clients', flush=True)
                            plain = attacks.plain_client(ros.add_node(Node, 'bench_default_qos_client'))
                            report['default-QoS client, 200 goals'] = attacks.plain_client_burst(plain, 200)
                            report[f'default-QoS client, {args.flood} goals'] = attacks.plain_client_burst(
                                plain, args.flood)
                            deep = attacks.plain_client(ros.add_node(Node, 'bench_deep_qos_client'), deep_queues=True)
                            report[f'client with deep queues, {args.flood} goals'] = attacks.plain_client_burst(
                                deep, args.flood)
                        if 'soak' in sections:
                            print(f'soak: {args.goals} goals, {args.in_flight} in flight', flush=True)
                            report['soak'] = soak(client, serve.process.pid, args.goals, args.in_flight, args.warmup)
                finally:
                    serve.stop()
        if 'gui' in sections or 'simulations' in sections:
            with reserve_domain_id() as domain, gui_process(domain, byproducts) as (url, gui_pid):
                if 'gui' in sections:
                    print('gui: 20 jobs at once', flush=True)
                    report['gui'] = gui_burst(url)
                if 'simulations' in sections:
                    print('gui: 40 simulations at once', flush=True)
                    report['gui simulations at once'] = attacks.gui_simulation_flood(url, gui_pid, rss_kib, _children)

    kept = _sections(RESULTS.read_text()) if RESULTS.exists() else {}
    lines = ['# Reliability under load', '',
             'Measured by `bench/bench_reliability.py` (2-core machine shared with other work; '
             'wall-clock times are indicative only).', '']
    for section, text in kept.items():
        if section not in report:
            lines += text
    for section, figures in report.items():
        lines += [f'## {section}', '', '| figure | value |', '|---|---|']
        for name, value in figures.items():
            shown = (', '.join(f'{code} {count}' for code, count in sorted(value.items()))
                     if isinstance(value, Counter) else f'{value:.3f}' if isinstance(value, float) else str(value))
            lines.append(f'| {name} | {shown} |')
        lines.append('')
    text = '\n'.join(lines)
    print(text)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(text)
    return 0


def _sections(text: str) -> dict[str, list[str]]:
    """The ``## section`` blocks of an earlier results file, by title (kept when not rerun)."""
    sections, current = {}, None
    for line in text.splitlines():
        if line.startswith('## '):
            current = line[3:]
            sections[current] = []
        if current is not None:
            sections[current].append(line)
    return sections


if __name__ == '__main__':
    sys.exit(main())
