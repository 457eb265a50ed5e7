"""ltl_synthesizer on small hand-made GR(1) games: fixpoints, both initial-state semantics,
next-step livenesses, strategies checked by walking their JSON, counter-strategies,
explanations, determinism and cancellation."""

import threading
import time

import networkx as nx
import pytest

import gr1_oracle

from counterstrategies import synthesize_with_counterstrategy
from ltl_synthesizer import Limits, Options, SynthesisCancelledError, synthesize
from respec.automaton import automaton_from_strategy
from ltl_synthesizer.strategy import strategy_to_json
from respec.ltl import (TRUE, conj, disj, evaluate, iff,
                        implies, neg, next_, var)
from respec.spec import GR1Specification
from respec.robot import robot_system

x, y, r, g = var('x'), var('y'), var('r'), var('g')


# --- explicit checks ---------------------------------------------------------------------

# The product's evaluator: formulas on a (current, next) valuation pair.
holds = evaluate


def check_strategy(spec: GR1Specification, strategy: dict, robotics_semantics: bool) -> None:
    """Assert that the JSON strategy is winning, by the independent checker of test/gr1_oracle.py:
    initial coverage, env moves answered, safety on every edge, no fair cycle missing a goal."""
    assert strategy['variables'] == spec.env_props + spec.sys_props
    assert gr1_oracle.check_strategy(spec, strategy, robotics_semantics) == []


def spec(**sections) -> GR1Specification:
    return GR1Specification(**sections)


# --- tiny games -----------------------------------------------------------------------------

def copy_game():
    """The system copies the input; goal: y infinitely often; assumption: x infinitely often."""
    return spec(env_props=['x'], sys_props=['y'], env_init=[neg(x)], sys_init=[neg(y)],
                sys_trans=[iff(next_(y), next_(x))], env_liveness=[x], sys_liveness=[y])


@pytest.mark.parametrize('robotics_semantics', [True, False])
def test_copy_game_is_realizable_with_a_checked_strategy(robotics_semantics):
    game = copy_game()
    result = synthesize(game, robotics_semantics=robotics_semantics)
    assert result.realizable and result.explanation == ''
    check_strategy(game, result.strategy, robotics_semantics)
    assert [n['state'] for n in result.strategy['nodes'].values()] == [[0, 0], [1, 1]]


def test_copy_game_without_the_assumption_is_unrealizable():
    game = copy_game()
    game.env_liveness = []
    assert not synthesize(game).realizable


def test_next_step_system_liveness_is_a_set_of_transitions():
    # Goal "y falls": y & !next(y). The system can toggle y freely: realizable.
    toggling = spec(sys_props=['y'], sys_init=[neg(y)], sys_liveness=[conj([y, neg(next_(y))])])
    result = synthesize(toggling)
    assert result.realizable
    check_strategy(toggling, result.strategy, True)
    # Once y is set it must stay: it can never fall, so the goal is unreachable.
    sticky = spec(sys_props=['y'], sys_init=[neg(y)], sys_trans=[implies(y, next_(y))],
                  sys_liveness=[conj([y, neg(next_(y))])])
    assert not synthesize(sticky).realizable


def fairness_game(with_fairness: bool):
    """The paper's activation-outcome pattern: request r, outcome g, fairness (7)."""
    return spec(env_props=['g'], sys_props=['r'], env_init=[neg(g)], sys_init=[neg(r)],
                env_trans=[implies(conj([neg(r), neg(g)]), neg(next_(g)))],
                sys_trans=[implies(next_(g), neg(next_(r)))],
                env_liveness=[disj([conj([r, next_(g)]), neg(r)])] if with_fairness else [],
                sys_liveness=[g])


def test_next_step_environment_fairness_makes_a_task_realizable():
    fair = fairness_game(True)
    result = synthesize(fair)
    assert result.realizable
    check_strategy(fair, result.strategy, True)
    assert not synthesize(fairness_game(False)).realizable


def initial_choice_game():
    """The system must pick y equal to x at the start (sys_trans constrains the current step)."""
    return spec(env_props=['x'], sys_props=['y'], sys_trans=[iff(y, x), iff(next_(y), next_(x))],
                sys_liveness=[TRUE])


