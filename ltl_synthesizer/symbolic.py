"""The symbolic game: a GR(1) specification translated into BDDs on CUDD (``dd.cudd``).

Every proposition ``p`` has a current copy ``p`` and a next-step copy ``p'``, declared next to
each other (interleaved order), so that renaming current <-> next is cheap. Safety sections are
kept as lists of conjunct BDDs ("partitioned transition relations"): the enforceable
predecessor conjoins them one by one and quantifies each next-step variable as soon as no
remaining conjunct mentions it (early quantification), which keeps intermediate BDDs small.
"""

from __future__ import annotations

import threading
import time
import warnings
from dataclasses import dataclass, field
from functools import cached_property

from dd import cudd

from respec.ltl import And, Const, Formula, Iff, Implies, Next, Not, Or, Var, children, to_infix
from respec.spec import GR1Specification

from ltl_synthesizer.errors import (InvalidFormulaError, SynthesisCancelled, SynthesisMemoryExceeded,
                                    UnknownPropositionError)

# Conjuncts are merged into clusters while the cluster's BDD stays below this many nodes: fewer,
# larger relational products are faster than many tiny ones, up to a point (see bench/): 1000
# rather than 2500 makes multi-goal ATLAS tasks 20-40% faster and leaves the chain family as is.
DEFAULT_CLUSTER_LIMIT = 1000

# CUDD's cache and unique tables grow on demand; starting small keeps tiny specs fast.
MEMORY_ESTIMATE = 64 * 2**20


def primed(name: str) -> str:
    """The name of the next-step copy of a proposition."""
    return name + "'"


@dataclass
class Options:
    """Tuning switches of the symbolic engine (defaults are the measured best; see bench/)."""

    reordering: bool = False  # dynamic reordering throughout (CUDD's automatic sifting)
    sift_once: bool = True  # one sifting pass after the relations are built (see SymbolicGame)
    cluster_limit: int = DEFAULT_CLUSTER_LIMIT
    variable_order: str = 'affinity'  # 'affinity' (co-occurrence) or 'declared'
    reachable_only: bool = True  # solve only on positions reachable from the initial ones
    chained_sweeps: bool = True  # Gauss-Seidel Y sweeps (see gr1._attract_to_goal)


class Interrupt:
    """Stops a synthesis on request: a cancel flag, a deadline (a ``time.monotonic()``
    instant) and a memory limit (bytes of BDD memory). Every long loop of the synthesizer
    (translation, fixpoints, reachability, extraction, explanation, parsing) calls
    ``check()``, so a synthesis stops within a few milliseconds of the request, beyond the
    duration of one BDD operation. The object is also a plain callable (for respec's parser).
    """

    MEMORY_CHECK_SECONDS = 0.05  # reading CUDD's statistics costs microseconds; not every step

    def __init__(self, cancel: threading.Event | None = None, deadline: float | None = None,
                 memory_limit: int | None = None):
        self.cancel = cancel
        self.deadline = deadline
        self.memory_limit = memory_limit
        self.memory_in_use = None  # a callable returning bytes, set by the game that is watched
        self._memory_checked_at = 0.0

    def check(self) -> None:
        if self.cancel is not None and self.cancel.is_set():
            raise SynthesisCancelled('cancelled')
        now = time.monotonic()
        if self.deadline is not None and now >= self.deadline:
            raise SynthesisCancelled('timeout')
        if self.memory_limit is not None and self.memory_in_use is not None \
                and now - self._memory_checked_at >= self.MEMORY_CHECK_SECONDS:
            self._memory_checked_at = now
            if self.memory_in_use() > self.memory_limit:
                raise memory_exceeded(self.memory_limit)

    __call__ = check


def memory_exceeded(limit: int) -> SynthesisMemoryExceeded:
    return SynthesisMemoryExceeded(
        f'synthesis needs more than its memory limit of {limit / 2**20:.0f} MB '
        '(memory_limit); simplify the specification or raise the limit', item='memory_limit')


@dataclass
class _Partition:
    """A conjunction of clusters with, per cluster, the variables to quantify right after it."""

    clusters: list = field(default_factory=list)
    quantify_after: list = field(default_factory=list)
    quantify_first: set = field(default_factory=set)


