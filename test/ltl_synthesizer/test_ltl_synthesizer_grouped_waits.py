"""Capability robots above gr1.GROUPED_WAITS_FROM capabilities wait for their capabilities'
fairness assumptions in one inner fixpoint (gr1._waits): the winning positions equal those of
one fixpoint per assumption, and the explicit strategy passes the independent check."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ltl_synthesizer import gr1, solve
from ltl_synthesizer.synthesizer import explicit_strategy
from respec.robot import robot_system

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import capability_robots  # noqa: E402
from strategy_check import check_strategy  # noqa: E402
from ltl_specification import compile_task  # noqa: E402


def _compiled(shape: str, size: int, directory: Path):
    robot = capability_robots.SHAPES[shape](size)
    robot.write(directory)
    return compile_task(robot_system(robot.name, str(directory)), robot.initial_conditions, robot.goals,
                        sm_outcomes=capability_robots.REQUEST_OUTCOMES,
                        state_library=capability_robots.STATE_LIBRARY)


@pytest.mark.parametrize('shape', ['chain', 'retry', 'sensor', 'diamond', 'fanout', 'mix'])
def test_grouped_waits_win_where_separate_ones_do_and_their_strategy_passes_the_check(shape, tmp_path, monkeypatch):
    spec = _compiled(shape, 20, tmp_path)
    # Grouped throughout, even where the group grows fast (the fan-out: see the test below).
    monkeypatch.setattr(gr1, 'GROUP_GROWTH_PER_PROPOSITION', 10**6)
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
    solved = solve(_compiled('chain', 10, tmp_path), True)
    assert all(len(wait.members) == 1 for wait in solved.solver.waits)


@pytest.mark.parametrize('shape, keeps_group', [('fanout', False), ('chain', True), ('diamond', True)])
def test_a_group_growing_fast_is_given_up_after_a_few_sweeps(shape, keeps_group, tmp_path):
    # The fan-out's capabilities end in any combination: its group's X grows by about 1.3
    # nodes per proposition and sweep (a chain's or a diamond's by under 0.1).
    spec = _compiled(shape, 20, tmp_path)
    solved = solve(spec, True)
    assert solved.realizable
    grouped = max(len(wait.members) for wait in solved.solver.waits) > 1
    assert grouped == keeps_group
    assert check_strategy(spec, explicit_strategy(solved)) == []
