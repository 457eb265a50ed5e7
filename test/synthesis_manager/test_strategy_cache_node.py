"""The synthesis node's strategy cache (issue 36 item 2): a hit is byte-identical to a fresh
synthesis (response and byproduct files), a changed robot file never returns a stale answer,
identical requests at once are one synthesis (service calls and action goals), a restarted
node reads its directory, and answers that depend on time (a stop, a cut-short diagnosis) are
never kept."""

import json
import shutil
import threading
from pathlib import Path

import pytest
from rclpy.parameter import Parameter

from ltl_specification.compiler import compile_task
from ltl_specification.provenance import provenance_to_json
from respec.robot import robot_system
from ltl_synthesizer.service import SynthesisJob
from suite_settings import suite_args
from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.nodes.ltl_synthesis_node import LTLSynthesisNode
from synthesis_manager.ros.conversions import msg_to_sections, spec_to_msg
from synthesis_manager.ros.harness import RosHarness, wait_for
from synthesis_manager.suite import suite_node_factories
from synthesis_msgs.msg import LTLSpecification, SynthesisErrorCodes
from synthesis_msgs.srv import SynthesizeAutomaton

pytestmark = pytest.mark.ros

SHIPPED_CONFIG = Path(__file__).resolve().parents[2] / 'config'
REALIZABLE = (['stand_prep'], ['look_down'])
# Compiled, then found unrealizable by synthesis (test_diagnosis_channels.py).
UNREALIZABLE = (['stand_prep'], ['look_down', 'stand_prep'])
RUNAWAY_SPEC = {'sys_props': [f'p{i}' for i in range(200)], 'env_props': ['e'], 'sys_liveness': ['p0']}


def answer_of(response) -> str:
    """A response's every field, as text (a message's repr shows each field whole; its CDR bytes
    are no measure: alignment padding is left uninitialized, so equal messages may differ there)."""
    return repr(response)


def request_for(task, spec_name='task', config_dir=None, **fields):
    spec = compile_task(robot_system('atlas', config_dir), *task)
    return SynthesizeAutomaton.Request(ltl_specification=spec_to_msg(spec), spec_name=spec_name,
                                       provenance=provenance_to_json(spec.provenance), **fields)


class SynthesisService:
    """One synthesis node in its own namespace, with a client; its byproducts in its own folder."""

    def __init__(self, ros, tmp_path, namespace, **parameters):
        self.byproducts = tmp_path / f'{namespace}-byproducts'
        self.node = ros.add_node(LTLSynthesisNode, namespace=f'/{namespace}', parameter_overrides=[
            Parameter('byproducts_dir', value=str(self.byproducts)),
            *(Parameter(name, value=value) for name, value in parameters.items())])
        client_node = ros.add_node(__import__('rclpy.node').node.Node, f'{namespace}_client')
        self.client = client_node.create_client(SynthesizeAutomaton, f'/{namespace}/ltl_synthesis')
        assert self.client.wait_for_service(timeout_sec=10.0)

    def call(self, request, timeout=120.0):
        return wait_for(self.client.call_async(request), timeout)

    def byproduct(self, name):
        return (self.byproducts / name).read_bytes()

    @property
    def statistics(self):
        return self.node.strategy_cache.statistics


@pytest.fixture
def fresh_and_cached(ros, tmp_path):
    return (SynthesisService(ros, tmp_path, 'fresh', strategy_cache_mb=0.0),
            SynthesisService(ros, tmp_path, 'cached'))


def test_a_hit_is_byte_identical_to_a_fresh_synthesis(fresh_and_cached):
    fresh, cached = fresh_and_cached
    for task in (REALIZABLE, UNREALIZABLE):
        request = request_for(task)
        expected = answer_of(fresh.call(request))
        files = {extension: fresh.byproduct(f'task.{extension}') for extension in ('structuredslugs', 'slugsin')}
        if task is REALIZABLE:
            files['json'] = fresh.byproduct('task.json')  # the JSON automaton
        for attempt in ('computed', 'hit'):
            for path in cached.byproducts.glob('task.*'):
                path.unlink()  # each answer writes its byproducts again
            assert answer_of(cached.call(request)) == expected, attempt
            assert {extension: cached.byproduct(f'task.{extension}') for extension in files} == files
    assert cached.statistics.misses == 2 and cached.statistics.hits == 2
    assert fresh.node.strategy_cache.statistics.hits == 0


def test_an_unrealizable_answer_names_each_request_spec_name(fresh_and_cached):
    fresh, cached = fresh_and_cached
    cached.call(request_for(UNREALIZABLE, spec_name='first_robot'))
    response = cached.call(request_for(UNREALIZABLE, spec_name='second_robot'))
    assert cached.statistics.hits == 1
    assert response.error_code.value == SynthesisErrorCodes.SPEC_UNSYNTHESIZABLE
    assert "specification 'second_robot' is unrealizable" in response.error_code.message
    assert 'first_robot' not in response.error_code.message
    assert answer_of(response) == answer_of(fresh.call(request_for(UNREALIZABLE,
                                                                                   spec_name='second_robot')))


