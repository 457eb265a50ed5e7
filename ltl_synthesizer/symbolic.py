"""The symbolic game: a GR(1) specification as BDDs on CUDD (``dd.cudd``) and its operators.

Formulas become BDDs in translation.py; this module holds the game built from them. Every
proposition ``p`` has a current copy ``p`` and a next-step copy ``p'``, declared next to
each other (interleaved order), so that renaming current <-> next is cheap. Safety sections are
kept as lists of conjunct BDDs ("partitioned transition relations"): the enforceable
predecessor conjoins them one by one and quantifies each next-step variable as soon as no
remaining conjunct mentions it (early quantification), which keeps intermediate BDDs small.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, Iterable, Mapping

from ltl_synthesizer.cudd_import import Node, cudd

from respec.spec import GR1Specification

from ltl_synthesizer.interrupt import Interrupt
from ltl_synthesizer.ordering import static_order
from ltl_synthesizer.policy import Options, cluster_limit
from ltl_synthesizer.translation import Translator, check_declarations, declare_pair, primed

# CUDD's cache and unique tables grow on demand; starting small keeps tiny specs fast (dd's
# default cache of 262,144 slots alone costs 5-6 ms to set up, a tenth of a paper-size task).
# The memory estimate bounds that growth: past 90% of it CUDD stops enlarging its unique
# table and collects garbage at every chance (64 MiB made moving obstacle 48x48 2x and
# factory 7x5 e10 2x slower); 256 MiB costs under a millisecond to set up (1 GiB: a 16 MB
# allocation, 2-6 ms) and is as fast on the largest family instances.
MEMORY_ESTIMATE = 256 * 2**20
INITIAL_CACHE_SLOTS = 2**14


@dataclass
class _Partition:
    """A conjunction of clusters with, per cluster, the variables to quantify right after it."""

    clusters: list[Node] = field(default_factory=list)
    quantify_after: list[set[str]] = field(default_factory=list)
    quantify_first: set[str] = field(default_factory=set)


class SymbolicGame:
    """BDD encoding of a GR(1) game; the current-step variables are the game positions.

    The game holds the specification's BDDs and stateless operators on them; whatever a
    solver keeps while it works (care set, memo, reordering progress) is the solver's
    (gr1.Solver). ``options`` choose the encoding: variable order and cluster size.
    """

    def __init__(self, spec: GR1Specification, options: Options | None = None,
                 interrupt: Interrupt | None = None) -> None:
        self.spec = spec
        options = options or Options()
        self.interrupt = interrupt or Interrupt(None, None)
        self.inputs = list(spec.env_props)
        self.outputs = list(spec.sys_props)
        check_declarations(spec)
        self.variables = self.inputs + self.outputs
        self.bdd = cudd.BDD(memory_estimate=MEMORY_ESTIMATE, initial_cache_size=INITIAL_CACHE_SLOTS)
        self.bdd.configure(reordering=False)
        if self.interrupt.memory_limit is not None:
            # CUDD fails an operation that would go beyond this (synthesize reports it);
            # the interrupt's own check catches slower growth between operations.
            self.bdd.configure(max_memory=self.interrupt.memory_limit)
        self.to_next = {name: primed(name) for name in self.variables}
        self.to_current = {primed(name): name for name in self.variables}
        self.next_inputs = [primed(name) for name in self.inputs]
        self.next_outputs = [primed(name) for name in self.outputs]
        self.true = self.bdd.true
        self.false = self.bdd.false

        # The static variable order: 'structure' (the default; ordering.static_order: integers
        # compared interleaved, FORCE over the conjuncts), 'declared', or 'affinity':
        # propositions in order of first use in the safety formulas, then the goals and initial
        # conditions (variables are declared as the translator meets them).
        if options.variable_order == 'declared':
            for name in self.variables:
                declare_pair(self.bdd, name)
        elif options.variable_order == 'structure':
            for name in static_order(spec):
                declare_pair(self.bdd, name)
        elif options.variable_order != 'affinity':
            raise ValueError(f'unknown variable order {options.variable_order!r}')
        self.translator = Translator(self.bdd, self.inputs, self.outputs, self.interrupt.check)
        translate = self.translator.translate
        self.sys_trans_parts = [translate(f, 'sys_trans') for f in spec.sys_trans]
        self.env_trans_parts = [translate(f, 'env_trans') for f in spec.env_trans]
        # slugs treats an empty liveness section as the single goal TRUE.
        self.sys_goals = [translate(f, 'sys_liveness') for f in spec.sys_liveness] or [self.true]
        self.env_goals = [translate(f, 'env_liveness') for f in spec.env_liveness] or [self.true]
        self.env_init = self.translator.conjunction(spec.env_init, 'env_init')
        self.sys_init = self.translator.conjunction(spec.sys_init, 'sys_init')
        for name in self.variables:  # the propositions no formula uses
            declare_pair(self.bdd, name)
        self.has_liveness = any(goal != self.true for goal in self.env_goals + self.sys_goals)
        # Assumptions that constrain no next output factor out of exists y' (see gr1).
        self.env_goal_ignores_outputs = [not self.mentions_next_outputs(goal)
                                         for goal in self.env_goals]
        self.env_partition = self._partition(self.env_trans_parts, set(self.next_inputs), options)
        # The system's safety formulas over current inputs only ("never next to the
        # obstacle": a condition the system meets only through its earlier moves) form its
        # invariant, kept out of its relational products (see system_can_respond). Formulas
        # that mention outputs stay in: they prune the responses (ATLAS tasks: 2x slower out).
        current_inputs = set(self.inputs)
        moving_parts = []
        self.sys_invariant = self.true
        for part in self.sys_trans_parts:
            if not options.invariant_apart or not self.bdd.support(part) <= current_inputs:
                moving_parts.append(part)
            else:
                self.sys_invariant &= part
        self.sys_partition = self._partition(moving_parts, set(self.next_outputs), options)
        # The size of the safety relations in the static order (before any reordering).
        self.relation_nodes = len(self.sys_invariant) + sum(
            len(cluster) for cluster in self.env_partition.clusters + self.sys_partition.clusters)

    # --- renaming and quantification ------------------------------------------------------

    def prime(self, u: Node) -> Node:
        """``u`` with every variable exchanged with its next-step copy (x <-> x').

        A set of positions Z becomes Z' (the same set, on the next step), a condition on the
        next step becomes a set of positions, and a set of transitions is reversed in time;
        ``prime(prime(u)) == u``. Swapping each pair is exact for any ``u`` and much cheaper
        than dd's general renaming, which composes a substitution vector.
        """
        return self.bdd._swap(u, self.to_next)  # noqa: SLF001 - exact and cheaper than rename (above)

    def env_trans(self) -> Node:
        """The monolithic environment safety relation (for explicit extraction and explanations)."""
        return _conjoin(self.true, self.env_partition.clusters, self.interrupt)

    def sys_trans(self) -> Node:
        return _conjoin(self.sys_invariant, self.sys_partition.clusters, self.interrupt)

    def _partition(self, parts: list[Node], quantified: set[str], options: Options) -> _Partition:
        clusters = _cluster(self.bdd, parts, cluster_limit(self.has_liveness, options),
                            self.interrupt)
        supports = [self.bdd.support(c) & quantified for c in clusters]
        partition = _Partition(clusters=clusters)
        for index, support in enumerate(supports):
            later = set().union(*supports[index + 1:])
            partition.quantify_after.append(support - later)
        partition.quantify_first = quantified - set().union(*supports)
        return partition

    def _relational_product(self, target: Node, partition: _Partition) -> Node:
        """``exists q. target & /\\ clusters`` with each variable quantified as early as possible."""
        # Quantifying a variable the target lacks is a no-op, so there is no need to ask for
        # the target's support (a Python set built on every call, ~10% of small solves).
        result = self.bdd.exist(partition.quantify_first, target) \
            if partition.quantify_first else target
        for cluster, quantify in zip(partition.clusters, partition.quantify_after):
            result = cudd.and_exists(result, cluster, quantify)
        return result

    def system_can_respond(self, target: Node) -> Node:
        """``exists y'. sys_trans & target``: the system has a legal move into ``target``, at
        the positions that satisfy ``sys_invariant`` (elsewhere the system has no legal move).

        The invariant is left out: conjoined into the result, a relation between integers
        (moving obstacle: robot and obstacle positions) multiplies its size by 7 and the cost
        of the products that follow alike (48x48: 11.4 s of products -> 1.5 s). The solver
        only asks at positions that are not lost at once (``not_lost_at_once``), where the
        answer is the same; ``cox``, ``env_cox``, ``sys_trans`` and ``legal_moves`` are exact.
        """
        return self._relational_product(target, self.sys_partition)

    def enforce(self, responses: Node) -> Node:
        """Positions where every next input allowed by env_trans has a response:
        ``forall x'. env_trans -> responses`` (``responses`` over current vars and next inputs)."""
        self.interrupt.check()
        return ~self._relational_product(~responses, self.env_partition)

    def cox(self, target: Node) -> Node:
        """Enforceable predecessor of a set of transitions (slugs' "cox").

        Positions from which, for every next input allowed by env_trans, the system has a next
        output allowed by sys_trans such that the transition lies in ``target``:
        ``forall x'. env_trans -> exists y'. sys_trans & target``.
        """
        return self.enforce(self.system_can_respond(target)) & self.not_lost_at_once

    @cached_property
    def not_lost_at_once(self) -> Node:
        """Positions where sys_invariant holds or env_trans allows no next input at all.

        Elsewhere the system has no legal move while the environment has one: no
        enforceable predecessor holds there. Since sys_invariant does not depend on the
        next step, ``cox(T) = not_lost_at_once & enforce(system_can_respond(T))``.
        """
        if self.sys_invariant == self.true:
            return self.true
        environment_can_move = self._relational_product(self.true, self.env_partition)
        return self.sys_invariant | ~environment_can_move

    @cached_property
    def legal_moves(self) -> Node:
        """env_trans & sys_trans as one BDD (built on first use, after the sifting pass)."""
        return _conjoin(self.env_trans() & self.sys_invariant, self.sys_partition.clusters,
                        self.interrupt)

    def successors(self, positions: Node) -> Node:
        """The positions one legal move away from ``positions``."""
        # The whole relation at once: measured 2x faster than its clusters with early
        # quantification here, where every current variable is quantified.
        return self.prime(cudd.and_exists(positions, self.legal_moves, self.variables))

    def reachable_positions(self) -> Node:
        """Positions reachable from the initial ones (env_init & sys_init, either semantics)
        by moves allowed by both safety sections: a breadth-first search.

        Each step takes the successors of everything reached so far, not of the last frontier
        only: the reached sets have simple BDDs, the frontiers (their differences) do not,
        and the image of the larger but simpler set is measured 2-3x faster overall.
        """
        reached = self.env_init & self.sys_init
        while True:
            self.interrupt.check()
            grown = reached | self.successors(reached)
            if grown == reached:
                return reached
            reached = grown

    def mentions_next_outputs(self, u: Node) -> bool:
        return bool(self.bdd.support(u) & set(self.next_outputs))

    def env_cox(self, target: Node) -> Node:
        """The environment's enforceable transitions: ``env_trans & forall y'. sys_trans -> target``.

        Returned over current variables and next inputs (the environment's choice).
        """
        self.interrupt.check()
        system_escapes = self.sys_invariant & self._relational_product(~target, self.sys_partition)
        return _conjoin(~system_escapes, self.env_partition.clusters, self.interrupt)

    def exist_next_inputs(self, u: Node) -> Node:
        return self.bdd.exist(self.next_inputs, u)

    # --- concrete valuations --------------------------------------------------------------

    def cube(self, valuation: dict[str, bool]) -> Node:
        return self.bdd.cube(valuation)

    def pick(self, u: Node, names: Iterable[str]) -> tuple[dict[str, bool], Node]:
        """The smallest assignment to ``names`` (False before True, in the given order) within ``u``.

        Returns ``(assignment, u restricted to it)``; ``u`` must not be FALSE. Independent of
        the BDD variable order, hence deterministic even with dynamic reordering.
        """
        self.interrupt.check()
        support = self.bdd.support(u)
        assignment, unconstrained = {}, {}
        for name in names:
            if name not in support:  # u allows both values: the smaller one, without BDD work
                assignment[name] = unconstrained[name] = False
                continue
            variable = self.bdd.var(name)
            low = u & ~variable
            if low != self.false:
                u, assignment[name] = low, False
            else:
                u, assignment[name] = u & variable, True
        return assignment, (u & self.bdd.cube(unconstrained) if unconstrained else u)

    def evaluate(self, u: Node, assignment: Mapping[str, bool | None], support: set[str] | None = None) -> bool:
        """Whether ``assignment`` satisfies ``u``; ``support``, u's support when the caller
        evaluates the same ``u`` many times (finding it walks the whole BDD)."""
        # Substituting only the variables u depends on is much cheaper for small u.
        support = self.bdd.support(u) if support is None else support
        value = self.bdd.let({name: assignment[name] for name in support}, u) if support else u
        if value == self.true:
            return True
        if value == self.false:
            return False
        raise ValueError('assignment does not fix every variable of the function')

    def statistics(self) -> dict[str, Any]:
        with warnings.catch_warnings():  # dd warns that 'mem' is now in bytes; we know
            warnings.simplefilter('ignore')
            stats = self.bdd.statistics()
        return {'bdd_nodes': stats.get('n_nodes'), 'peak_bdd_nodes': stats.get('peak_nodes'),
                'reorderings': stats.get('n_reorderings'), 'bdd_memory_bytes': stats.get('mem')}


def _conjoin(start: Node, parts: Iterable[Node], interrupt: Interrupt) -> Node:
    result = start
    for part in parts:
        interrupt.check()
        result &= part
    return result


def _cluster(bdd: Any, parts: Iterable[Node], limit: int, interrupt: Interrupt) -> list[Node]:
    """Greedily merge consecutive conjuncts while the merged BDD stays under ``limit`` nodes."""
    clusters = []
    current = None
    for part in parts:
        interrupt.check()
        if part == bdd.true:
            continue
        if current is None:
            current = part
            continue
        merged = current & part
        if len(merged) <= limit:
            current = merged
        else:
            clusters.append(current)
            current = part
    if current is not None:
        clusters.append(current)
    return clusters
