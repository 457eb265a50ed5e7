"""The static variable order, chosen from the specification's formulas before any BDD is built.

In the order of first use, the propositions a specification keeps together can end up far
apart, and then a conjunct over them is exponential where it could be linear. Two shapes
are common (issue 44):

- wide integers (structured slugs' bit-blasted ``x@0.0.7``, ``x@1``, ...) that one conjunct
  compares: with all of the robot's position bits above all of the adversary's, "the two do
  not swap cells", ``!((rob' = adv) & (adv' = rob))``, is 786,429 nodes; with the bits of
  equal weight next to each other it is 108. Integers compared with each other form one
  block, their bits interleaved (least significant first, as stored);
- a capability robot's activation, outcomes and memory: its conjuncts mention them together,
  but the one-hot activation conjuncts mention every activation first, so the first-use order
  puts all activations above all outcomes above all memories (a 20-capability chain: 23 s,
  against 0.05 s grouped per capability).

The order is FORCE (Aloul, Markov, Sakallah, "FORCE: a fast and easy-to-implement
variable-ordering heuristic", GLSVLSI 2003): each conjunct is a hyperedge over the units
(propositions, integer blocks) it mentions; every unit moves to the mean of the centres of
its hyperedges, the units are sorted by that and the step is repeated while the total span
of the hyperedges shrinks. The pairwise exclusions of a one-hot group (``!(a & b)`` for every
two of them: a clique whose BDD is linear in any order) count as one hyperedge over the
group, or they would pull the group together and away from everything else. Every
proposition's current and next copies stay adjacent (``translation.declare_pair``).
"""

from __future__ import annotations

from respec.ltl import And, Formula, Next, Not, Or, Var, children
from respec.spec import GR1Specification

# Most FORCE iterations, and how many in a row may fail to shorten the total span.
FORCE_ITERATIONS = 60
FORCE_PATIENCE = 4
# Larger formula DAGs (in nodes) keep the order of first use: the support walk would cost
# more than it could save on specifications whose conjuncts are that large.
MAX_FORMULA_NODES = 2_000_000
# Integers compared in a conjunct over at most this many units (integers only) are interleaved:
# two, as in "rob' != adv'" (cinderella's sums over three buckets, interleaved, made its relations
# 5x larger and its solve 0.12 -> 0.45 s).
COMPARISON_UNITS = 2
# ... when both have at least this many bits: separated, a comparison of two such integers at
# the next step and now (the no-swap conjunct) takes 3 x 2^(2 x bits) nodes, 786,429 at 9
# bits. Narrower integers keep their first-use places, where the sifting passes place them
# better than interleaved (evasion 48x16, 6-bit positions: 3.4 s, interleaved 6.6 s).
MIN_INTERLEAVED_BITS = 8
# ... or when both have this many bits and the same width (two positions on one grid, as the
# per-cell gridworld's robot and adversary): their no-swap conjunct separated is 3,072 nodes
# at 5 bits and 12,288 at 6, most of the relations of the 5x4 and 7x5 gridworlds, whose
# solves take 2-3x longer so (issue 44). Evasion's obstacle coordinates, compared in
# "mox' = mox | moy' = moy", are of different widths and stay apart (interleaved from 5 bits,
# evasion 64x24 took 79 s instead of 25 s).
MIN_INTERLEAVED_EQUAL_BITS = 5
SECTIONS = ('sys_trans', 'env_trans', 'sys_liveness', 'env_liveness', 'env_init', 'sys_init')


def integer_bit(name: str) -> tuple[str, int] | None:
    """``('x', 2)`` for structured slugs' bit ``x@2`` (``x@0.low.high`` is bit 0), else None."""
    base, at, rest = name.partition('@')
    if not at:
        return None
    index = rest.split('.', 1)[0]
    return (base, int(index)) if index.isdigit() else None


def static_order(spec: GR1Specification) -> list[str]:
    """The propositions of ``spec`` in the order to declare them (see the module docstring)."""
    propositions = list(spec.env_props) + list(spec.sys_props)
    conjuncts = _conjuncts(spec)
    supports = _supports(conjuncts)
    if supports is None:
        return _first_use(propositions, [])
    first_use = _first_use(propositions, supports)
    unit_of = {name: bit[0] if (bit := integer_bit(name)) else name for name in propositions}
    widths: dict[str, int] = {}
    for name in propositions:
        if integer_bit(name):
            widths[unit_of[name]] = widths.get(unit_of[name], 0) + 1
    blocks = _compared_integers(supports, unit_of, widths)
    unit_of = {name: blocks.get(unit, unit) for name, unit in unit_of.items()}
    units = list(dict.fromkeys(unit_of[name] for name in first_use))
    index = {unit: k for k, unit in enumerate(units)}
    edges = _hyperedges(conjuncts, supports, unit_of, index)
    ranked = _force(len(units), edges)
    members: dict[str, list[str]] = {}
    for name in first_use:
        members.setdefault(unit_of[name], []).append(name)
    order = []
    for k in ranked:
        order += _interleaved(members[units[k]])
    return order