def test_a_changed_robot_file_never_returns_a_stale_answer(fresh_and_cached, tmp_path):
    fresh, cached = fresh_and_cached
    config = tmp_path / 'config'
    shutil.copytree(SHIPPED_CONFIG, config)
    atlas = config / 'atlas.yaml'

    def both(expect_hit):
        request = request_for(REALIZABLE, config_dir=config)
        hits = cached.statistics.hits
        answer = answer_of(cached.call(request))
        assert answer == answer_of(fresh.call(request))
        assert cached.statistics.hits == hits + expect_hit
        return answer

    original = both(expect_hit=False)
    # look_down now needs manipulate: another specification, another answer.
    atlas.write_text(atlas.read_text().replace('    look_down: [stand]\n', '    look_down: [manipulate]\n'))
    changed = both(expect_hit=False)
    assert changed != original
    # A comment changes neither the specification nor its provenance: the same answer.
    atlas.write_text(atlas.read_text() + '# edited\n')
    assert both(expect_hit=True) == changed
    # Back to the original file: the first answer again (its entry was kept).
    shutil.copy(SHIPPED_CONFIG / 'atlas.yaml', atlas)
    assert both(expect_hit=True) == original
    assert cached.statistics.misses == 2


def test_identical_service_calls_at_once_are_one_synthesis(fresh_and_cached):
    _, cached = fresh_and_cached
    request = request_for(REALIZABLE)
    futures = [cached.client.call_async(request) for _ in range(8)]
    answers = {answer_of(wait_for(future, 120.0)) for future in futures}
    assert len(answers) == 1
    assert cached.statistics.misses == 1 and cached.statistics.stored == 1
    assert cached.statistics.hits + cached.statistics.shared == 7