class SymbolicGame:
    """BDD encoding of a GR(1) game; the current-step variables are the game positions."""

    def __init__(self, spec: GR1Specification, options: Options | None = None,
                 interrupt: Interrupt | None = None):
        self.spec = spec
        self.options = options or Options()
        self.interrupt = interrupt or Interrupt(None, None)
        self.inputs = list(spec.env_props)
        self.outputs = list(spec.sys_props)
        _check_declarations(spec)
        self.variables = self.inputs + self.outputs
        self.bdd = cudd.BDD(memory_estimate=MEMORY_ESTIMATE)
        self.bdd.configure(reordering=False)
        if self.interrupt.memory_limit is not None:
            # CUDD fails an operation that would go beyond this (synthesize reports it);
            # the interrupt's own check catches slower growth between operations.
            self.bdd.configure(max_memory=self.interrupt.memory_limit)
            self.interrupt.memory_in_use = self.memory_in_use
        for name in _variable_order(spec, self.options.variable_order):
            self.bdd.declare(name, primed(name))
            self.bdd.group({name: 2})  # reordering keeps each pair adjacent (cheap renaming)
        self.to_next = {name: primed(name) for name in self.variables}
        self.to_current = {primed(name): name for name in self.variables}
        self.next_inputs = [primed(name) for name in self.inputs]
        self.next_outputs = [primed(name) for name in self.outputs]
        self.true = self.bdd.true
        self.false = self.bdd.false
        self._moves_into = {}
        self._previous_moves_into = {}

        self.env_init = self.conjunction(spec.env_init, 'env_init')
        self.sys_init = self.conjunction(spec.sys_init, 'sys_init')
        self.env_trans_parts = [self.translate(f, 'env_trans') for f in spec.env_trans]
        self.sys_trans_parts = [self.translate(f, 'sys_trans') for f in spec.sys_trans]
        # slugs treats an empty liveness section as the single goal TRUE.
        self.env_goals = [self.translate(f, 'env_liveness') for f in spec.env_liveness] or [self.true]
        self.sys_goals = [self.translate(f, 'sys_liveness') for f in spec.sys_liveness] or [self.true]
        # Assumptions that constrain no next output factor out of exists y' (see gr1).
        self.env_goal_ignores_outputs = [not self.mentions_next_outputs(goal)
                                         for goal in self.env_goals]
        self.env_partition = self._partition(self.env_trans_parts, set(self.next_inputs))
        self.sys_partition = self._partition(self.sys_trans_parts, set(self.next_outputs))
        if self.options.sift_once:
            # The static order cannot know that e.g. a memory proposition belongs next to its
            # action's activation and outcomes; one sifting pass on the relations finds such
            # placements (3x faster multi-goal solving) for a few milliseconds.
            self.bdd.reorder()
        if self.options.reordering:
            self.bdd.configure(reordering=True)
        # Positions outside this set never matter (see relevant_positions); set by the solver.
        self.care = self.true

    # --- translation ----------------------------------------------------------------------

    def translate(self, formula: Formula, section: str) -> cudd.Function:
        """The BDD of a formula over current and next-step variables."""
        self.interrupt.check()
        if section in ('env_init', 'sys_init') and _mentions_next(formula):
            raise InvalidFormulaError(
                f'{section}: initial conditions cannot refer to the next step: {to_infix(formula)}',
                item=to_infix(formula))
        if section == 'env_trans' and _next_outputs(formula, set(self.outputs)):
            # slugs rejects this too: the environment moves first and cannot see the system's move.
            bad = sorted(_next_outputs(formula, set(self.outputs)))[0]
            raise InvalidFormulaError(
                f"env_trans: environment assumption refers to the next value of output '{bad}': "
                f'{to_infix(formula)}', item=bad)
        return self._translate(formula, primed_context=False, section=section)

    def _translate(self, formula: Formula, primed_context: bool, section: str):
        if isinstance(formula, Const):
            return self.true if formula.value else self.false
        if isinstance(formula, Var):
            if formula.name not in self.to_next:
                raise UnknownPropositionError(
                    f"{section}: unknown proposition '{formula.name}' (declare it as an input or output)",
                    item=formula.name)
            return self.bdd.var(primed(formula.name) if primed_context else formula.name)
        if isinstance(formula, Next):
            if primed_context:
                raise InvalidFormulaError(f'{section}: nested next is not GR(1): {to_infix(formula)}',
                                          item=to_infix(formula))
            return self._translate(formula.arg, True, section)
        args = [self._translate(child, primed_context, section) for child in children(formula)]
        if isinstance(formula, Not):
            return ~args[0]
        if isinstance(formula, And):
            result = self.true
            for arg in args:
                result &= arg
            return result
        if isinstance(formula, Or):
            result = self.false
            for arg in args:
                result |= arg
            return result
        if isinstance(formula, Implies):
            return ~args[0] | args[1]
        if isinstance(formula, Iff):
            return self.bdd.apply('<=>', args[0], args[1])
        raise InvalidFormulaError(f'{section}: not a formula: {formula!r}', item=repr(formula))

    def conjunction(self, formulas, section: str):
        result = self.true
        for formula in formulas:
            result &= self.translate(formula, section)
        return result

    # --- renaming and quantification ------------------------------------------------------

    def prime(self, u):
        """The set ``u`` of positions (current variables only) as a condition on the next step."""
        # Swapping each pair is exact here (u has no next-step variables) and much cheaper
        # than dd's general renaming, which composes a substitution vector.
        return self.bdd._swap(u, self.to_next)

    def unprime(self, u):
        """A condition on next-step variables only, as a set of current positions."""
        return self.bdd._swap(u, self.to_next)

    def swap_steps(self, u):
        """``u`` with current and next-step variables exchanged (any set of transitions)."""
        return self.bdd._swap(u, self.to_next)

    def env_trans(self):
        """The monolithic environment safety relation (for explicit extraction and explanations)."""
        return _conjoin(self.true, self.env_partition.clusters)

    def sys_trans(self):
        return _conjoin(self.true, self.sys_partition.clusters)

    def _partition(self, parts, quantified: set[str]) -> _Partition:
        clusters = _cluster(self.bdd, parts, self.options.cluster_limit, self.interrupt)
        supports = [self.bdd.support(c) & quantified for c in clusters]
        partition = _Partition(clusters=clusters)
        for index, support in enumerate(supports):
            later = set().union(*supports[index + 1:])
            partition.quantify_after.append(support - later)
        partition.quantify_first = quantified - set().union(*supports)
        return partition

    def _relational_product(self, target, partition: _Partition):
        """``exists q. target & /\\ clusters`` with each variable quantified as early as possible."""
        # Quantifying a variable the target lacks is a no-op, so there is no need to ask for
        # the target's support (a Python set built on every call, ~10% of small solves).
        result = self.bdd.exist(partition.quantify_first, target) \
            if partition.quantify_first else target
        for cluster, quantify in zip(partition.clusters, partition.quantify_after):
            result = cudd.and_exists(result, cluster, quantify)
        return result

    def system_can_respond(self, target):
        """``exists y'. sys_trans & target``: the system has a legal move into ``target``."""
        return self._relational_product(target, self.sys_partition)

    def system_can_move_into(self, positions):
        """``exists y'. sys_trans & positions'``, memoized: the assumptions' inner fixpoints
        share start sets, and each outer iteration restarts them from the previous one's
        results (see ``start_outer_iteration``)."""
        key = int(positions)
        found = self._moves_into.get(key) or self._previous_moves_into.get(key)
        if found is None or found[0] != positions:
            # Only moves from relevant positions matter, and they lead to relevant positions:
            # the target may take any values elsewhere, so take CUDD's simplest such BDD.
            target = positions if self.care == self.true else cudd.restrict(positions, self.care)
            found = (positions, self.system_can_respond(self.prime(target)))
        self._moves_into[key] = found
        return found[1]

    def start_outer_iteration(self):
        """Keep the memo of the previous outer (Z) iteration only: older sets do not recur."""
        self._previous_moves_into = self._moves_into
        self._moves_into = {}

    def enforce(self, responses):
        """Positions where every next input allowed by env_trans has a response:
        ``forall x'. env_trans -> responses`` (``responses`` over current vars and next inputs)."""
        self.interrupt.check()
        return ~self._relational_product(~responses, self.env_partition)

    def cox(self, target):
        """Enforceable predecessor of a set of transitions (slugs' "cox").

        Positions from which, for every next input allowed by env_trans, the system has a next
        output allowed by sys_trans such that the transition lies in ``target``:
        ``forall x'. env_trans -> exists y'. sys_trans & target``.
        """
        return self.enforce(self.system_can_respond(target))

    @cached_property
    def legal_moves(self):
        """env_trans & sys_trans as one BDD (built on first use, after the sifting pass)."""
        return _conjoin(self.env_trans(), self.sys_partition.clusters)

    def successors(self, positions):
        """The positions one legal move away from ``positions``."""
        # The whole relation at once: measured 2x faster than its clusters with early
        # quantification here, where every current variable is quantified.
        return self.unprime(cudd.and_exists(positions, self.legal_moves, self.variables))

    def relevant_positions(self):
        """The positions the solver must decide: all, or those reachable from the initial ones.

        Every legal move (env_trans and sys_trans) from a reachable position leads to a
        reachable one, so the game restricted to them has the same winner there; the
        solver's sets then stay within them, and targets are simplified outside them.
        """
        if self.options.reachable_only:
            self.care = self.reachable_positions()
        return self.care

    def reachable_positions(self):
        """Positions reachable from the initial ones (env_init & sys_init, either semantics)
        by moves allowed by both safety sections: a breadth-first search on frontiers."""
        reached = frontier = self.env_init & self.sys_init
        while frontier != self.false:
            self.interrupt.check()
            frontier = self.successors(frontier) & ~reached
            reached |= frontier
        return reached

    def mentions_next_outputs(self, u) -> bool:
        return bool(self.bdd.support(u) & set(self.next_outputs))

    def env_cox(self, target):
        """The environment's enforceable transitions: ``env_trans & forall y'. sys_trans -> target``.

        Returned over current variables and next inputs (the environment's choice).
        """
        self.interrupt.check()
        system_escapes = self._relational_product(~target, self.sys_partition)
        return _conjoin(~system_escapes, self.env_partition.clusters)

    def exist_next_inputs(self, u):
        return self.bdd.exist(self.next_inputs, u)

    # --- concrete valuations --------------------------------------------------------------

    def cube(self, valuation: dict[str, bool]):
        return self.bdd.cube(valuation)

    def pick(self, u, names):
        """The smallest assignment to ``names`` (False before True, in the given order) within ``u``.

        Returns ``(assignment, u restricted to it)``; ``u`` must not be FALSE. Independent of
        the BDD variable order, hence deterministic even with dynamic reordering.
        """
        self.interrupt.check()
        assignment = {}
        for name in names:
            variable = self.bdd.var(name)
            low = u & ~variable
            if low != self.false:
                u, assignment[name] = low, False
            else:
                u, assignment[name] = u & variable, True
        return assignment, u

    def evaluate(self, u, assignment: dict[str, bool]) -> bool:
        # Substituting only the variables u depends on is much cheaper for small u.
        support = self.bdd.support(u)
        value = self.bdd.let({name: assignment[name] for name in support}, u) if support else u
        if value == self.true:
            return True
        if value == self.false:
            return False
        raise ValueError('assignment does not fix every variable of the function')

    def memory_in_use(self) -> int:
        """Bytes CUDD holds for this game's BDDs."""
        return int(self._cudd_statistics()['mem'])

    def _cudd_statistics(self) -> dict:
        with warnings.catch_warnings():  # dd warns that 'mem' is now in bytes; we know
            warnings.simplefilter('ignore')
            return self.bdd.statistics()

    def statistics(self) -> dict:
        stats = self._cudd_statistics()
        return {'bdd_nodes': stats.get('n_nodes'), 'peak_bdd_nodes': stats.get('peak_nodes'),
                'reorderings': stats.get('n_reorderings'), 'bdd_memory_bytes': stats.get('mem')}