def _conjuncts(spec: GR1Specification) -> list[Formula]:
    """The top-level conjuncts of every formula, in translation order."""
    result = []
    for section in SECTIONS:
        for formula in getattr(spec, section):
            stack = [formula]
            while stack:
                node = stack.pop()
                if isinstance(node, And):
                    stack.extend(reversed(node.args))
                else:
                    result.append(node)
    return result


def _supports(conjuncts: list[Formula]) -> list[tuple[str, ...]] | None:
    """Each conjunct's propositions (current or next), in order of appearance, each conjunct's
    DAG walked once (a walk per conjunct: memoized supports of nested subformulas would take
    quadratic space on a long nested disjunction). None when the walks would visit more than
    MAX_FORMULA_NODES nodes in all."""
    walked = 0
    result = []
    for root in conjuncts:
        names: dict[str, None] = {}
        seen = set()
        stack = [root]
        while stack:
            node = stack.pop()
            if isinstance(node, Var):
                names[node.name] = None
                continue
            if id(node) in seen:
                continue
            seen.add(id(node))
            walked += 1
            if walked > MAX_FORMULA_NODES:
                return None
            stack.extend(reversed(children(node)))
        result.append(tuple(names))
    return result


def _first_use(propositions: list[str], supports: list[tuple[str, ...]]) -> list[str]:
    seen = dict.fromkeys(name for support in supports for name in support)
    return [name for name in seen if name in set(propositions)] + [p for p in propositions if p not in seen]


def _compared_integers(supports: list[tuple[str, ...]], unit_of: dict[str, str], widths: dict[str, int]
                       ) -> dict[str, str]:
    """Integer -> the block (its first member's name, tagged) of the integers compared with it:
    those sharing a conjunct over at most COMPARISON_UNITS units, all of them integers of at
    least MIN_INTERLEAVED_BITS bits (``widths``), or two of MIN_INTERLEAVED_EQUAL_BITS bits or
    more and the same width."""
    parent: dict[str, str] = {}

    def root(unit: str) -> str:
        while parent.get(unit, unit) != unit:
            unit = parent[unit]
        return unit

    for support in supports:
        units = dict.fromkeys(unit_of[name] for name in support if name in unit_of)
        integers = [unit for unit in units if _is_integer_unit(unit, support, unit_of)]
        if 2 <= len(units) <= COMPARISON_UNITS and len(integers) == len(units) \
                and _wide_enough([widths.get(unit, 0) for unit in integers]):
            first = root(integers[0])
            for other in integers[1:]:
                top = root(other)
                if top != first:
                    parent[top] = first
    groups: dict[str, list[str]] = {}
    for unit in parent:
        groups.setdefault(root(unit), []).append(unit)
    blocks = {}
    for top, members in groups.items():
        name = '\0' + top  # no proposition name starts with NUL
        for member in [top, *members]:
            blocks[member] = name
    return blocks


def _wide_enough(widths: list[int]) -> bool:
    """Whether integers of these widths, compared, are interleaved (MIN_INTERLEAVED_BITS,
    MIN_INTERLEAVED_EQUAL_BITS)."""
    return min(widths) >= MIN_INTERLEAVED_BITS or (
        len(set(widths)) == 1 and widths[0] >= MIN_INTERLEAVED_EQUAL_BITS)


def _is_integer_unit(unit: str, support: tuple[str, ...], unit_of: dict[str, str]) -> bool:
    return any(unit_of[name] == unit and integer_bit(name) for name in support if name in unit_of)