def test_identical_goals_at_once_are_one_synthesis(ros, tmp_path):
    from rclpy.node import Node

    for factory in suite_node_factories(suite_args(tmp_path)):
        ros.add_node(factory)
    synthesis = next(node for node in ros.nodes if isinstance(node, LTLSynthesisNode))
    client = SynthesisClient(ros.add_node(Node, 'fleet_client'))
    assert client.wait_for_server(timeout=10.0)
    outcomes = [None] * 6

    def run(index):
        outcomes[index] = client.run(make_goal('atlas', *REALIZABLE), timeout=120.0)

    threads = [threading.Thread(target=run, args=(index,)) for index in range(len(outcomes))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(150)
    assert all(outcome.error_code == SynthesisErrorCodes.SUCCESS for outcome in outcomes), outcomes
    assert len({json.dumps(outcome.states, sort_keys=True) for outcome in outcomes}) == 1
    assert synthesis.strategy_cache.statistics.misses == 1
    assert synthesis.strategy_cache.statistics.hits + synthesis.strategy_cache.statistics.shared == 5


def test_a_restarted_node_answers_from_its_directory(tmp_path):
    cache_dir = tmp_path / 'strategy-cache'
    answers, statistics = [], []
    for run in ('first', 'restarted', 'corrupted'):
        if run == 'corrupted':  # half the file: a miss, synthesized again, never a crash
            [kept] = cache_dir.iterdir()
            kept.write_bytes(kept.read_bytes()[:kept.stat().st_size // 2])
        with RosHarness() as ros:
            service = SynthesisService(ros, tmp_path, run, strategy_cache_dir=str(cache_dir))
            answers.append(answer_of(service.call(request_for(REALIZABLE))))
            statistics.append(service.statistics)
    assert answers[0] == answers[1] == answers[2]
    assert statistics[1].misses == 0 and statistics[1].disk_hits == 1
    assert statistics[2].misses == 1 and statistics[2].corrupt == 1 and statistics[2].stored == 1
    assert [path.suffix for path in cache_dir.iterdir()] == ['.entry']


def test_stopped_syntheses_and_cut_short_diagnoses_are_not_kept(fresh_and_cached):
    fresh, cached = fresh_and_cached
    runaway = SynthesizeAutomaton.Request(ltl_specification=LTLSpecification(**RUNAWAY_SPEC), timeout=0.5)
    for _ in range(2):  # the second is synthesized again, and stopped again
        assert cached.call(runaway).error_code.value == SynthesisErrorCodes.SYNTHESIS_TIMEOUT
    assert cached.statistics.misses == 2 and cached.statistics.stored == 0
    # No time to diagnose: the verdict without its diagnosis is answered, not kept.
    hurried = cached.call(request_for(UNREALIZABLE, diagnosis_timeout=0.001))
    assert hurried.error_code.value == SynthesisErrorCodes.SPEC_UNSYNTHESIZABLE
    assert cached.statistics.stored == 0
    whole = cached.call(request_for(UNREALIZABLE))
    assert whole.error_code.message != hurried.error_code.message
    assert cached.statistics.stored == 1
    assert answer_of(whole) == answer_of(fresh.call(request_for(UNREALIZABLE)))


def test_an_unsafe_directory_leaves_the_cache_in_memory(ros, tmp_path):
    shared = tmp_path / 'shared'
    shared.mkdir()
    shared.chmod(0o777)
    service = SynthesisService(ros, tmp_path, 'unsafe', strategy_cache_dir=str(shared))
    assert service.node.strategy_cache.directory is None and service.node.strategy_cache.enabled
    request = request_for(REALIZABLE)
    assert answer_of(service.call(request)) == answer_of(service.call(request))
    assert service.statistics.hits == 1 and list(shared.iterdir()) == []


def test_serve_options_set_the_cache(ros, tmp_path):
    import argparse

    from synthesis_manager.suite import add_suite_arguments

    parser = argparse.ArgumentParser()
    add_suite_arguments(parser)
    args = parser.parse_args(['--byproducts-dir', str(tmp_path / 'byproducts'), '--strategy-cache-mb', '0.5',
                              '--strategy-cache-dir', str(tmp_path / 'kept')])
    node = ros.add_node(suite_node_factories(args, ['ltl_synthesis'])[0])
    assert node.strategy_cache.max_bytes == 2**19 and node.strategy_cache.directory == tmp_path / 'kept'
    off = parser.parse_args(['--strategy-cache-mb', '0'])
    assert not ros.add_node(suite_node_factories(off, ['ltl_synthesis'])[0],
                            namespace='/off').strategy_cache.enabled


def test_an_option_that_changes_the_answer_is_another_key(fresh_and_cached):
    fresh, cached = fresh_and_cached
    request = request_for(REALIZABLE)
    cached.call(request)
    for name, value in (('robotics_semantics', False), ('check_well_separation', False),
                        ('max_strategy_edges', 5000)):
        for service in (fresh, cached):
            service.node.set_parameters([Parameter(name, value=value)])
        misses = cached.statistics.misses
        assert answer_of(cached.call(request)) == answer_of(fresh.call(request))
        assert cached.statistics.misses == misses + 1, name
    # Limits are not part of the key: a longer time limit is the same answer.
    request.timeout = 30.0
    assert answer_of(cached.call(request)) == answer_of(fresh.call(request))
    assert cached.statistics.misses == 4


def test_a_large_specification_is_kept_too(fresh_and_cached):
    from ltl_synthesizer.service import LARGE_SPEC_BYTES

    fresh, cached = fresh_and_cached
    tautology = ' & '.join(['(p0 | !p0)'] * 100)
    formulas = [tautology] * (LARGE_SPEC_BYTES // len(tautology) + 1)
    request = SynthesizeAutomaton.Request(ltl_specification=LTLSpecification(
        sys_props=['p0'], env_props=['e'], sys_trans=formulas, sys_liveness=['p0']), spec_name='large')
    expected = answer_of(fresh.call(request))
    assert answer_of(cached.call(request)) == expected  # parsed in a synthesis process, kept
    assert answer_of(cached.call(request)) == expected  # its key computed in a worker: a hit
    assert cached.statistics.misses == 1 and cached.statistics.hits == 1
    assert cached.byproduct('large.slugsin') == fresh.byproduct('large.slugsin')


def test_an_entry_signed_with_a_stolen_key_but_not_a_winning_strategy_is_not_served(tmp_path):
    """Issue 48, item 6: a loaded strategy is checked against its specification before it is
    served; whoever holds the key can sign anything, but a strategy whose moves break the
    specification is a miss, synthesized again."""
    from ltl_synthesizer.cache import StrategyCache

    cache_dir = tmp_path / 'strategy-cache'
    request = request_for(REALIZABLE)
    with RosHarness() as ros:
        service = SynthesisService(ros, tmp_path, 'first', strategy_cache_dir=str(cache_dir))
        honest = answer_of(service.call(request))
        key = service.node.service.cache_key(SynthesisJob(msg_to_sections(request.ltl_specification),
                                                          request.spec_name, 60.0, 0.0, request.provenance))
    thief = StrategyCache(directory=cache_dir)  # the key file beside the directory: the thief has it
    entry = dict(thief.get(key))
    strategy = json.loads(entry['json'])
    first = next(iter(strategy['nodes']))
    strategy['nodes'][first]['trans'] = [list(strategy['nodes'])[-1]]  # a move the specification forbids
    entry['json'] = json.dumps(strategy).encode()
    thief.put(key, entry)
    with RosHarness() as ros:
        service = SynthesisService(ros, tmp_path, 'restarted', strategy_cache_dir=str(cache_dir))
        assert answer_of(service.call(request)) == honest
        statistics = service.statistics
    assert statistics.rejected == 1 and statistics.disk_hits == 0 and statistics.misses == 1
