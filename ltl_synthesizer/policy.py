"""The engine's switches (``Options``) and the automatic policy that sets those left open: a
``Plan`` read off the game's shape before solving, and a ``ReorderingSwitch`` that follows
the solve's progress. Both look at sizes and node counts, never at time: the same request
always takes the same path."""

from __future__ import annotations

from dataclasses import dataclass

# Conjuncts are merged into clusters while the cluster's BDD stays below this many nodes: fewer,
# larger relational products are faster than many tiny ones, up to a point (see bench/): 1000
# rather than 2500 makes multi-goal ATLAS tasks 20-40% faster and leaves the chain family as is.
DEFAULT_CLUSTER_LIMIT = 1000

# Up to this many propositions a game solves in a few tens of milliseconds, and neither the
# sifting pass nor the reachability search pays for itself (bench/bench_synthesizer.py
# --compare: paper tasks 35-45% faster without them, 5-goal ATLAS tasks and 12-action chains
# 10-45% slower); 'automatic' options switch them on above it.
SMALL_GAME_PROPOSITIONS = 36

# ... and the sifting pass also runs on smaller games whose safety relations have this many nodes.
SIFTED_RELATION_NODES = 1000

# Automatic dynamic reordering. Sifting from the start, as slugs does, is 2-5x faster on
# games with several system goals (a Y/X family per goal stays alive and one order must suit
# them all: AMBA) and on small pure safety games over wide integers (moving obstacle: few
# variables, large BDDs). Elsewhere it starts on the static order and switches sifting on only
# once this many BDD nodes are alive: ATLAS tasks (one goal, an assumption per action) would
# lose up to 2x to sifting, cinderella (many variables, small BDDs) 4x
# (bench/bench_gr1_families.py, bench_goals.py).
DYNAMIC_REORDERING_FROM_NODES = 100_000
REORDERING_CHECK_PERIOD = 4


@dataclass
class Options:
    """Tuning switches of the symbolic engine (defaults are the measured best; see bench/)."""

    # Dynamic reordering (CUDD's automatic sifting); None = automatic: from the start with
    # several system goals or on small safety games, else past DYNAMIC_REORDERING_FROM_NODES.
    reordering: bool | None = None
    # One sifting pass after the relations are built; None = automatic: on for games of more
    # than SMALL_GAME_PROPOSITIONS propositions or with large safety relations.
    sift_once: bool | None = None
    cluster_limit: int = DEFAULT_CLUSTER_LIMIT
    variable_order: str = 'affinity'  # 'affinity' (co-occurrence) or 'declared'
    # Solve only on positions reachable from the initial ones; None = automatic: on for games
    # of more than SMALL_GAME_PROPOSITIONS propositions with some liveness goal.
    reachable_only: bool | None = None
    chained_sweeps: bool = True  # Gauss-Seidel Y sweeps (see gr1._attract_to_goal)


@dataclass(frozen=True)
class Plan:
    """How to solve one game: every automatic option decided."""

    sift_once: bool
    reachable_only: bool
    # True: dynamic reordering from the start; False: never; None: once the BDDs grow large.
    reordering: bool | None


def plan(game, options: Options) -> Plan:
    """The plan for ``game`` (a SymbolicGame), from its shape and the options the caller set."""
    large = len(game.variables) > SMALL_GAME_PROPOSITIONS
    # A pure safety game is solved by one greatest fixpoint, no dearer than the
    # reachability search itself (cinderella: 0.01 s solving after 2.5 s of search).
    reachable_only = large and game.has_liveness
    # The static order cannot know that e.g. a memory proposition belongs next to its
    # action's activation and outcomes; one sifting pass on the relations finds such
    # placements (3x faster multi-goal solving) for a few milliseconds. Few propositions but
    # wide integers (grids, counters) also make large relations, whose bits the static order
    # cannot place well (moving obstacle 16x16: 3x faster).
    sift_once = large or game.relation_nodes >= SIFTED_RELATION_NODES
    sift_from_start = len(game.sys_goals) > 1 or not (large or game.has_liveness)
    return Plan(
        sift_once=sift_once if options.sift_once is None else options.sift_once,
        reachable_only=reachable_only if options.reachable_only is None else options.reachable_only,
        reordering=(True if sift_from_start else None) if options.reordering is None
        else options.reordering)


class ReorderingSwitch:
    """CUDD's dynamic reordering during a solve, as planned: on from the start, never, or
    (``None``) switched on once more than DYNAMIC_REORDERING_FROM_NODES BDD nodes are alive,
    which ``observe()`` (called before every enforceable-predecessor step) looks at."""

    def __init__(self, game, planned: bool | None):
        self.game = game
        self.on = planned is True
        self._watching = planned is None
        self._observed = 0
        if self.on:
            game.bdd.configure(reordering=True)

    def observe(self) -> None:
        if not self._watching:
            return
        # Reading CUDD's statistics scans its unique table: look every few operations only.
        self._observed += 1
        if self._observed % REORDERING_CHECK_PERIOD:
            return
        if self.game.statistics()['bdd_nodes'] > DYNAMIC_REORDERING_FROM_NODES:
            self.on, self._watching = True, False
            self.game.bdd.configure(reordering=True)

    def stop(self) -> None:
        """No more reordering: after the solve, the work is many small operations on BDDs
        already built, which a late sifting pass (seconds) would not repay (slugs also stops
        reordering before extracting strategies)."""
        self.game.bdd.configure(reordering=False)
        self.on = self._watching = False