def test_initial_semantics_differ_as_in_slugs():
    game = initial_choice_game()
    standard = synthesize(game, robotics_semantics=False)
    assert standard.realizable
    check_strategy(game, standard.strategy, False)
    robotics = synthesize(game, robotics_semantics=True)
    assert not robotics.realizable
    assert 'initial state(s) allowed by ENV_INIT and SYS_INIT are losing' in robotics.explanation
    # The two losing initial states are x & !y and y & !x.
    assert '{x}' in robotics.explanation and '{y}' in robotics.explanation


def test_unrealizable_when_no_system_initial_value_fits():
    game = spec(env_props=['x'], sys_props=['y'], sys_init=[y], sys_trans=[iff(y, x)])
    result = synthesize(game, robotics_semantics=False)
    assert not result.realizable
    assert 'initial input valuation(s)' in result.explanation and '{}' in result.explanation


def test_unrealizable_only_in_the_outermost_fixpoint():
    # Two goals that the system can reach only by alternating, but each step needs the other
    # goal's region: y and !y with y frozen once x was seen. The environment sets x once.
    game = spec(env_props=['x'], sys_props=['y'], env_init=[neg(x)], sys_init=[neg(y)],
                env_trans=[implies(x, next_(x))],
                sys_trans=[implies(x, iff(next_(y), y))], sys_liveness=[y, neg(y)])
    result = synthesize_with_counterstrategy(game)
    assert not result.realizable


def test_blocked_goal_is_named_with_a_play():
    game = spec(env_props=['x'], sys_props=['y'], sys_liveness=[y, x])
    result = synthesize_with_counterstrategy(game)
    assert not result.realizable
    assert "system liveness #1 'x'" in result.explanation
    assert 'step 0: inputs {}' in result.explanation
    assert 'repeats step' in result.explanation


def test_deadlock_explanation_names_the_conflicting_safety_formulas():
    game = spec(env_props=['x'], sys_props=['y'], env_init=[neg(x)], sys_init=[neg(y)],
                sys_trans=[iff(next_(y), next_(x)), implies(y, next_(y)), neg(next_(y))],
                sys_liveness=[neg(y)])
    result = synthesize_with_counterstrategy(game)
    assert not result.realizable
    text = result.explanation
    assert 'System deadlock' in text and 'inputs to {x}' in text
    assert 'sys_trans #0: next(y) <-> next(x)' in text and 'sys_trans #2: !next(y)' in text
    assert 'sys_trans #1' not in text  # not needed for the conflict
    nodes = result.counterstrategy['nodes']
    dead = [n for n in nodes.values() if None in n['state']]
    assert dead and dead[0]['trans'] == [] and dead[0]['state'][0] == 1


def check_counterstrategy(spec_, counter: dict) -> None:
    """Every play of the counter-strategy violates the specification for the system."""
    names = spec_.env_props + spec_.sys_props
    nodes = {k: v for k, v in counter['nodes'].items()}
    graph = nx.DiGraph()
    for name, node in nodes.items():
        if None in node['state']:
            assert node['trans'] == []
            continue
        state = dict(zip(names, map(bool, node['state'])))
        assert node['trans'], f'node {name} has no successor but is no deadlock'
        for t in node['trans']:
            following = nodes[str(t)]['state']
            if None in following:
                continue
            following = dict(zip(names, map(bool, following)))
            assert all(holds(f, state, following) for f in spec_.env_trans)
            assert all(holds(f, state, following) for f in spec_.sys_trans)
            graph.add_edge(name, str(t))
    goals = spec_.sys_liveness or [TRUE]
    assumptions = spec_.env_liveness or [TRUE]
    values = {k: dict(zip(names, map(bool, v['state']))) for k, v in nodes.items() if None not in v['state']}

    def edges_within(graph_, component):
        return [(a, b) for a, b in graph_.edges if a in component and b in component]

    # No cycle satisfies every system goal (a strongly connected set has such a cycle iff
    # each goal labels one of its edges) ...
    for component in nx.strongly_connected_components(graph):
        edges = edges_within(graph, component)
        if edges:
            assert not all(any(holds(goal, values[a], values[b]) for a, b in edges) for goal in goals)
    # ... and no cycle misses an environment assumption.
    for assumption in assumptions:
        pruned = nx.DiGraph([(a, b) for a, b in graph.edges
                             if not holds(assumption, values[a], values[b])])
        for component in nx.strongly_connected_components(pruned):
            assert not edges_within(pruned, component), f'cycle misses assumption {assumption}'


