"""The structural static variable order (ltl_synthesizer.ordering, issue 44)."""

from ltl_synthesizer import synthesize
from ltl_synthesizer.ordering import integer_bit, static_order
from ltl_synthesizer.policy import Options
from ltl_synthesizer.symbolic import SymbolicGame
from respec.ltl import conj, disj, iff, implies, neg, next_, var
from respec.spec import GR1Specification

BITS = 8


def bits(name: str, width: int = BITS) -> list[str]:
    """Structured slugs' bits of an integer ``name: 0...2^width - 1``."""
    return [f'{name}@0.0.{2 ** width - 1}'] + [f'{name}@{k}' for k in range(1, width)]


def equal(left, right):
    return conj(iff(a, b) for a, b in zip(left, right))


def swap_spec(rob_width: int = BITS, adv_width: int = BITS) -> GR1Specification:
    """Two positions (8-bit by default) that never coincide nor swap: ``rob' != adv'``,
    ``!((rob' = adv) & (adv' = rob))`` (as structured slugs bit-blasts them)."""
    rob, adv = [var(b) for b in bits('rob', rob_width)], [var(b) for b in bits('adv', adv_width)]
    following = [next_(v) for v in rob], [next_(v) for v in adv]
    # The first conjunct names every bit of rob before any of adv: the order of first use.
    return GR1Specification(env_props=bits('adv', adv_width), sys_props=bits('rob', rob_width), sys_trans=[
        neg(conj(following[0] + following[1])),
        neg(equal(following[0], following[1])),
        neg(conj([equal(following[0], adv), equal(following[1], rob)]))])


def test_integers_a_conjunct_compares_are_interleaved_bit_by_bit():
    order = [integer_bit(name) for name in static_order(swap_spec())]
    assert [{order[2 * bit], order[2 * bit + 1]} for bit in range(BITS)] == \
        [{('rob', bit), ('adv', bit)} for bit in range(BITS)]


def test_narrower_integers_are_interleaved_only_when_of_the_same_width():
    """5 to 7 bits: two positions on one grid (the 5x4 and 7x5 gridworlds' robot and
    adversary) interleave; integers of different widths (evasion's obstacle coordinates) keep
    their first-use places, all of rob's bits before adv's."""
    for width in (5, 6, 7):
        order = [integer_bit(name) for name in static_order(swap_spec(width, width))]
        assert [{order[2 * bit], order[2 * bit + 1]} for bit in range(width)] == \
            [{('rob', bit), ('adv', bit)} for bit in range(width)]
    order = [integer_bit(name)[0] for name in static_order(swap_spec(6, 5))]
    assert order == ['rob'] * 6 + ['adv'] * 5
    order = [integer_bit(name)[0] for name in static_order(swap_spec(4, 4))]
    assert order == ['rob'] * 4 + ['adv'] * 4


def test_the_no_swap_conjunct_is_small_interleaved_and_exponential_in_first_use_order():
    spec = swap_spec()
    interleaved = SymbolicGame(spec, Options(sift_once=False)).relation_nodes
    first_use = SymbolicGame(spec, Options(variable_order='affinity', sift_once=False)).relation_nodes
    assert interleaved < 250 and first_use > 1000 * interleaved  # 165 and 197,371 nodes


def capability_chain(count: int) -> GR1Specification:
    """A chain of capabilities as ltl_specification.capabilities compiles one: one-hot
    activations (their pairwise exclusions and a disjunction over all), outcomes only of the
    running capability, memories set by completions, each capability needing the previous
    one's memory; a failure ends the machine in ``failed``."""
    names = [f'k{i}' for i in range(count)]
    active = [var(f'{n}_a') for n in names] + [var('failed'), var('done')]
    env_trans, sys_trans, env_liveness = [], [], []
    sys_trans.append(disj(next_(a) for a in active))
    sys_trans += [neg(conj([next_(a), next_(b)])) for i, a in enumerate(active) for b in active[i + 1:]]
    for i, n in enumerate(names):
        a, c, f, m = var(f'{n}_a'), var(f'{n}_c'), var(f'{n}_f'), var(f'{n}_m')
        env_trans += [implies(neg(a), neg(next_(c))), implies(neg(a), neg(next_(f))),
                      neg(conj([next_(c), next_(f)]))]
        env_liveness.append(disj([neg(a), next_(c)]))
        sys_trans += [implies(conj([a, neg(next_(c)), neg(next_(f))]), next_(a)),
                      implies(next_(c), next_(m)), implies(neg(next_(c)), implies(m, next_(m))),
                      implies(next_(f), next_(var('failed')))]
        if i:
            sys_trans.append(implies(next_(a), next_(var(f'{names[i - 1]}_m'))))
    sys_trans += [implies(var('failed'), next_(var('failed'))),
                  implies(next_(var('done')), var(f'{names[-1]}_m'))]
    return GR1Specification(
        env_props=[f'{n}_{x}' for n in names for x in 'cf'],
        sys_props=[f'{n}_a' for n in names] + ['failed', 'done'] + [f'{n}_m' for n in names],
        env_trans=env_trans, sys_trans=sys_trans, env_liveness=env_liveness,
        sys_liveness=[disj([var('done'), var('failed')])],
        env_init=[neg(var(f'{n}_{x}')) for n in names for x in 'cf'],
        sys_init=[neg(a) for a in active] + [neg(var(f'{n}_m')) for n in names])


def test_a_capabilitys_activation_outcomes_and_memory_sit_together():
    order = static_order(capability_chain(12))
    for index in range(12):
        places = [order.index(f'k{index}_{x}') for x in 'acfm']
        assert max(places) - min(places) <= 6, (index, order)  # first use: 16-38 apart


def test_the_capability_chain_is_solved_alike_in_every_order():
    spec = capability_chain(8)
    verdicts = {order: synthesize(spec, options=Options(variable_order=order)) for order in
                ('structure', 'affinity', 'declared')}
    assert all(result.realizable for result in verdicts.values())
    strategies = {order: result.strategy for order, result in verdicts.items()}
    assert strategies['structure'] == strategies['affinity'] == strategies['declared']
