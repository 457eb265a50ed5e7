"""The engine's switches (``Options``) and the automatic policy that sets those left open: a
``Plan`` read off the game's shape before solving, and a ``ReorderingSwitch`` that follows
the solve's progress. Both look at sizes and node counts, never at time: the same request
always takes the same path."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol, Sequence

from ltl_synthesizer.cudd_import import Node


class GameShape(Protocol):
    """What the policy reads of a game (``ltl_synthesizer.symbolic.SymbolicGame``, which
    imports this module)."""

    @property
    def variables(self) -> Sequence[str]: ...
    @property
    def has_liveness(self) -> bool: ...
    @property
    def relation_nodes(self) -> int: ...
    @property
    def sys_goals(self) -> Sequence[Node]: ...
    @property
    def bdd(self) -> Any: ...
    def statistics(self) -> dict[str, Any]: ...

# Conjuncts are merged into clusters while the cluster's BDD stays below this many nodes: fewer,
# larger relational products are faster than many tiny ones, up to a point (see bench/): 1000
# rather than 2500 makes multi-goal ATLAS tasks 20-40% faster and leaves the chain family as is.
DEFAULT_CLUSTER_LIMIT = 1000
# Pure safety games (no liveness) only ever compute the enforceable predecessor of the whole
# safe set, quantifying every next-step variable at once; there fewer, larger products win
# (bench/bench_gr1_families.py: moving obstacle 48x48 20.3 -> 16.4 s, whose environment
# relation becomes one BDD of 1,559 nodes; cinderella n8c3 b15 40 -> 27 s, n7c1 b20 7.7 ->
# 4.8 s; factory 7x5 as fast). Games with liveness goals keep the smaller limit: their inner
# fixpoints and strategies take many products of small sets, and AMBA's solve times jump
# 20x on some larger limits.
SAFETY_GAME_CLUSTER_LIMIT = 3000

# Up to this many propositions a game solves in a few tens of milliseconds, and neither the
# sifting pass nor the reachability search pays for itself (bench/bench_synthesizer.py
# --compare: paper tasks 35-45% faster without them, 5-goal ATLAS tasks and 12-action chains
# 10-45% slower); 'automatic' options switch them on above it.
SMALL_GAME_PROPOSITIONS = 36

# ... and the sifting pass also runs on smaller games whose safety relations have this many nodes.
SIFTED_RELATION_NODES = 1000

# Automatic dynamic reordering. Sifting from the start, as slugs does, is 2-5x faster on
# games with several system goals (a Y/X family per goal stays alive and one order must suit
# them all: AMBA). Elsewhere it starts on the static order and switches sifting on only
# once this many BDD nodes are alive: ATLAS tasks (one goal, an assumption per action) would
# lose up to 2x to sifting, cinderella (many variables, small BDDs) 4x
# (bench/bench_gr1_families.py, bench_goals.py).
DYNAMIC_REORDERING_FROM_NODES = 100_000
# A game whose safety relations, in the static order, have at most this many BDD nodes per
# proposition is "compact": the static order (ordering.static_order) already keeps every
# conjunct small, so the sifting pass has little to find, and the reachability restriction
# only complicates the iterates (capability robots, issue 44: a chain of 80 capabilities
# solves in 3.6 s without them, 11 s with the restriction, over 100 s with the dynamic sifting
# that its 10^5 live nodes set off). Compact games sift only once the BDDs hold
# COMPACT_REORDERING_FROM_NODES nodes (some 400 MB: a guard against running out of memory).
COMPACT_NODES_PER_PROPOSITION = 20
# With one system goal the static order stays in place (no sifting from the start), and the
# bound is looser: the chain of 160 capabilities retrying on failure has 30 nodes per
# proposition and solves in 7.7 s as compact, 13.4 s with the sifting pass (and over 60 s with
# the reachability restriction and dynamic sifting). Several goals keep 20: GenBuf of 64
# senders (25.5) sifts from the start anyway, and is 25% slower as compact.
COMPACT_ONE_GOAL_NODES_PER_PROPOSITION = 32
COMPACT_REORDERING_FROM_NODES = 10_000_000
# With many system goals (GenBuf: one per sender), dynamic sifting from the start still pays,
# but CUDD's default growth bound (1.2: a variable keeps moving while the BDDs are at most
# 20% larger) makes each pass over the many variables cost most of the solve (GenBuf 48
# senders: 4.2 of 7.0 s, 64 senders unrealizable 21 of 26 s). A 2% bound stops each
# variable's walk early: 2.1 s and 8.8 s. AMBA (at most 11 goals) keeps the default: its
# sifting results, and so its solve times, vary by up to 4x with the bound.
MANY_SYSTEM_GOALS = 16
MANY_GOALS_SIFTING_GROWTH = 1.02
REORDERING_CHECK_PERIOD = 4
# Reading CUDD's statistics scans its unique table and cache (a 1.4M-node chain of 80
# capabilities: 8 of its 12 s went to looking every 4 steps); the period between looks
# doubles up to this many steps, so a solve that stays small pays for few looks.
REORDERING_CHECK_MAX_PERIOD = 256
# Small pure safety games over wide integers (moving obstacle: few variables, large BDDs) need
# sifting too, but CUDD's automatic sifting strikes in the middle of a relational product,
# when its intermediate results (7x the fixpoint iterate) are alive, and so costs the most
# and may even strike during the confirming last iteration (48x48: 17 s of 55). They sift
# between iterations instead, whenever the BDD an iteration is about to quantify (the
# system's responses, which sifting then fits) has grown by this factor since the last
# sifting, from CUDD's own first threshold: moving obstacle 24x24 2x and 48x48 1.7x faster.
SIFT_BETWEEN_ITERATIONS_GROWTH = 2
SIFT_BETWEEN_ITERATIONS_FROM_NODES = 4004
# Large pure safety games (cinderella: many variables) need few iterations over large BDDs,
# after the one sifting pass: further sifting never pays (n7c1 b20: 7 s without, 13 s once
# large, 8 s between iterations; n7c2 b16: 29, 41, 36 s).

# The reordering modes of a plan.
NEVER, FROM_START, ONCE_LARGE, BETWEEN_ITERATIONS = 'never', 'from start', 'once large', \
    'between iterations'


@dataclass
class Options:
    """Tuning switches of the symbolic engine (defaults are the measured best; see bench/)."""

    # Dynamic reordering (CUDD's automatic sifting); None = automatic: from the start with
    # several system goals or on small safety games, else past DYNAMIC_REORDERING_FROM_NODES.
    reordering: bool | None = None
    # One sifting pass after the relations are built; None = automatic: on for games of more
    # than SMALL_GAME_PROPOSITIONS propositions or with large safety relations.
    sift_once: bool | None = None
    # Most BDD nodes in a cluster of conjoined safety formulas; None = automatic:
    # SAFETY_GAME_CLUSTER_LIMIT for pure safety games, else DEFAULT_CLUSTER_LIMIT.
    cluster_limit: int | None = None
    # 'structure' (ordering.static_order: integers compared interleaved, FORCE over the
    # conjuncts), 'affinity' (order of first use in the formulas) or 'declared'.
    variable_order: str = 'structure'
    # Solve only on positions reachable from the initial ones; None = automatic: on for games
    # of more than SMALL_GAME_PROPOSITIONS propositions with some liveness goal.
    reachable_only: bool | None = None
    chained_sweeps: bool = True  # Gauss-Seidel Y sweeps (see gr1._attract_to_goal)
    # sys_trans's formulas over current inputs only stay out of the relational products
    # (SymbolicGame.sys_invariant): moving obstacle 48x48 2x, evasion 48x16 3x faster.
    invariant_apart: bool = True


@dataclass(frozen=True)
class Plan:
    """How to solve one game: every automatic option decided."""

    sift_once: bool
    reachable_only: bool
    reordering: str  # NEVER, FROM_START, ONCE_LARGE or BETWEEN_ITERATIONS
    sifting_growth: float | None = None  # CUDD's max growth during sifting; None: its default
    reordering_from_nodes: int = DYNAMIC_REORDERING_FROM_NODES  # ONCE_LARGE's threshold


def cluster_limit(has_liveness: bool, options: Options) -> int:
    """The cluster limit for a game with or without liveness goals (see SAFETY_GAME_CLUSTER_LIMIT)."""
    if options.cluster_limit is not None:
        return options.cluster_limit
    return DEFAULT_CLUSTER_LIMIT if has_liveness else SAFETY_GAME_CLUSTER_LIMIT


def plan(game: GameShape, options: Options) -> Plan:
    """The plan for ``game``, from its shape and the options the caller set."""
    large = len(game.variables) > SMALL_GAME_PROPOSITIONS
    compact = is_compact(game, options)
    # A pure safety game is solved by one greatest fixpoint, no dearer than the
    # reachability search itself (cinderella: 0.01 s solving after 2.5 s of search).
    reachable_only = large and game.has_liveness and not compact
    # The static order cannot know that e.g. a memory proposition belongs next to its
    # action's activation and outcomes; one sifting pass on the relations finds such
    # placements (3x faster multi-goal solving) for a few milliseconds. Few propositions but
    # wide integers (grids, counters) also make large relations, whose bits the static order
    # cannot place well (moving obstacle 16x16: 3x faster).
    sift_once = (large or game.relation_nodes >= SIFTED_RELATION_NODES) and not compact
    if options.reordering is not None:
        reordering = FROM_START if options.reordering else NEVER
    elif len(game.sys_goals) > 1:
        reordering = FROM_START
    elif not game.has_liveness:
        reordering = NEVER if large else BETWEEN_ITERATIONS
    else:
        reordering = ONCE_LARGE
    many_goals = reordering == FROM_START and len(game.sys_goals) > MANY_SYSTEM_GOALS
    return Plan(
        sift_once=sift_once if options.sift_once is None else options.sift_once,
        reachable_only=reachable_only if options.reachable_only is None else options.reachable_only,
        reordering=reordering,
        sifting_growth=MANY_GOALS_SIFTING_GROWTH if many_goals else None,
        reordering_from_nodes=COMPACT_REORDERING_FROM_NODES if compact else DYNAMIC_REORDERING_FROM_NODES)


def is_compact(game: GameShape, options: Options) -> bool:
    """Whether the static order left the safety relations compact (see
    COMPACT_NODES_PER_PROPOSITION); only the structural order is trusted to."""
    per_proposition = COMPACT_ONE_GOAL_NODES_PER_PROPOSITION if len(game.sys_goals) <= 1 \
        else COMPACT_NODES_PER_PROPOSITION
    return options.variable_order == 'structure' and \
        game.relation_nodes <= per_proposition * len(game.variables)


class ReorderingSwitch:
    """Variable reordering during a solve, as planned (``Plan.reordering``): CUDD's dynamic
    sifting from the start or never; switched on once more than DYNAMIC_REORDERING_FROM_NODES
    BDD nodes are alive (ONCE_LARGE); or one sifting pass between fixpoint iterations when
    the BDDs have grown (BETWEEN_ITERATIONS). ``observe(responses)`` is called before every
    enforceable-predecessor step with the BDD it is about to quantify."""

    def __init__(self, game: GameShape, planned: str, from_nodes: int = DYNAMIC_REORDERING_FROM_NODES) -> None:
        self.game = game
        self.planned = planned
        self.from_nodes = from_nodes
        self.on = planned in (FROM_START, BETWEEN_ITERATIONS)
        self._observed = 0
        self._period = self._next_look = REORDERING_CHECK_PERIOD
        self._sifted_at = SIFT_BETWEEN_ITERATIONS_FROM_NODES
        if planned == FROM_START:
            game.bdd.configure(reordering=True)

    def observe(self, responses: Node) -> None:
        if not self.on and self.planned == ONCE_LARGE:
            # Reading CUDD's statistics scans its unique table: look every few steps only.
            self._observed += 1
            if self._observed >= self._next_look:
                self._next_look += self._period
                self._period = min(2 * self._period, REORDERING_CHECK_MAX_PERIOD)
                if self.game.statistics()['bdd_nodes'] > self.from_nodes:
                    self.on = True
                    self.game.bdd.configure(reordering=True)
        elif self.on and self.planned == BETWEEN_ITERATIONS:
            # The DAG size of one BDD, not the manager's node count (a scan of its tables).
            if len(responses) > SIFT_BETWEEN_ITERATIONS_GROWTH * self._sifted_at:
                self.game.bdd.reorder()
                self._sifted_at = max(len(responses), SIFT_BETWEEN_ITERATIONS_FROM_NODES)

    def stop(self) -> None:
        """No more reordering: after the solve, the work is many small operations on BDDs
        already built, which a late sifting pass (seconds) would not repay (slugs also stops
        reordering before extracting strategies)."""
        self.game.bdd.configure(reordering=False)
        self.on, self.planned = False, NEVER
