"""The strategy cache (issue 36 item 2): what a hit costs and how often a fleet hits.

Measures, for ATLAS tasks and for a synthetic specification whose strategy has thousands of
transitions (free inputs copied to outputs):

- at the node: a hit's work in the synthesis node (key, lookup, byproduct files, response);
- through the SynthesizeAutomaton service: a hit's round trip, against a fresh synthesis
  (the node with strategy_cache_mb 0), and a restarted node's first answer (from its directory);
- through the /behavior_synthesis action (the suite in one process): a goal answered with the
  cache against one without (compilation and state-machine generation run either way);
- a fleet: ROBOTS robots asking, round after round, for one of a few tasks at once (goals sent
  together): the hit rate and how many syntheses ran.

Prints tables and writes bench/results/strategy_cache.md.

    .venv/bin/python bench/bench_strategy_cache.py [--calls 50] [--rounds 5] [--robots 4]
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import threading
import time
from argparse import Namespace
from pathlib import Path
from respec.robot import robot_system

TASKS = {
    'stand_prep -> [look_down]': (['stand_prep'], ['look_down']),
    'stand_prep -> [pregrasp, pickup_object, footstep_execution, look_down]':
        (['stand_prep'], ['pregrasp', 'pickup_object', 'footstep_execution', 'look_down']),
}
#: Free inputs of the synthetic specification (5: about 20 000 transitions; 6 would be over the
#: node's max_strategy_edges).
COPIED_INPUTS = 5
FLEET_TASKS = (['look_down'], ['pickup_object'], ['footstep_execution'])
RESULTS = Path(__file__).resolve().parent / 'results' / 'strategy_cache.md'
TARGET_MS = 10.0


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(fraction * (len(ordered) - 1))))]


def milliseconds(values) -> str:
    return f'{statistics.median(values) * 1000:.2f} | {percentile(values, 0.95) * 1000:.2f}'


def copying_spec(inputs: int):
    """A realizable specification whose strategy grows as 4**inputs (every input is free, and
    each output copies its input)."""
    from respec.parsing import spec_from_text_sections

    return spec_from_text_sections({
        'env_props': [f'x{i}' for i in range(inputs)], 'sys_props': [f'y{i}' for i in range(inputs)],
        'sys_trans': [f'next(y{i}) <-> next(x{i})' for i in range(inputs)], 'sys_liveness': ['y0 | !y0']})


def requests() -> dict:
    from ltl_specification.compiler import compile_task
    from ltl_specification.provenance import provenance_to_json
    from synthesis_manager.ros.conversions import spec_to_msg
    from synthesis_msgs.srv import SynthesizeAutomaton

    made = {}
    for label, (initial, goals) in TASKS.items():
        spec = compile_task(robot_system('atlas'), initial, goals)
        made[label] = SynthesizeAutomaton.Request(ltl_specification=spec_to_msg(spec), spec_name='bench',
                                                  provenance=provenance_to_json(spec.provenance))
    made[f'{COPIED_INPUTS} free inputs copied to outputs'] = SynthesizeAutomaton.Request(
        ltl_specification=spec_to_msg(copying_spec(COPIED_INPUTS)), spec_name='bench')
    return made


class Service:
    def __init__(self, ros, directory: Path, name: str, **parameters):
        from rclpy.node import Node
        from rclpy.parameter import Parameter

        from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
        from synthesis_msgs.srv import SynthesizeAutomaton

        self.node = ros.add_node(LTLSynthesisNode, namespace=f'/{name}', parameter_overrides=[
            Parameter('byproducts_dir', value=str(directory / f'{name}-byproducts')),
            *(Parameter(key, value=value) for key, value in parameters.items())])
        self.client = ros.add_node(Node, f'{name}_bench_client').create_client(
            SynthesizeAutomaton, f'/{name}/ltl_synthesis')
        assert self.client.wait_for_service(timeout_sec=30.0)

    def timed_call(self, request) -> float:
        return self.call(request)[0]

    def call(self, request):
        """(seconds, response) of one call."""
        from synthesis_manager.ros.harness import wait_for

        started = time.perf_counter()
        response = wait_for(self.client.call_async(request), 120.0)
        elapsed = time.perf_counter() - started
        assert response.error_code.value == 1, response.error_code.message
        return elapsed, response


def job_of(request):
    """The synthesis service's job of a SynthesizeAutomaton request, as the node makes it."""
    from ltl_synthesizer.service import SynthesisJob
    from synthesis_manager.ros.conversions import msg_to_sections

    return SynthesisJob(msg_to_sections(request.ltl_specification), request.spec_name, 60.0,
                        time.monotonic() + 60.0, request.provenance, request.diagnosis_timeout)