def _hyperedges(conjuncts: list[Formula], supports: list[tuple[str, ...]], unit_of: dict[str, str],
                index: dict[str, int]) -> list[tuple[tuple[int, ...], float]]:
    """Hyperedges (unit indices, multiplicity): one per distinct conjunct support, the
    pairwise exclusions of a group of three or more counted as one edge over the group."""
    exclusions: dict[str, set[str]] = {}
    counted: dict[tuple[int, ...], int] = {}
    for conjunct, support in zip(conjuncts, supports):
        units = tuple(sorted({index[unit_of[name]] for name in support if name in unit_of}))
        if len(units) < 2:
            continue
        pair = _excluded_pair(conjunct)
        if pair is not None and len(units) == 2:
            a, b = pair
            exclusions.setdefault(a, set()).add(b)
            exclusions.setdefault(b, set()).add(a)
            continue
        counted[units] = counted.get(units, 0) + 1
    seen = set()
    for start in exclusions:  # connected groups of exclusions
        if start in seen:
            continue
        group, stack = [], [start]
        seen.add(start)
        while stack:
            name = stack.pop()
            group.append(name)
            for other in exclusions[name]:
                if other not in seen:
                    seen.add(other)
                    stack.append(other)
        units = tuple(sorted({index[unit_of[name]] for name in group}))
        counted[units] = counted.get(units, 0) + 1
    # A hyperedge of k units pulls as a clique of weight 1/(k-1) would: a conjunct over all
    # the capabilities (one of them runs) must not drag them all into its middle. A hub (a
    # unit in many hyperedges, as the machine's ``failed`` outcome that every capability's
    # failure raises) pulls each of its many partners by as little.
    degree = [0] * len(index)
    for units in counted:
        for unit in units:
            degree[unit] += 1
    return [(units, count / (len(units) - 1) / max(degree[unit] for unit in units))
            for units, count in counted.items()]


def _excluded_pair(formula: Formula) -> tuple[str, str] | None:
    """``(a, b)`` when ``formula`` is ``!(a & b)`` or ``!a | !b`` over two literals."""
    if isinstance(formula, Not) and isinstance(formula.arg, And) and len(formula.arg.args) == 2:
        atoms = [_atom(arg) for arg in formula.arg.args]
    elif isinstance(formula, Or) and len(formula.args) == 2 and all(isinstance(a, Not) for a in formula.args):
        atoms = [_atom(arg.arg) for arg in formula.args if isinstance(arg, Not)]  # all are (checked above)
    else:
        return None
    first, second = atoms
    return (first, second) if first is not None and second is not None and first != second else None


def _atom(formula: Formula) -> str | None:
    if isinstance(formula, Next):
        formula = formula.arg
    return formula.name if isinstance(formula, Var) else None


def _force(count: int, edges: list[tuple[tuple[int, ...], float]]) -> list[int]:
    """FORCE's iterations over ``count`` units (initially in index order): the ranking with the
    smallest total weighted span found."""
    position = list(range(count))
    incident: list[list[int]] = [[] for _ in range(count)]
    for k, (units, _) in enumerate(edges):
        for unit in units:
            incident[unit].append(k)

    def span(position: list[int]) -> float:
        return sum(weight * (max(position[u] for u in units) - min(position[u] for u in units))
                   for units, weight in edges)

    best, best_span, stale = list(range(count)), span(position), 0
    for _ in range(FORCE_ITERATIONS):
        centres = [sum(position[u] for u in units) / len(units) for units, _ in edges]
        target = []
        for unit in range(count):
            pulls = incident[unit]
            if pulls:
                total = sum(edges[k][1] for k in pulls)
                target.append(sum(centres[k] * edges[k][1] for k in pulls) / total)
            else:
                target.append(position[unit])
        ranking = sorted(range(count), key=lambda unit: (target[unit], position[unit]))
        position = [0] * count
        for rank, unit in enumerate(ranking):
            position[unit] = rank
        current = span(position)
        if current < best_span:
            best, best_span, stale = ranking, current, 0
        else:
            stale += 1
            if stale >= FORCE_PATIENCE:
                break
    return best


def _interleaved(names: list[str]) -> list[str]:
    """A unit's propositions: an integer block's bits interleaved by weight (bit 0 of each
    integer, then bit 1, ...), each integer's bits in their first-use order otherwise."""
    by_integer: dict[str, list[tuple[int, str]]] = {}
    plain = []
    for name in names:
        bit = integer_bit(name)
        if bit is None:
            plain.append(name)
        else:
            by_integer.setdefault(bit[0], []).append((bit[1], name))
    if len(by_integer) < 2:
        return names
    result = []
    widest = max(len(bits) for bits in by_integer.values())
    ordered = {name: [n for _, n in sorted(bits)] for name, bits in by_integer.items()}
    for level in range(widest):
        for bits in ordered.values():
            if level < len(bits):
                result.append(bits[level])
    return result + plain
