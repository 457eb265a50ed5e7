"""Games above gr1.GROUPED_WAITS_FROM environment goals wait for goals whose violations are
confined in one inner fixpoint (gr1._waits), as long as the group finds its positions in the
first sweeps, and sweep their inner fixpoints in alternating directions (gr1._sweep_order):
the winning positions equal those of one fixpoint per assumption in one direction, and the
explicit strategy passes the independent check."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ltl_synthesizer import gr1, solve
from ltl_synthesizer.synthesizer import explicit_strategy

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import capability_robots  # noqa: E402
import gr1_families  # noqa: E402
from strategy_check import check_strategy  # noqa: E402
from respec.parsing import parse_structuredslugs  # noqa: E402


@pytest.mark.parametrize('shape', ['chain', 'retry', 'sensor', 'diamond', 'fanout', 'mix'])
def test_grouped_waits_win_where_separate_ones_do_and_their_strategy_passes_the_check(shape, tmp_path, monkeypatch):
    spec = capability_robots.compiled_spec(shape, 20, tmp_path)
    # Grouped throughout, even where the group still adds positions late (see the test below).
    monkeypatch.setattr(gr1, 'GROUP_SWEEPS', 10**6)
    solved = solve(spec, True)
    assert solved.realizable
    assert max(len(wait.members) for wait in solved.solver.waits) >= 19  # all but a sensor's
    assert check_strategy(spec, explicit_strategy(solved)) == []
    game = solved.game
    monkeypatch.setattr(gr1, 'GROUPED_WAITS_FROM', 10**6)
    separate = gr1.Solver(game)
    assert all(len(wait.members) == 1 for wait in separate.waits)
    assert gr1.solve_system_game(separate).winning == solved.solution.winning


def test_small_robots_keep_one_fixpoint_per_assumption(tmp_path):
    solved = solve(capability_robots.compiled_spec('chain', 10, tmp_path), True)
    assert all(len(wait.members) == 1 for wait in solved.solver.waits)


@pytest.mark.parametrize('shape', ['fanout', 'chain', 'diamond', 'mix'])
def test_a_robots_group_still_adding_positions_after_a_few_sweeps_is_given_up(shape, tmp_path):
    # A robot's capabilities run one after another: a grouped fixpoint per sweep finds one
    # more capability's positions in each sweep, single fixpoints in alternating sweeps all.
    spec = capability_robots.compiled_spec(shape, 20, tmp_path)
    solved = solve(spec, True)
    assert solved.realizable
    assert all(len(wait.members) == 1 for wait in solved.solver.waits)
    assert check_strategy(spec, explicit_strategy(solved)) == []


def test_the_arbiters_clients_stay_grouped():
    # Any client may be the granted one: the group finds them all in its first sweep.
    spec = parse_structuredslugs(gr1_families.arbiter(24), filename='arbiter.structuredslugs')
    solved = solve(spec, True)
    assert solved.realizable
    assert max(len(wait.members) for wait in solved.solver.waits) == 24
    separate = gr1.Solver(solved.game)
    separate.waits = gr1.ungrouped(separate)
    assert gr1.solve_system_game(separate).winning == solved.solution.winning


@pytest.mark.parametrize('shape, one_after_another', [
    ('chain', True), ('retry', True), ('sensor', True), ('diamond', True), ('mix', True), ('fanout', False)])
def test_alternating_sweeps_win_where_one_direction_does_with_fewer_fixpoints(shape, one_after_another, tmp_path,
                                                                              monkeypatch):
    spec = capability_robots.compiled_spec(shape, 40, tmp_path)
    game = solve(spec, True).game
    computed = []
    wait_for_assumption = gr1._wait_for_assumption

    def counted(*arguments):
        computed.append(arguments)
        return wait_for_assumption(*arguments)

    monkeypatch.setattr(gr1, '_wait_for_assumption', counted)
    results = {}
    for alternating in (True, False):
        solver = gr1.Solver(game)
        solver.waits = gr1.ungrouped(solver)
        assert solver.alternating_sweeps
        solver.alternating_sweeps = alternating
        computed.clear()
        results[alternating] = (gr1.solve_system_game(solver).winning, len(computed))
    assert results[True][0] == results[False][0]
    # Forwards only, a capability that runs before another is found a sweep after it: about
    # N^2/2 fixpoints; alternating, a few sweeps of N. The fan-out's capabilities run in any
    # order: one sweep finds them in either direction.
    assert results[True][1] <= 5 * 40
    assert (results[False][1] > 5 * 40) == one_after_another
