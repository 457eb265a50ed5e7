"""Issue 38: the new bench families (GenBuf, gridworld with a patrolling adversary, the fair
arbiter, the lift) decide as designed, and our counter-strategies pass the independent check
of bench/strategy_check.py, which also rejects broken ones."""

from __future__ import annotations

import copy
import sys
from pathlib import Path

import pytest

from ltl_synthesizer import solve
from ltl_synthesizer.synthesizer import counter_strategy, explicit_strategy
from respec.parsing import parse_structuredslugs

REPOSITORY = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPOSITORY / 'bench'))

import gr1_families  # noqa: E402
from strategy_check import check_counterstrategy, check_strategy  # noqa: E402

SMALL = {
    'genbuf 3 senders': lambda realizable: gr1_families.genbuf(3, realizable),
    'gridworld 7x5 k=3': lambda realizable: gr1_families.gridworld(7, 5, 3, realizable),
    'arbiter 3 clients': lambda realizable: gr1_families.arbiter(3, realizable),
    'lift 4 floors': lambda realizable: gr1_families.lift(4, realizable),
}


def _spec(text: str):
    return parse_structuredslugs(text, filename='family.structuredslugs')


@pytest.mark.parametrize('family', SMALL)
def test_the_realizable_variant_has_a_checked_strategy(family):
    spec = _spec(SMALL[family](True))
    solved = solve(spec, robotics_semantics=False)
    assert solved.realizable
    assert check_strategy(spec, explicit_strategy(solved)) == []


@pytest.mark.parametrize('robotics_semantics', [False, True])
@pytest.mark.parametrize('family', SMALL)
def test_the_unrealizable_variant_has_a_checked_counterstrategy(family, robotics_semantics):
    spec = _spec(SMALL[family](False))
    solved = solve(spec, robotics_semantics=robotics_semantics)
    assert not solved.realizable
    strategy = counter_strategy(solved)
    assert len(strategy['nodes']) > 1
    assert check_counterstrategy(spec, strategy, robotics_semantics) == []


def test_the_counterstrategy_check_rejects_a_missing_system_answer_and_a_foreign_strategy():
    spec = _spec(gr1_families.gridworld(7, 5, 3, False))
    strategy = counter_strategy(solve(spec, robotics_semantics=False))
    # A node that lists several system answers loses one: that answer escapes the strategy.
    broken = copy.deepcopy(strategy)
    name = next(name for name, node in broken['nodes'].items() if len(node['trans']) > 1)
    broken['nodes'][name]['trans'].pop()
    assert any('has no successor' in problem
               for problem in check_counterstrategy(spec, broken, robotics_semantics=False))
    # The realizable variant's own specification: the same graph no longer wins there (the
    # adversary must patrol), so some cycle fails an assumption or meets every goal.
    realizable = _spec(gr1_families.gridworld(7, 5, 3, True))
    assert check_counterstrategy(realizable, strategy, robotics_semantics=False) != []
