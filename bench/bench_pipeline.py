"""End-to-end goal -> result latency of /behavior_synthesis (median and p95 over N goals).

Measures the paper's two tasks with all four nodes in one process, and with each node in
its own process (the client is always in this process). Prints a table and writes
bench/results/pipeline_latency.md.

    .venv/bin/python bench/bench_pipeline.py [--goals 50]
"""

from __future__ import annotations

import argparse
import os
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from argparse import Namespace
from pathlib import Path

TASKS = {
    'stand_prep -> [look_down, pickup_object]': ('atlas', ['stand_prep'], ['look_down', 'pickup_object']),
    'manipulate -> [footstep_execution]': ('atlas', ['manipulate'], ['footstep_execution']),
}
NODE_SCRIPTS = ('ltl-compilation-node', 'ltl-synthesis-node', 'sm-generation-node',
                'behavior-synthesis-server')
RESULTS = Path(__file__).resolve().parent / 'results' / 'pipeline_latency.md'


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(fraction * (len(ordered) - 1))))]


def measure(client, goals: int) -> dict:
    from synthesis_manager.client import make_goal

    figures = {}
    for label, (system, initial, goal_names) in TASKS.items():
        goal = make_goal(system, initial, goal_names)
        for _ in range(3):  # warm-up: imports, discovery, caches
            assert client.run(goal).succeeded
        latencies = []
        for _ in range(goals):
            started = time.perf_counter()
            outcome = client.run(goal)
            latencies.append(time.perf_counter() - started)
            assert outcome.succeeded, outcome.message
        figures[label] = (statistics.median(latencies), percentile(latencies, 0.95))
    return figures


def one_process(goals: int, byproducts: str) -> dict:
    from synthesis_manager.suite import in_process_suite

    args = Namespace(config_dir='', byproducts_dir=byproducts, backend='builtin', slugs_executable='slugs',
                     synthesis_timeout=60.0, service_timeout=5.0)
    with in_process_suite(args, 'bench_client') as (_, client):
        return measure(client, goals)


def four_processes(goals: int, byproducts: str) -> dict:
    from synthesis_manager.ros.harness import reserve_domain_id
    from rclpy.node import Node

    from synthesis_manager.client import SynthesisClient
    from synthesis_manager.ros.harness import RosHarness
    from synthesis_manager.ros.env import prepare_ros_environment

    bin_dir = Path(sys.executable).parent
    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        commands = [[str(bin_dir / script)] for script in NODE_SCRIPTS]
        commands[1] += ['--ros-args', '-p', f'byproducts_dir:={byproducts}']
        processes = [subprocess.Popen(c, env=environment, stdout=subprocess.DEVNULL) for c in commands]
        try:
            with RosHarness(domain_id=domain) as ros:
                client = SynthesisClient(ros.add_node(Node, 'bench_client'))
                assert client.wait_for_server(30.0)
                return measure(client, goals)
        finally:
            for process in processes:
                process.send_signal(signal.SIGTERM)
                process.wait(20)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--goals', type=int, default=50)
    args = parser.parse_args(argv)
    rows = []
    with tempfile.TemporaryDirectory() as byproducts:
        for deployment, run in (('1 process', one_process), ('4 processes', four_processes)):
            for task, (median, p95) in run(args.goals, byproducts).items():
                rows.append(f'| {deployment} | {task} | {median * 1000:.1f} | {p95 * 1000:.1f} |')
    table = '\n'.join(['| deployment | task | median ms | p95 ms |', '|---|---|---|---|', *rows])
    print(table)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(f'# End-to-end latency over {args.goals} goals per task\n\n'
                       f'Machine: {os.cpu_count()} cores. Targets: median < 150 ms in one process, '
                       f'< 300 ms across processes.\n\n{table}\n')
    return 0


if __name__ == '__main__':
    sys.exit(main())
