"""The explicit strategy's extraction has two ways of reading a position's moves
(strategy.COFACTORED_FROM): on cofactors by the state (games of many variables) and on the
state's cube conjoined with the relations (few variables). Both give the same strategy, byte
for byte, and it passes the independent check; the search for the outputs a position's moves
leave free (strategy._free_names) finds exactly those."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

from ltl_synthesizer import strategy
from ltl_synthesizer.strategy import strategy_to_json
from ltl_synthesizer.synthesizer import explicit_strategy, solve
from respec.parsing import parse_slugsin

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import capability_robots  # noqa: E402
from strategy_check import check_strategy  # noqa: E402


def _both_ways(spec, monkeypatch) -> tuple[str, str]:
    texts = []
    for threshold in (0, 10**6):  # every game on cofactors, then every game on the cube
        monkeypatch.setattr(strategy, 'COFACTORED_FROM', threshold)
        texts.append(strategy_to_json(explicit_strategy(solve(spec, True))))
    return texts[0], texts[1]


@pytest.mark.parametrize('shape', ['chain', 'sensor', 'mix'])
def test_a_capability_robot_has_the_same_strategy_on_cofactors_and_on_the_cube(shape, tmp_path, monkeypatch):
    spec = capability_robots.compiled_spec(shape, 36, tmp_path)
    assert len(spec.env_props) + len(spec.sys_props) > strategy.COFACTORED_FROM  # the default takes cofactors
    on_cofactors, on_cube = _both_ways(spec, monkeypatch)
    assert on_cofactors == on_cube
    assert check_strategy(spec, json.loads(on_cofactors)) == []


def test_a_gridworld_has_the_same_strategy_on_cofactors_and_on_the_cube(monkeypatch):
    spec = parse_slugsin(capability_robots.per_cell_gridworld(5, 4, 3, True))
    assert len(spec.env_props) + len(spec.sys_props) <= strategy.COFACTORED_FROM  # the default takes the cube
    on_cofactors, on_cube = _both_ways(spec, monkeypatch)
    assert on_cofactors == on_cube
    assert len(json.loads(on_cube)['nodes']) > 10


def chain_outputs(tmp_path):
    """The solved game of the 20-capability chain, its first 40 next outputs and their literals."""
    game = solve(capability_robots.compiled_spec('chain', 20, tmp_path), True).game
    names = game.next_outputs[:40]
    return game, names, [game.bdd.var(name) for name in names]


def test_free_names_are_exactly_the_names_taking_both_values(tmp_path):
    game, names, literals = chain_outputs(tmp_path)
    # Names 3, 17 and 30 are free (in two different ways), name 8 takes both values only
    # together with name 9; every other name is fixed, alternately False and True.
    u = game.bdd.true
    for index, literal in enumerate(literals):
        if index not in (3, 8, 9, 17, 30):
            u &= literal if index % 2 else ~literal
    u &= (literals[8] & ~literals[9]) | (~literals[8] & literals[9])
    u &= literals[17] | literals[30]
    found = strategy._free_names(game, u, names)
    # Brute force: a name is free when u allows it False and allows it True.
    expected = {name for name, literal in zip(names, literals)
                if u & literal != game.false and u & ~literal != game.false}
    assert found == expected == {names[index] for index in (3, 8, 9, 17, 30)}


def test_free_names_of_moves_with_many_assignments_are_found_by_the_search(tmp_path):
    # More assignments than _free_names reads (FREE_NAMES_READ) before its search: five pairs
    # of names whose values differ (32 assignments), one name fixed by all of them.
    game, names, literals = chain_outputs(tmp_path)
    u = game.bdd.true
    for index, literal in enumerate(literals):
        if index >= 10:
            u &= literal if index % 3 else ~literal
        elif index % 2:
            u &= (literals[index - 1] & ~literal) | (~literals[index - 1] & literal)
    assert 2**5 > strategy.FREE_NAMES_READ + 1
    found = strategy._free_names(game, u, names)
    expected = {name for name, literal in zip(names, literals)
                if u & literal != game.false and u & ~literal != game.false}
    assert found == expected == set(names[:10])