def _conjoin(start, parts):
    result = start
    for part in parts:
        result &= part
    return result


def _cluster(bdd, parts, limit: int, interrupt: Interrupt):
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


def _check_declarations(spec: GR1Specification) -> None:
    seen = set()
    for name in list(spec.env_props) + list(spec.sys_props):
        if not isinstance(name, str) or not name or name.endswith("'"):
            raise UnknownPropositionError(f'invalid proposition name {name!r}', item=name)
        if name in seen:
            raise UnknownPropositionError(f"proposition '{name}' is declared twice", item=name)
        seen.add(name)


def _mentions_next(formula: Formula) -> bool:
    return isinstance(formula, Next) or any(_mentions_next(c) for c in children(formula))


def _next_outputs(formula: Formula, outputs: set[str], under_next: bool = False) -> set[str]:
    if isinstance(formula, Var):
        return {formula.name} if under_next and formula.name in outputs else set()
    under_next = under_next or isinstance(formula, Next)
    found = set()
    for child in children(formula):
        found |= _next_outputs(child, outputs, under_next)
    return found


def _formula_variables(formula: Formula, found: list[str], seen: set[str]) -> None:
    if isinstance(formula, Var):
        if formula.name not in seen:
            seen.add(formula.name)
            found.append(formula.name)
    for child in children(formula):
        _formula_variables(child, found, seen)


def _variable_order(spec: GR1Specification, strategy: str) -> list[str]:
    """Static variable order: declared, or 'affinity' (first appearance in the safety formulas).

    Propositions used together (an action's activation and its outcomes) then sit together,
    which keeps the transition relations small.
    """
    declared = list(spec.env_props) + list(spec.sys_props)
    if strategy == 'declared':
        return declared
    if strategy != 'affinity':
        raise ValueError(f'unknown variable order {strategy!r}')
    found, seen = [], set()
    known = set(declared)
    for formula in list(spec.sys_trans) + list(spec.env_trans) + list(spec.sys_liveness) \
            + list(spec.env_liveness) + list(spec.env_init) + list(spec.sys_init):
        _formula_variables(formula, found, seen)
    order = [name for name in found if name in known]
    return order + [name for name in declared if name not in seen]