def test_counterstrategy_shape_and_soundness():
    game = spec(env_props=['x'], sys_props=['y'], sys_liveness=[x])
    result = synthesize_with_counterstrategy(game)
    assert result.counterstrategy['variables'] == ['x', 'y']
    node = result.counterstrategy['nodes']['0']
    assert node['rank'] == [0, 0]
    check_counterstrategy(game, result.counterstrategy)
    # The environment keeps x false after the first step.
    successors = {str(t) for n in result.counterstrategy['nodes'].values() for t in n['trans']}
    assert all(result.counterstrategy['nodes'][t]['state'][0] == 0 for t in successors)


@pytest.mark.parametrize('robotics_semantics', [True, False])
@pytest.mark.parametrize('make', [lambda: fairness_game(False), lambda: spec(
    env_props=['x'], sys_props=['y'], sys_liveness=[y, x]), initial_choice_game, lambda: spec(
    env_props=['x', 'z'], sys_props=['y'], env_trans=[implies(x, next_(var('z')))],
    env_liveness=[var('z'), neg(x)], sys_liveness=[iff(y, x), neg(var('z'))])])
def test_counterstrategies_of_unrealizable_games_are_winning_for_the_environment(make, robotics_semantics):
    game = make()
    result = synthesize_with_counterstrategy(game, robotics_semantics)
    if result.realizable:
        check_strategy(game, result.strategy, robotics_semantics)
        return
    assert result.counterstrategy['nodes']
    check_counterstrategy(game, result.counterstrategy)


def test_realizable_result_has_no_counterstrategy_and_unrealizable_no_strategy():
    realizable = synthesize_with_counterstrategy(copy_game())
    assert realizable.counterstrategy is None and realizable.strategy is not None
    unrealizable = synthesize(spec(env_props=['x'], sys_props=['y'], sys_liveness=[x]))
    assert unrealizable.strategy is None and unrealizable.counterstrategy is None
    assert unrealizable.explanation


# --- determinism ----------------------------------------------------------------------------

def chain_like_spec(n: int) -> GR1Specification:
    """A request/response chain: the system activates a_i after done_{i-1}; the environment
    answers fairly; the goal is the last done."""
    env = [f'd{i}' for i in range(n)]
    sys = [f'a{i}' for i in range(n)] + ['fin']
    env_trans, sys_trans, env_live = [], [], []
    for i in range(n):
        a, d = var(f'a{i}'), var(f'd{i}')
        env_trans += [implies(conj([neg(a), neg(d)]), neg(next_(d))), implies(d, next_(d))]
        env_live.append(disj([conj([a, next_(d)]), neg(a), d]))
        if i:
            sys_trans.append(implies(neg(var(f'd{i - 1}')), neg(a)))
        sys_trans.append(implies(next_(d), neg(next_(a))))
    sys_trans += [iff(var('fin'), var(f'd{n - 1}'))]
    return spec(env_props=env, sys_props=sys, env_init=[neg(var(e)) for e in env],
                sys_init=[neg(var(s)) for s in sys], env_trans=env_trans, sys_trans=sys_trans,
                env_liveness=env_live, sys_liveness=[var('fin')])


def test_chain_strategy_is_checked_and_deterministic():
    game = chain_like_spec(3)
    first = synthesize(game)
    assert first.realizable
    check_strategy(game, first.strategy, True)
    again = synthesize(chain_like_spec(3))
    assert strategy_to_json(first.strategy) == strategy_to_json(again.strategy)


@pytest.mark.parametrize('options', [Options(reordering=True), Options(variable_order='declared'),
                                     Options(cluster_limit=0), Options(cluster_limit=10**9)])
def test_engine_options_do_not_change_the_strategy(options):
    game = chain_like_spec(3)
    reference = strategy_to_json(synthesize(game).strategy)
    assert strategy_to_json(synthesize(game, options=options).strategy) == reference