def at_the_node(node, request, calls: int) -> list[float]:
    """A hit's work in the node, as on_request does it (no ROS transport)."""
    from synthesis_manager.ros.conversions import automaton_to_msg

    latencies = []
    for _ in range(calls):
        started = time.perf_counter()
        answer, _ = node.service.cached_answer(job_of(request))
        automaton_to_msg(answer.automaton)
        latencies.append(time.perf_counter() - started)
    return latencies


def hit_parts(node, request, calls: int) -> str:
    """Medians (ms) of a hit's three parts: the key, the automaton message, the byproduct files."""
    from ltl_synthesizer.service import KeptAnswer
    from synthesis_manager.byproducts import EXTENSIONS
    from synthesis_manager.ros.conversions import automaton_to_msg

    job = job_of(request)
    entry = node.strategy_cache.get(node.service.cache_key(job))

    def write_files():
        with node.byproduct_store().open_set(request.spec_name) as files:
            for extension in EXTENSIONS:
                if extension in entry:
                    files.write(extension, entry[extension].decode())

    parts = (lambda: node.service.cache_key(job), lambda: automaton_to_msg(KeptAnswer.from_entry(entry).automaton),
             write_files)
    medians = []
    for part in parts:
        latencies = []
        for _ in range(calls):
            started = time.perf_counter()
            part()
            latencies.append(time.perf_counter() - started)
        medians.append(f'{statistics.median(latencies) * 1000:.2f}')
    return ' | '.join(medians)


