"""Every limit of a synthesis is enforced in every phase: time limit, cancel, memory limit."""

import threading
import time

import pytest

from ltl_synthesizer import (Interrupt, Limits, SynthesisCancelledError, SynthesisMemoryError, is_realizable,
                             synthesize)
from ltl_synthesizer.policy import Options
from respec.ltl import conj, disj, iff, neg, next_, var
from respec.parsing import parse_structuredslugs
from respec.spec import GR1Specification


def runaway_spec(size=100):
    """``size`` inputs and outputs that nothing constrains: solved at once, but 2**(2 size)
    initial states for the strategy (issue 15's reproducer: the time limit was ignored)."""
    return GR1Specification(env_props=[f'x{i}' for i in range(size)],
                            sys_props=[f'y{i}' for i in range(size)], sys_liveness=[var('y0')])


def exponential_spec(pairs=20):
    """next(y_i) <-> x_i for all i, with every x ordered before every y (the first formula
    mentions them so): the BDD of the conjunction has 2**pairs nodes."""
    xs, ys = [var(f'x{i}') for i in range(pairs)], [var(f'y{i}') for i in range(pairs)]
    order = disj(xs + ys + [neg(xs[0])])
    return GR1Specification(env_props=[x.name for x in xs], sys_props=[y.name for y in ys],
                            sys_trans=[order, conj([iff(next_(y), x) for x, y in zip(xs, ys)])])


@pytest.mark.parametrize('robotics_semantics', [True, False])
def test_the_deadline_stops_strategy_extraction_within_a_second(robotics_semantics):
    started = time.monotonic()
    with pytest.raises(SynthesisCancelledError) as raised:
        synthesize(runaway_spec(), robotics_semantics, Limits(deadline=started + 1.0))
    assert raised.value.code == 'SYNTHESIS_TIMEOUT'
    assert time.monotonic() - started < 2.0


def test_cancel_stops_a_runaway_within_a_second():
    cancel = threading.Event()
    threading.Timer(0.5, cancel.set).start()
    started = time.monotonic()
    with pytest.raises(SynthesisCancelledError) as raised:
        synthesize(runaway_spec(), limits=Limits(cancel=cancel))
    assert raised.value.code == 'PREEMPTED'
    assert time.monotonic() - started < 1.5


def test_the_verdict_alone_of_the_runaway_is_immediate():
    started = time.monotonic()
    assert is_realizable(runaway_spec(), limits=Limits(deadline=started + 30))
    assert time.monotonic() - started < 5


def test_the_memory_limit_ends_a_blow_up_with_a_clear_error():
    limit = 48 * 2**20
    with pytest.raises(SynthesisMemoryError) as raised:
        # The order of first use (the structural order pairs x_i with y_i: no blow-up).
        synthesize(exponential_spec(), limits=Limits(memory_limit=limit), options=Options(variable_order='affinity'))
    assert raised.value.code == 'SYNTHESIS_FAILED' and raised.value.item == 'memory_limit'
    assert 'memory limit of 48 MB' in str(raised.value)
    # The stage it ran into the limit in, and the size measure of the task.
    assert 'while building the game (20 inputs and 20 outputs)' in str(raised.value)


def test_a_timeout_names_the_stage_and_the_size_of_the_task():
    with pytest.raises(SynthesisCancelledError) as raised:
        synthesize(runaway_spec(), limits=Limits(deadline=time.monotonic() + 0.5))
    assert raised.value.code == 'SYNTHESIS_TIMEOUT' and raised.value.reason == 'timeout'
    assert str(raised.value).startswith('synthesis timeout while extracting the strategy (100 inputs and 100 '
                                        'outputs: 400 BDD variables, safety relations of '), str(raised.value)


def test_unrealizable_runaway_explanation_is_bounded_too():
    # The same free propositions, but a goal the environment blocks: every one of the 2**200
    # initial states loses. The explanation counts them symbolically instead of listing them.
    spec = runaway_spec()
    spec.sys_liveness = [var('x0')]
    result = synthesize(spec, limits=Limits(deadline=time.monotonic() + 30))
    assert not result.realizable
    assert f'{2**200} initial state(s)' in result.explanation.replace('.0 initial', ' initial')


@pytest.mark.parametrize('lines', [
    ['x -> next(y)'] * 5000,                                            # one shape
    [' & '.join(['x'] * length) + ' -> next(y)' for length in range(1, 1500)],  # all unlike
])
def test_parsing_checks_the_interrupt(lines):
    text = '[INPUT]\nx\n\n[OUTPUT]\ny\n\n[SYS_TRANS]\n' + '\n'.join(lines) + '\n'
    cancel = threading.Event()
    cancel.set()
    with pytest.raises(SynthesisCancelledError):
        parse_structuredslugs(text, check=Interrupt(cancel))
    assert len(parse_structuredslugs(text, check=Interrupt()).sys_trans) == len(lines)
