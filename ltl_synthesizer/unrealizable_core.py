"""Unrealizable cores: the fewest guarantees that are still unrealizable, by delta debugging.

A specification is divided into groups of formulas (``ltl_specification.components.FormulaGroup``: the
formulas one paper equation adds for one item, or one custom formula). The environment's
assumptions stay as they are; among the system's guarantees, Zeller and Hildebrandt's
``ddmin`` finds a subset of groups that is still unrealizable and from which no single group
can be dropped (1-minimal). As in Spectra's unrealizable cores, only guarantees are dropped:
dropping an assumption frees the environment, which makes almost anything unrealizable. With
slugs' robotics semantics SYS_INIT is not dropped either: there it narrows the initial states
that must all be winning, so dropping it makes a specification harder, like an assumption.

Realizability of each candidate is decided by the synthesizer's own game (the same check as
``synthesize`` makes before extracting a strategy), so results never differ from synthesis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Generic, Protocol, Sequence, TypeVar

from respec.ltl import Formula
from respec.spec import FORMULA_SECTIONS, GR1Specification

from ltl_synthesizer.gr1 import Solver, solve_environment_game
from ltl_synthesizer.interrupt import Limits
from ltl_synthesizer.strategy import extract_counterstrategy
from ltl_synthesizer.symbolic import SymbolicGame
from ltl_synthesizer.synthesizer import is_realizable

T = TypeVar('T')
# Positions the search for a telling environment play may visit (it is only an illustration).
MAX_PLAY_SEARCH = 20000


def ddmin(candidates: Sequence[T], fails: Callable[[list[T]], bool]) -> list[T]:
    """Zeller and Hildebrandt's minimizing delta debugging.

    ``fails(candidates)`` must hold; the result is a sublist (in the given order) for which
    ``fails`` still holds and which loses that property when any single element is removed.
    Tests on subsets and on complements of an ``n``-way split, refining ``n`` when neither fails.
    """
    def test(positions: list[int]) -> bool:
        return fails([candidates[p] for p in positions])

    current = list(range(len(candidates)))  # positions, so equal candidates stay distinct
    granularity = 2
    while len(current) >= 2:
        chunks = _split(current, granularity)
        reduced = next((chunk for chunk in chunks if test(chunk)), None)
        if reduced is not None:
            current, granularity = reduced, 2
            continue
        # With two chunks the complements are the chunks themselves, already tested.
        complements = [[p for p in current if p not in chunk] for chunk in chunks] if granularity > 2 else []
        reduced = next((rest for rest in complements if test(rest)), None)
        if reduced is not None:
            current, granularity = reduced, max(granularity - 1, 2)
            continue
        if granularity >= len(current):
            break
        granularity = min(len(current), 2 * granularity)
    return [candidates[p] for p in current]


def _split(items: list[T], parts: int) -> list[list[T]]:
    """``items`` in ``parts`` consecutive chunks of nearly equal size."""
    size, extra = divmod(len(items), parts)
    chunks, start = [], 0
    for index in range(parts):
        end = start + size + (1 if index < extra else 0)
        chunks.append(items[start:end])
        start = end
    return [chunk for chunk in chunks if chunk]


class Group(Protocol):
    """What a core is made of: formulas of one section (``ltl_specification.components.FormulaGroup``)."""

    @property
    def section(self) -> str: ...

    @property
    def formulas(self) -> Sequence[Formula]: ...


G = TypeVar('G', bound=Group)


@dataclass
class Core(Generic[G]):
    """An unrealizable core: the guarantee groups (in the specification's order) and the
    specification made of them plus every assumption."""

    groups: list[G]
    specification: GR1Specification
    realizability_checks: int


def droppable_sections(robotics_semantics: bool) -> tuple[str, ...]:
    """The sections whose formulas a core may leave out (see the module documentation)."""
    return ('sys_trans', 'sys_liveness') if robotics_semantics else ('sys_init', 'sys_trans', 'sys_liveness')


def restrict_guarantees(spec: GR1Specification, groups: Sequence[Group], sections: Sequence[str]) -> GR1Specification:
    """``spec`` with only those formulas of ``sections`` that belong to ``groups``."""
    kept = {(group.section, formula) for group in groups for formula in group.formulas}
    restricted = GR1Specification(env_props=list(spec.env_props), sys_props=list(spec.sys_props))
    for section in FORMULA_SECTIONS:
        formulas = getattr(spec, section)
        if section in sections:
            formulas = [f for f in formulas if (section, f) in kept]
        setattr(restricted, section, list(formulas))
    return restricted


def unrealizable_core(spec: GR1Specification, groups: Sequence[G], robotics_semantics: bool = True,
                      limits: Limits = Limits()) -> Core[G] | None:
    """A 1-minimal set of guarantee ``groups`` that, with all assumptions, is unrealizable.

    ``groups`` are objects with ``section`` and ``formulas`` covering the specification
    (e.g. ``ltl_specification.components.FormulaGroup``); only those of ``droppable_sections`` are candidates.
    Returns None when ``spec`` is realizable. Raises ``SynthesisCancelledError`` when ``limits``
    stop it (each realizability check keeps to them).
    """
    sections = droppable_sections(robotics_semantics)
    guarantees = [group for group in groups if group.section in sections]
    outcomes: dict[tuple[int, ...], bool] = {}

    def unrealizable(subset: list[G]) -> bool:
        key = tuple(sorted(id(group) for group in subset))
        if key not in outcomes:
            outcomes[key] = not is_realizable(restrict_guarantees(spec, subset, sections), robotics_semantics,
                                              limits)
        return outcomes[key]

    if not unrealizable(guarantees):
        return None
    core = ddmin(guarantees, unrealizable)
    return Core(core, restrict_guarantees(spec, core, sections), len(outcomes))


def environment_play(spec: GR1Specification, robotics_semantics: bool = True, length: int = 8,
                     limits: Limits = Limits()) -> list[dict[str, bool | None]]:
    """Up to ``length`` steps of a play the environment wins (``spec`` must be unrealizable).

    The environment follows its counter-strategy. The system plays its best: among the
    plays of at most ``length`` steps it takes one in which the most inputs (the outcomes
    the robot brought about) became true at some step, the shortest such one, and it never
    walks into a position where it would be stuck (a deadlock). So the play shows how far
    an eager system gets and where it gets stuck. Each step maps every proposition to its
    value (0/1).
    """
    game = SymbolicGame(spec, None, limits.interrupt())
    environment = solve_environment_game(Solver(game))
    nodes = extract_counterstrategy(game, environment, robotics_semantics)['nodes']
    if '0' not in nodes:
        return []
    n_inputs = len(game.inputs)

    def stuck(name: str) -> bool:
        node = nodes[name]
        return None in node['state'] or not node['trans']

    def usable(name: str) -> bool:
        return not stuck(name) and not all(stuck(str(t)) for t in nodes[name]['trans'])

    def achieved(name: str) -> frozenset[int]:
        return frozenset(i for i, value in enumerate(nodes[name]['state'][:n_inputs]) if value)

    # Breadth-first over (node, inputs seen true so far): the first path found to a
    # combination is a shortest one; a play may revisit nodes, but not combinations.
    start = ('0', achieved('0'))
    parent: dict[tuple[str, frozenset[int]], tuple[str, frozenset[int]] | None] = {start: None}
    frontier = [start]
    best = start
    for _ in range(length - 1):
        following = []
        for key in frontier:
            game.interrupt.check()
            for successor in (str(t) for t in nodes[key[0]]['trans']):
                if not usable(successor):
                    continue
                child = (successor, key[1] | achieved(successor))
                if child not in parent and len(parent) < MAX_PLAY_SEARCH:
                    parent[child] = key
                    following.append(child)
                    if len(child[1]) > len(best[1]):
                        best = child
        frontier = following
    path = []
    at: tuple[str, frozenset[int]] | None = best
    while at is not None:
        path.append(at[0])
        at = parent[at]
    return [dict(zip(game.variables, nodes[name]['state'])) for name in reversed(path)]