def service_rows(calls: int, directory: Path) -> list[str]:
    from synthesis_manager.ros.harness import RosHarness

    rows = []
    cache_dir = directory / 'strategy-cache'
    made = requests()
    with RosHarness() as ros:
        fresh = Service(ros, directory, 'fresh', strategy_cache_mb=0.0)
        cached = Service(ros, directory, 'cached', strategy_cache_dir=str(cache_dir))
        size_before = 0
        for label, request in made.items():
            fresh_times = [fresh.timed_call(request) for _ in range(max(3, calls // 10))]
            first, response = cached.call(request)  # the miss: synthesized and kept
            transitions = sum(len(state.transitions) for state in response.automaton.automaton)
            hits = [cached.timed_call(request) for _ in range(calls)]
            node = at_the_node(cached.node, request, calls)
            size = cached.node.strategy_cache.memory_bytes - size_before
            size_before += size
            rows.append(f'| {label} | {transitions} | {milliseconds(fresh_times)} | {first * 1000:.1f} | '
                        f'{milliseconds(hits)} | {milliseconds(node)} | {hit_parts(cached.node, request, calls)} | '
                        f'{size / 1024:.0f} |')
    with RosHarness() as ros:  # a restarted node: each task's first answer comes from the directory
        restarted = Service(ros, directory, 'restarted', strategy_cache_dir=str(cache_dir))
        disk = [f'{at_the_node(restarted.node, request, 1)[0] * 1000:.1f}' for request in made.values()]
        assert restarted.node.strategy_cache.statistics.disk_hits == len(made)
    return rows, disk


def action_rows(calls: int, directory: Path) -> list[str]:
    from synthesis_manager.client import make_goal
    from synthesis_manager.suite import in_process_suite

    rows = []
    for label, megabytes in (('without cache', 0.0), ('with cache', None)):
        args = Namespace(config_dir='', byproducts_dir=str(directory / 'action-byproducts'), backend='builtin',
                         slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=5.0,
                         strategy_cache_mb=megabytes)
        with in_process_suite(args, 'bench_action_client') as (_, client):
            for task, (initial, goals) in TASKS.items():
                goal = make_goal('atlas', initial, goals)
                assert client.run(goal).succeeded  # warm-up (and, with the cache, the miss)
                latencies = []
                for _ in range(calls):
                    started = time.perf_counter()
                    outcome = client.run(goal)
                    latencies.append(time.perf_counter() - started)
                    assert outcome.succeeded, outcome.message
                rows.append(f'| {label} | {task} | {milliseconds(latencies)} |')
    return rows


def fleet(robots: int, rounds: int, directory: Path) -> dict:
    """``robots`` goals at once per round, robot r asking FLEET_TASKS[(r + round) % 3]."""
    from synthesis_manager.client import make_goal
    from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
    from synthesis_manager.suite import in_process_suite

    args = Namespace(config_dir='', byproducts_dir=str(directory / 'fleet-byproducts'), backend='builtin',
                     slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=5.0)
    latencies = []
    with in_process_suite(args, 'bench_fleet_client') as (ros, client):
        synthesis = next(node for node in ros.nodes if isinstance(node, LTLSynthesisNode))
        for round_ in range(rounds):
            outcomes = [None] * robots

            def ask(robot):
                goals = FLEET_TASKS[(robot + round_) % len(FLEET_TASKS)]
                started = time.perf_counter()
                outcomes[robot] = client.run(make_goal('atlas', ['stand_prep'], goals), timeout=120.0)
                latencies.append(time.perf_counter() - started)

            threads = [threading.Thread(target=ask, args=(robot,)) for robot in range(robots)]
            for thread in threads:
                thread.start()
            for thread in threads:
                thread.join()
            assert all(outcome.succeeded for outcome in outcomes), [o.message for o in outcomes]
        figures = synthesis.strategy_cache.statistics
    asked = robots * rounds
    return {'goals': asked, 'syntheses': figures.misses, 'hits': figures.hits, 'shared': figures.shared,
            'hit rate': (asked - figures.misses) / asked, 'latency': latencies}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--calls', type=int, default=50, help='hits measured per task')
    parser.add_argument('--rounds', type=int, default=5, help='rounds of the fleet')
    parser.add_argument('--robots', type=int, default=4, help='robots of the fleet (goals per round)')
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as temporary:
        directory = Path(temporary)
        service, disk = service_rows(args.calls, directory)
        action = action_rows(max(5, args.calls // 5), directory)
        fleet_figures = fleet(args.robots, args.rounds, directory)
    service_table = '\n'.join([
        '| request | transitions | fresh synthesis: median | p95 ms | first (miss) ms | hit via service: median | '
        'p95 ms | hit at the node: median | p95 ms | of which key | automaton message | '
        'byproduct files (medians, ms) | entry KiB |', '|---|---|---|---|---|---|---|---|---|---|---|---|---|',
        *service])
    disk_line = ('A restarted node (same `strategy_cache_dir`) answered each request\'s first call from '
                 f'its directory in {", ".join(disk)} ms at the node (same order; read, checked, kept in memory, '
                 'answered).')
    action_table = '\n'.join(['| suite | task | goal median | p95 ms |', '|---|---|---|---|', *action])
    fleet_line = (f'{args.robots} robots x {args.rounds} rounds, goals of a round sent at once, '
                  f'{len(FLEET_TASKS)} distinct tasks: {fleet_figures["goals"]} goals, '
                  f'{fleet_figures["syntheses"]} syntheses, {fleet_figures["hits"]} hits and '
                  f'{fleet_figures["shared"]} answers shared with a synthesis running at the same time: '
                  f'hit rate {fleet_figures["hit rate"]:.0%}; goal latency median | p95 '
                  f'{milliseconds(fleet_figures["latency"])} ms.')
    report = (f'# Strategy cache: hit latency and a fleet\'s hit rate\n\n'
              f'`bench/bench_strategy_cache.py --calls {args.calls} --rounds {args.rounds} --robots {args.robots}`. '
              f'Machine: {os.cpu_count()} cores, shared with other jobs while measured. Target: a hit under '
              f'{TARGET_MS:g} ms at the node.\n\n'
              f'## SynthesizeAutomaton (one node, strategy_cache_mb 64, a cache directory)\n\n{service_table}\n\n'
              f'{disk_line}\n\n## /behavior_synthesis goals (suite in one process)\n\n{action_table}\n\n'
              f'## A fleet\n\n{fleet_line}\n')
    print(report)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text(report)
    return 0


if __name__ == '__main__':
    sys.exit(main())