def test_strategy_json_layout_is_slugs():
    text = strategy_to_json(synthesize(copy_game()).strategy)
    assert text.startswith('{"version": 0,\n "slugs": "0.0.1",\n\n "variables": ["x", "y"],\n\n "nodes": {\n')
    assert '"0": {\n\t"rank": 0,\n\t"state": [0, 0],\n\t"trans": [0, 1]\n},\n\n' in text
    assert text.endswith('\n\n}}\n')
    import json
    assert json.loads(text) == synthesize(copy_game()).strategy


# --- cancellation ---------------------------------------------------------------------------

@pytest.fixture(scope='module')
def atlas_chain(tmp_path_factory):
    """The benchmark's chain family at N=20 (several seconds of synthesis), via compile_task."""
    import yaml
    from ltl_specification import compile_task
    directory = tmp_path_factory.mktemp('chain')
    actions = {f'act{i}': ([f'act{i - 1}'] if i else []) + [['stand', 'manipulate'][i % 2]]
               for i in range(20)}
    modes = {'stand_prep': ['stand'], 'stand': ['manipulate', 'step', 'walk'],
             'manipulate': ['stand'], 'step': ['stand'], 'walk': ['stand']}
    (directory / 'chain.yaml').write_text(yaml.safe_dump({'system': 'chain', 'abstraction': {
        'outcomes': ['completed', 'failed'], 'control_modes': modes, 'actions': actions}}))
    return compile_task(robot_system('chain', directory), ['stand_prep'], ['act19'])


def test_deadline_stops_a_long_synthesis(atlas_chain):
    game = atlas_chain
    with pytest.raises(SynthesisCancelledError) as raised:
        synthesize(game, limits=Limits(deadline=time.monotonic() + 0.2))
    assert raised.value.reason == 'timeout' and raised.value.code == 'SYNTHESIS_TIMEOUT'


def test_cancel_flag_stops_a_long_synthesis(atlas_chain):
    game = atlas_chain
    cancel = threading.Event()
    timer = threading.Timer(0.2, cancel.set)
    timer.start()
    try:
        with pytest.raises(SynthesisCancelledError) as raised:
            synthesize(game, limits=Limits(cancel=cancel))
    finally:
        timer.cancel()
    assert raised.value.reason == 'cancelled' and raised.value.code == 'PREEMPTED'


def test_already_cancelled_request_does_no_work():
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(SynthesisCancelledError):
        synthesize(copy_game(), limits=Limits(cancel=cancel))


# --- the automaton message shape ------------------------------------------------------------

def test_automaton_drops_memory_and_names_initial_states():
    game = spec(env_props=['d'], sys_props=['a', 'g_m'], env_init=[neg(var('d'))],
                sys_init=[neg(var('a')), neg(var('g_m'))],
                env_trans=[implies(conj([neg(var('a')), neg(var('d'))]), neg(next_(var('d')))),
                           implies(var('d'), next_(var('d')))],
                sys_trans=[iff(next_(var('g_m')), disj([var('g_m'), next_(var('d'))])),
                           implies(next_(var('d')), neg(next_(var('a'))))],
                env_liveness=[disj([conj([var('a'), next_(var('d'))]), neg(var('a')), var('d')])],
                sys_liveness=[var('g_m')])
    result = synthesize(game)
    assert result.realizable
    automaton = automaton_from_strategy(result.strategy, game)
    assert automaton.output_variables == ['a'] and automaton.input_variables == ['d']
    assert automaton.initial_states == ['0']
    names = [s.name for s in automaton.states]
    assert names == [str(i) for i in range(len(names))]
    for state, node in zip(automaton.states, (result.strategy['nodes'][n] for n in names)):
        assert state.input_valuation == [bool(node['state'][0])]
        assert state.output_valuation == [bool(node['state'][1])]
        assert state.transitions == [str(t) for t in node['trans']] and state.rank == node['rank']
    kept = automaton_from_strategy(result.strategy, game, drop_memory=False)
    assert kept.output_variables == ['a', 'g_m']


def test_automaton_rejects_a_strategy_of_another_specification():
    from respec.automaton import AutomatonError
    strategy = synthesize(copy_game()).strategy
    other = spec(env_props=['y'], sys_props=['x'])
    with pytest.raises(AutomatonError) as raised:
        automaton_from_strategy(strategy, other)
    assert raised.value.code == 'AUTOMATON_INVALID' and raised.value.item == 'variables'
