"""Issue 24: the automatic engine policy, strictness as slugs, ``gr1synth --serve``, streamed
JSON strategies and the lean start-up."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ltl_synthesizer import Options, is_realizable, solve, stream_strategy, synthesize
from ltl_synthesizer.strategy import strategy_json_chunks, strategy_to_json
from ltl_synthesizer.gr1 import Solver, solve_system_game
from ltl_synthesizer.strategy import StrategyPiece, SymbolicStrategy, symbolic_strategy
from ltl_synthesizer.synthesizer import initial_positions_win
from ltl_synthesizer.policy import (BETWEEN_ITERATIONS, FROM_START, NEVER, ONCE_LARGE,
                                    SMALL_GAME_PROPOSITIONS)
from ltl_synthesizer.symbolic import SymbolicGame
from respec.parsing import ParseError, parse_slugsin, parse_structuredslugs

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import gr1_families  # noqa: E402
from strategy_check import check_strategy, check_symbolic_strategy  # noqa: E402

REALIZABLE = '[INPUT]\nx\n[OUTPUT]\ny\n[SYS_TRANS]\nnext(y) <-> next(x)\n[SYS_LIVENESS]\ny | !x\n'


def gr1synth(*arguments, stdin=None):
    return subprocess.run([sys.executable, '-m', 'ltl_synthesizer', *map(str, arguments)],
                          input=stdin, capture_output=True, text=True, cwd=REPOSITORY, timeout=120)


# --- strictness -----------------------------------------------------------------------------

@pytest.mark.parametrize('text, parse', [
    ('[INPUT]\na\n[SYS_TRANS]\n| b a\n[OUTPUT]\nb\n', parse_slugsin),
    ('[INPUT]\na\n[SYS_TRANS]\nb | a\n[OUTPUT]\nb\n', parse_structuredslugs),
    ('[ENV_INIT]\nn = 2\n[INPUT]\nn:0...3\n', parse_structuredslugs),
])
def test_a_variable_used_before_its_declaration_is_an_error(text, parse):
    with pytest.raises(ParseError, match='used before its section declares it'):
        parse(text, filename='late')


def test_formula_sections_above_declarations_of_other_variables_are_fine():
    spec = parse_slugsin('[INPUT]\na\n[SYS_TRANS]\n| ! a a\n[OUTPUT]\nb\n')
    assert spec.sys_props == ['b'] and len(spec.sys_trans) == 1


def test_late_declaration_exits_1_on_the_command_line(tmp_path):
    source = tmp_path / 'late.slugsin'
    source.write_text('[INPUT]\na\n[SYS_TRANS]\n| b a\n[OUTPUT]\nb\n')
    done = gr1synth(source)
    assert done.returncode == 1 and f'{source}:4:' in done.stderr and "'b'" in done.stderr


# --- resident mode --------------------------------------------------------------------------

def test_serve_answers_each_request_as_the_command_would(tmp_path):
    source = tmp_path / 'spec.structuredslugs'
    source.write_text(REALIZABLE)
    requests = [[str(source)], ['--explicitStrategy', '--jsonOutput', str(source)],
                [str(source), str(tmp_path / 'out.json')], ['--nonsense'], [str(tmp_path / 'none.slugsin')]]
    done = gr1synth('--serve', stdin=''.join(json.dumps(r) + '\n' for r in requests) + 'not json\n')
    assert done.returncode == 0
    answers = [json.loads(line) for line in done.stdout.splitlines()]
    assert len(answers) == len(requests) + 1
    assert answers[0] == {'status': 0, 'stdout': '', 'stderr': 'RESULT: Specification is realizable.\n'}
    alone = gr1synth('--explicitStrategy', '--jsonOutput', source)
    assert answers[1]['stdout'] == alone.stdout and answers[1]['status'] == 0
    assert answers[2]['status'] == 1 and not (tmp_path / 'out.json').exists()
    assert answers[3]['status'] == 2 and 'unrecognized arguments' in answers[3]['stderr']
    assert answers[4]['status'] == 1
    assert answers[5]['status'] == 1 and 'error' in answers[5]['stderr']


# --- streamed strategies --------------------------------------------------------------------

def test_streamed_json_is_the_same_text_in_pieces():
    spec = parse_structuredslugs(gr1_families.factory(4, 3, 1, 1))
    strategy = synthesize(spec, robotics_semantics=False).strategy
    assert len(strategy['nodes']) > 100
    chunks = list(strategy_json_chunks(strategy, nodes_per_chunk=7))
    assert len(chunks) > 10 and ''.join(chunks) == strategy_to_json(strategy)
    assert json.loads(''.join(chunks))['nodes'].keys() == strategy['nodes'].keys()
    # Streamed: the nodes are made while the text is written, with the same bytes.
    streamed = stream_strategy(solve(spec, robotics_semantics=False))
    assert not isinstance(streamed['nodes'], dict)
    assert ''.join(strategy_json_chunks(streamed, nodes_per_chunk=5)) == strategy_to_json(strategy)


# --- automatic policy -----------------------------------------------------------------------

def test_large_safety_games_skip_the_reachability_search_and_dynamic_sifting():
    spec = parse_structuredslugs(gr1_families.cinderella(6, 3, 11, 6))
    solver = Solver(SymbolicGame(spec))
    assert len(solver.game.variables) > SMALL_GAME_PROPOSITIONS
    assert not solver.plan.reachable_only and solver.plan.reordering == NEVER
    assert not solver.reordering.on


def test_small_safety_games_sift_between_iterations_only():
    """Moving obstacle: sifting passes happen, but never inside a BDD operation."""
    spec = parse_structuredslugs(gr1_families.moving_obstacle(24, 7))
    solver = Solver(SymbolicGame(spec))
    assert solver.plan.reordering == BETWEEN_ITERATIONS and solver.plan.sift_once
    assert not solver.game.bdd.configure()['reordering']  # no automatic (mid-operation) sifting
    sifted_once = solver.game.statistics()['reorderings']
    solution = solve_system_game(solver, stop_when_losing=None)
    assert solver.game.statistics()['reorderings'] > sifted_once
    assert not solver.game.bdd.configure()['reordering']
    assert solution.winning != solver.game.false


def test_several_system_goals_sift_from_the_start():
    solver = Solver(SymbolicGame(parse_structuredslugs(gr1_families.amba(2))))
    assert len(solver.game.sys_goals) > 1 and solver.plan.reordering == FROM_START
    assert solver.reordering.on


@pytest.mark.parametrize('family, arguments, realizable', [
    ('amba', (2,), True), ('cinderella', (5, 2, 6, 4), False), ('cinderella', (5, 2, 7, 4), True),
    ('factory', (3, 3, 1, 1), False), ('factory', (4, 3, 1, 1), True),
    ('moving_obstacle', (8, 0), True), ('moving_obstacle', (8, 1), False),
])
def test_families_verdicts_are_the_same_under_every_engine_choice(family, arguments, realizable):
    spec = parse_structuredslugs(getattr(gr1_families, family)(*arguments))
    verdicts = {is_realizable(spec, robotics_semantics=False, options=options)
                for options in (Options(), Options(reordering=True), Options(reordering=False),
                                Options(reachable_only=True), Options(sift_once=True))}
    assert verdicts == {realizable}


@pytest.mark.parametrize('family, arguments', [
    ('moving_obstacle', (16, 3)), ('moving_obstacle', (16, 4)), ('evasion', (24, 8)),
])
@pytest.mark.slow
def test_the_invariant_kept_apart_changes_nothing_but_the_work(family, arguments):
    """Moving obstacle and evasion have invariants over inputs only (the robot never meets
    the obstacle): the same winning positions with the invariant in or out of the products,
    and the strategy solved with it out passes the independent check."""
    spec = parse_structuredslugs(getattr(gr1_families, family)(*arguments))
    apart = SymbolicGame(spec, options=Options(invariant_apart=True))
    kept_in = SymbolicGame(spec, options=Options(invariant_apart=False))
    assert apart.sys_invariant != apart.true and kept_in.sys_invariant == kept_in.true
    won = [solve_system_game(Solver(game, Options(invariant_apart=flag))).winning
           for game, flag in ((apart, True), (kept_in, False))]
    assert kept_in.bdd.copy(won[1], apart.bdd) == won[0]
    solution = solve_system_game(Solver(apart))
    if initial_positions_win(apart, solution.winning, robotics_semantics=False):
        strategy = symbolic_strategy(apart, solution)
        assert check_symbolic_strategy(spec, strategy, apart.bdd) == []


def test_automatic_reordering_switches_on_past_the_node_threshold(monkeypatch):
    from ltl_synthesizer import policy
    monkeypatch.setattr(policy, 'DYNAMIC_REORDERING_FROM_NODES', 10)
    monkeypatch.setattr(policy, 'REORDERING_CHECK_PERIOD', 1)
    spec = parse_structuredslugs(gr1_families.evasion(24, 8).replace(
        '!requestPending2\n', ''))  # one system goal and an (implicit) assumption
    solver = Solver(SymbolicGame(spec))
    assert solver.plan.reordering == ONCE_LARGE and not solver.reordering.on
    assert len(solver.game.sys_goals) == 1
    solver.enforce(solver.game.true)
    assert solver.reordering.on
    solver.reordering.stop()
    assert not solver.reordering.on


@pytest.mark.slow
def test_strategies_of_family_instances_pass_the_independent_check():
    for generator, arguments in ((gr1_families.amba, (2,)), (gr1_families.factory, (4, 3, 1, 1)),
                                 (gr1_families.moving_obstacle, (8, 0))):
        spec = parse_structuredslugs(generator(*arguments))
        result = synthesize(spec, robotics_semantics=False)
        assert result.realizable
        assert check_strategy(spec, result.strategy) == []


def test_the_independent_check_catches_a_broken_strategy():
    spec = parse_structuredslugs(REALIZABLE)
    strategy = synthesize(spec, robotics_semantics=False).strategy
    broken = json.loads(json.dumps(strategy))
    for node in broken['nodes'].values():
        node['state'][1] = 1 - node['state'][1]  # y no longer follows x
    assert check_strategy(spec, broken)


def solved(spec):
    """The game of ``spec``, its solution and our strategy as relations."""
    game = SymbolicGame(spec)
    solution = solve_system_game(Solver(game))
    return game, solution, symbolic_strategy(game, solution)


def test_symbolic_strategies_of_family_instances_pass_the_independent_check():
    for generator, arguments in ((gr1_families.amba, (2,)), (gr1_families.factory, (4, 3, 1, 1)),
                                 (gr1_families.moving_obstacle, (8, 0)),
                                 (gr1_families.cinderella, (5, 2, 7, 4))):
        spec = parse_structuredslugs(generator(*arguments))
        game, solution, strategy = solved(spec)
        assert initial_positions_win(game, solution.winning, robotics_semantics=False)
        assert check_symbolic_strategy(spec, strategy, game.bdd) == []


# A system that must raise y infinitely often, free to choose it every step.
FREE_GOAL = '[INPUT]\nx\n[OUTPUT]\ny\n[SYS_LIVENESS]\ny\n[ENV_LIVENESS]\nx\n'


def test_the_symbolic_check_catches_broken_strategies():
    spec = parse_structuredslugs(FREE_GOAL)
    game, solution, strategy = solved(spec)
    assert check_symbolic_strategy(spec, strategy, game.bdd) == []
    y_next = game.bdd.var("y'")
    # May keep y low forever: one more piece per goal, offering every move into !y.
    may_idle = SymbolicStrategy(strategy.winning, [pieces + [StrategyPiece(game.true, ~y_next)]
                                                   for pieces in strategy.pieces])
    assert check_symbolic_strategy(spec, may_idle, game.bdd) == [
        'goal 0: a path of the strategy meets every assumption and never the goal']
    nowhere = SymbolicStrategy(game.false, strategy.pieces)
    assert 'no initial position' in check_symbolic_strategy(spec, nowhere, game.bdd)[0]
    silent = SymbolicStrategy(strategy.winning, [[]])
    assert check_symbolic_strategy(spec, silent, game.bdd) == [
        'goal 0: some environment move allowed at a position of the strategy has no answer']

    spec = parse_structuredslugs(REALIZABLE)
    game, solution, strategy = solved(spec)
    assert check_symbolic_strategy(spec, strategy, game.bdd) == []
    # Claims only the position x = y = 1, but the environment may then lower x.
    x, y = game.bdd.var('x'), game.bdd.var('y')
    narrowed = SymbolicStrategy(x & y, strategy.pieces)
    assert 'goal 0: a move leaves the positions of the strategy' in \
        check_symbolic_strategy(spec, narrowed, game.bdd)


# --- start-up -------------------------------------------------------------------------------

def fresh_python(code: str) -> subprocess.CompletedProcess:
    """``code`` run by a fresh interpreter in the repository: what importing it loads."""
    return subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, cwd=REPOSITORY, timeout=60)


def test_synthesis_does_not_load_networkx():
    code = ('import sys; from ltl_synthesizer import synthesize; import ltl_synthesizer.symbolic; '
            'print("networkx" in sys.modules)')
    done = fresh_python(code)
    assert done.stdout.strip() == 'False'


def test_synthesis_loads_none_of_what_dd_imports_for_features_it_does_not_use():
    # The verdict needs none of them; an explicit strategy only dd.bdd (dd.cudd enumerates cubes
    # with it), without dd's parser (ply) and the rest.
    code = ('import sys; from ltl_synthesizer import is_realizable, synthesize\n'
            'from ltl_synthesizer.cudd_import import _DEFERRED\n'
            'from respec.parsing import parse_structuredslugs\n'
            'spec = parse_structuredslugs("[INPUT]\\nx\\n[OUTPUT]\\ny\\n[SYS_TRANS]\\ny\' <-> x\'\\n")\n'
            'assert is_realizable(spec)\n'
            'print(sorted(name for name in _DEFERRED if name in sys.modules))\n'
            'assert synthesize(spec).strategy["nodes"]\n'
            'print(sorted(name for name in _DEFERRED if name in sys.modules), "ply" in sys.modules)')
    done = fresh_python(code)
    assert done.stdout.splitlines() == ['[]', "['dd.bdd'] False"], done.stderr


def test_dd_features_behind_the_stand_ins_still_work(tmp_path):
    # dd's parser (ply), JSON dump (dd._copy), enumeration (dd.bdd) and networkx export load on
    # first use, as the one copy that a plain import of the same modules gets.
    code = f'''
import sys
from ltl_synthesizer.cudd_import import cudd
bdd = cudd.BDD()
bdd.declare('x', 'y')
u = bdd.add_expr(r'x /\\ ~ y')
print(list(bdd.pick_iter(u)))
bdd.dump({str(tmp_path / 'u.json')!r}, [u])
import dd._copy, dd.bdd, dd._utils, networkx, pickle
print(cudd._copy.load_json is dd._copy.load_json, cudd._bdd.BDD is dd.bdd.BDD, cudd.pickle.dump is pickle.dump)
print(dd._utils.import_module('networkx').MultiDiGraph is networkx.MultiDiGraph)
'''
    done = fresh_python(code)
    assert done.stdout.split('\n')[:3] == ["[{'x': True, 'y': False}]", 'True True True', 'True'], done.stderr
    assert '"roots"' in (tmp_path / 'u.json').read_text()


def test_dd_logs_through_logging_once_logging_is_configured():
    # dd's loggers come without logging; its info messages are dropped only while nothing has
    # loaded (so configured) logging, as the root logger's default level would drop them.
    code = (
        'import sys\n'
        'from ltl_synthesizer.cudd_import import cudd\n'
        'cudd.BDD()\n'
        'print("logging" in sys.modules)\n'
        'import logging\n'
        'logging.basicConfig(level=logging.INFO, stream=sys.stdout, format="%(name)s %(levelname)s")\n'
        'cudd.BDD()\n')
    done = fresh_python(code)
    assert done.stdout.splitlines() == ['False', 'dd.cudd INFO'], done.stderr


def test_one_goal_games_are_compact_up_to_a_looser_bound():
    # The chain of 160 capabilities retrying on failure: 30 nodes per proposition, one goal.
    from types import SimpleNamespace
    from ltl_synthesizer.policy import is_compact
    one_goal = SimpleNamespace(variables=['p'] * 100, sys_goals=[None], relation_nodes=3000)
    many_goals = SimpleNamespace(variables=['p'] * 100, sys_goals=[None] * 20, relation_nodes=3000)
    assert is_compact(one_goal, Options())
    assert not is_compact(many_goals, Options())
    assert not is_compact(SimpleNamespace(variables=['p'] * 100, sys_goals=[None], relation_nodes=3300), Options())
    assert not is_compact(one_goal, Options(variable_order='affinity'))
