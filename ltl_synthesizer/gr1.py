"""GR(1) game solving: the three nested fixpoints of Piterman, Pnueli and Sa'ar, on transitions.

Liveness goals may mention next-step variables (slugs' extended fragment, needed by the
paper's fairness formulas (7) and (13)), so goals are sets of *transitions*: the fixpoints
compute which positions can enforce a transition into a target set of transitions
(``SymbolicGame.cox``), exactly as slugs' ``computeWinningPositions`` does:

    nu Z. /\\_j mu Y. \\/_i nu X. cox( (G_j & Z') | Y' | (!A_i & X') )

with G_j the system goals (guarantees) and A_i the environment goals (assumptions).
The counter-game (for unrealizable specifications) is the dual, from the environment's side.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from functools import cached_property
from typing import Callable

from ltl_synthesizer.cudd_import import Node, cudd
from ltl_synthesizer.policy import Options, ReorderingSwitch, plan
from ltl_synthesizer.symbolic import SymbolicGame
from respec.vocabulary.errors import ControlFlowSignal


class Solver:
    """What the solver keeps while it works on one game (the game itself stays stateless):
    the plan chosen for it (``policy.plan``), the positions that matter (``care``), the
    reordering switch, and a memo of the system's predecessors of recent position sets."""

    def __init__(self, game: SymbolicGame, options: Options | None = None) -> None:
        self.game = game
        self.options = options or Options()
        self.plan = plan(game, self.options)
        if self.plan.sifting_growth is not None:
            game.bdd.configure(max_growth=self.plan.sifting_growth)
        if self.plan.sift_once:
            game.bdd.reorder()
        self.reordering = ReorderingSwitch(game, self.plan.reordering, self.plan.reordering_from_nodes)
        self._moves_into: dict[int, tuple[Node, Node]] = {}
        self._previous_moves_into: dict[int, tuple[Node, Node]] = {}
        self._may_violate: dict[int, Node] = {}
        self.waits = _waits(self) if self.options.chained_sweeps else ungrouped(self)
        # See _sweep_order.
        self.alternating_sweeps = self.options.chained_sweeps and len(game.env_goals) > GROUPED_WAITS_FROM

    @cached_property
    def care(self) -> Node:
        """The positions the solver must decide: all, or those reachable from the initial ones.

        Every legal move (env_trans and sys_trans) from a reachable position leads to a
        reachable one, so the game restricted to them has the same winner there; the
        solver's sets then stay within them, and targets are simplified outside them.
        """
        return self.game.reachable_positions() if self.plan.reachable_only else self.game.true

    def enforce(self, responses: Node) -> Node:
        """``game.enforce``, with the reordering switch watching the BDDs grow."""
        self.reordering.observe(responses)
        return self.game.enforce(responses)

    def system_can_move_into(self, positions: Node, remember: bool = True) -> Node:
        """``exists y'. sys_trans & positions'``, memoized: the assumptions' inner fixpoints
        share start sets, and each outer iteration restarts them from the previous one's
        results (see ``start_outer_iteration``). Sets that never recur (``remember=False``)
        stay out of the memo: kept alive, they would slow every garbage collection and
        reordering (the safety fixpoint of moving obstacle 24x24: 2.5x slower)."""
        key = int(positions)
        found = self._moves_into.get(key) or self._previous_moves_into.get(key)
        if found is None or found[0] != positions:
            # Only moves from relevant positions matter, and they lead to relevant positions:
            # the target may take any values elsewhere, so take CUDD's simplest such BDD.
            care = self.care
            target = positions if care == self.game.true else cudd.restrict(positions, care)
            found = (positions, self.game.system_can_respond(self.game.prime(target)))
        if remember:
            self._moves_into[key] = found
        return found[1]

    def may_violate(self, assumption_index: int) -> Node:
        """The positions from which some transition violates environment goal i:
        ``exists next. !A_i`` (for a capability's fairness, the positions where it runs)."""
        found = self._may_violate.get(assumption_index)
        if found is None:
            game = self.game
            found = self._may_violate[assumption_index] = game.bdd.exist(
                game.next_inputs + game.next_outputs, ~game.env_goals[assumption_index])
        return found

    def may_violate_any(self, wait: _Wait) -> Node:
        """The positions from which some transition violates one of the wait's assumptions."""
        found = self.game.false
        for index in wait.members:
            found |= self.may_violate(index)
        return found

    def start_outer_iteration(self) -> None:
        """Keep the memo of the previous outer (Z) iteration only: older sets do not recur."""
        self._previous_moves_into = self._moves_into
        self._moves_into = {}


@dataclass
class AttractorStep:
    """One inner fixpoint of the last Z iteration: for goal ``goal_index``, the transitions
    ``(goal & Z') | closer' | (waiting' & !assumption)`` the system may take. Kept as parts
    (the fixpoints never need the whole, and strategy extraction only a few moves of it)."""

    goal_index: int
    goal_transitions: Node
    closer: Node
    waiting: Node
    assumption: Node
    responses: Node  # exists y'. sys_trans & transitions: where the step offers a move


@dataclass
class SystemSolution:
    """Winning positions and the attractor steps of the last Z iteration, per goal in the order
    of increasing distance to the goal (the "mY" ranks): a strategy for goal j takes, at each
    position, the first step that offers a move."""

    winning: Node
    attractor_steps: list[AttractorStep] = field(default_factory=list)
    complete: bool = True  # False when the solver stopped early because the initial check failed
    reachable_only: bool = False  # decided on the reachable positions only (Solver.care)


class WarmStarts:
    """Upper bounds for the inner fixpoints X, from the previous Z iteration.

    Everything is monotone in Z, and Z only shrinks, so the X computed at the same place
    (goal, sweep, assumption) of the previous Z iteration bounds this iteration's X from
    above; beyond the previous iteration's sweeps, its last X for (goal, assumption) does.
    """

    def __init__(self) -> None:
        self._previous: dict[tuple[int, int, int], Node] = {}
        self._previous_last: dict[tuple[int, int], Node] = {}
        self._current: dict[tuple[int, int, int], Node] = {}
        self._current_last: dict[tuple[int, int], Node] = {}

    def upper_bound(self, goal_index: int, sweep: int, assumption_index: int, winning: Node) -> Node:
        """The best known upper bound of this X, within ``winning`` (Z)."""
        bound = self._previous.get((goal_index, sweep, assumption_index),
                                   self._previous_last.get((goal_index, assumption_index)))
        return winning if bound is None else bound & winning

    def record(self, goal_index: int, sweep: int, assumption_index: int, waiting: Node) -> None:
        self._current[(goal_index, sweep, assumption_index)] = waiting
        self._current_last[(goal_index, assumption_index)] = waiting

    def next_outer_iteration(self) -> None:
        self._previous, self._previous_last = self._current, self._current_last
        self._current, self._current_last = {}, {}


def solve_system_game(solver: Solver, stop_when_losing: Callable[[Node], bool] | None = None) -> SystemSolution:
    """The system's winning positions: the greatest fixpoint Z over all goals,

        nu Z. /\\_j mu Y. \\/_i nu X. cox( (G_j & Z') | Y' | (!A_i & X') ).

    ``stop_when_losing(Z)`` may return False to stop early: Z only shrinks, so once the
    initial positions are not covered they never will be (used to reject quickly). It is
    also asked after each goal within an iteration, whenever the intersection of the goals'
    attractors so far has shrunk: that intersection already bounds the winning positions
    from above (each attractor is monotone in Z, and Z bounds them), so a loss seen there
    is final one goal early instead of one whole iteration late.
    """
    # Z may start from any upper bound of the winning positions (the iterates still descend
    # to the same greatest fixpoint). The safety game's winning positions are one, and cheap;
    # on typical specifications they are exactly the winning positions, so the first Z
    # iteration is already the confirming one (instead of two or three full iterations).
    game = solver.game
    reachable_only = solver.plan.reachable_only
    # Every set below stays within the positions not lost at once, where the system's
    # responses need not repeat its invariant (see SymbolicGame.system_can_respond).
    safe = _safe_positions(solver, solver.care & game.not_lost_at_once, stop_when_losing)
    if stop_when_losing is not None and not stop_when_losing(safe):
        return SystemSolution(safe, [], complete=False, reachable_only=reachable_only)
    try:
        return _solve_from(solver, safe, stop_when_losing)
    except _GroupTooLarge:
        solver.waits = ungrouped(solver)
        return _solve_from(solver, safe, stop_when_losing)


def _solve_from(solver: Solver, safe: Node, stop_when_losing: Callable[[Node], bool] | None) -> SystemSolution:
    """The outer fixpoint Z of ``solve_system_game``, from the safe positions."""
    game = solver.game
    reachable_only = solver.plan.reachable_only
    Z = safe
    warm_starts = WarmStarts()
    while True:
        solver.start_outer_iteration()
        attractor_steps = []
        next_Z = game.true
        for goal_index, goal in enumerate(game.sys_goals):
            attracted, steps = _attract_to_goal(solver, goal_index, goal, Z, warm_starts)
            attractor_steps += steps
            narrowed = next_Z & attracted
            if narrowed != next_Z and stop_when_losing is not None \
                    and not stop_when_losing(narrowed):
                return SystemSolution(narrowed, [], complete=False, reachable_only=reachable_only)
            next_Z = narrowed
            if next_Z == game.false:
                break
        if next_Z == Z:
            return SystemSolution(Z, attractor_steps, reachable_only=reachable_only)
        Z = next_Z
        warm_starts.next_outer_iteration()
        if stop_when_losing is not None and not stop_when_losing(Z):
            return SystemSolution(Z, [], complete=False, reachable_only=reachable_only)


def _safe_positions(solver: Solver, within: Node, stop_when_losing: Callable[[Node], bool] | None = None) -> Node:
    """``nu Z. within & cox(Z')``: positions (among ``within``) from which the system can keep
    both safety sections forever. Every winning position is one (a winning strategy stays
    among them). Stops early (returning the current Z) once ``stop_when_losing`` says the
    initial positions are lost: Z only shrinks."""
    Z = within
    while True:
        next_Z = Z & solver.enforce(solver.system_can_move_into(Z, remember=False))
        if next_Z == Z or (stop_when_losing is not None and not stop_when_losing(next_Z)):
            return next_Z
        Z = next_Z


def _attract_to_goal(solver: Solver, goal_index: int, goal: Node, winning: Node,
                     warm_starts: WarmStarts) -> tuple[Node, list[AttractorStep]]:
    """Middle least fixpoint Y: positions that can force goal ``goal`` (into Z = ``winning``)
    or keep some environment goal false forever while staying safe.

    Returns Y and its attractor steps by increasing rank. With ``chained_sweeps`` each inner
    fixpoint already uses the positions the previous ones of the same sweep added (a
    Gauss-Seidel iteration: the same least fixpoint, reached in far fewer sweeps, and each
    step's ``closer`` set still only holds positions of lower rank), in the order of
    ``_sweep_order``.
    """
    game = solver.game
    chained = solver.options.chained_sweeps
    goal_transitions = goal & game.prime(winning)
    reach_goal = game.system_can_respond(goal_transitions)
    Y = game.false
    can_move_towards_goal = reach_goal  # moves into the goal, or into Y
    steps = []
    moving_on = _NoWaitingPositions(solver)
    for sweep in itertools.count():
        Y_before_sweep = Y
        for wait in _sweep_order(solver, sweep):
            assumption_index, assumption = wait.index, wait.assumption
            start = warm_starts.upper_bound(goal_index, sweep, assumption_index, winning)
            if chained and moving_on.adds_nothing(start, Y, can_move_towards_goal, wait):
                # X lies within Y: no step, and Y & start bounds X from above (see the class).
                warm_starts.record(goal_index, sweep, assumption_index, Y & start)
                continue
            X, responses = _wait_for_assumption(
                solver, can_move_towards_goal, assumption, start, wait.ignores_outputs)
            warm_starts.record(goal_index, sweep, assumption_index, X)
            closer = Y if chained else Y_before_sweep
            new_positions = X & ~Y != game.false
            if len(wait.members) > 1:
                _check_group(X, new_positions, sweep, len(game.variables))
            if new_positions or not chained:  # else every position of X has a lower rank
                steps.append(AttractorStep(
                    goal_index, goal_transitions, closer, X, assumption, responses))
            Y |= X
            if chained and new_positions:
                # The product distributes over the union, and X's own product is memoized.
                can_move_towards_goal |= solver.system_can_move_into(X)
        # Y never leaves Z (every X starts inside it): once Y is Z, the next sweep could
        # only confirm it, at the price of all the inner fixpoints.
        if Y == Y_before_sweep or Y == winning:
            return Y, steps
        if not chained:
            can_move_towards_goal = reach_goal | solver.system_can_move_into(Y)
    raise AssertionError('unreachable: the sweeps (itertools.count) end only by the return above')


def _sweep_order(solver: Solver, sweep: int) -> list[_Wait]:
    """The inner fixpoints of one sweep, in order: with many environment goals, every other
    sweep runs backwards (a symmetric Gauss-Seidel iteration).

    A chained sweep finds in one pass the positions whose waits come after those of the
    positions they move on to; the rest waits for the next sweep. A capability robot's
    capabilities are listed in the order they run, and each waits for the next one's
    positions: forwards only, a chain of N capabilities took N sweeps of N fixpoints (the mix
    of 80: 3,157 fixpoints, 9 s), while the backward sweep after the first finds the whole
    chain (237 fixpoints, 0.8 s), whichever way the specification lists it. Where the listed
    order was right already, a backward sweep may cost one more sweep (the fan-out of 160: 3
    sweeps instead of 2). Games with few environment goals keep one direction, and the
    strategies they always had.
    """
    if solver.alternating_sweeps and sweep % 2 == 1:
        return solver.waits[::-1]
    return solver.waits


class _NoWaitingPositions:
    """Tells, before an inner fixpoint X of assumption A is computed, that X adds no position
    to Y, so that it need not be computed (a robot of N capabilities has an assumption per
    capability, and in each sweep only the few whose capability is next can add anything:
    N^2 fixpoints become N^2 of these checks and O(N) fixpoints).

    X = nu X. start & enforce(towards | (!A & X')). At a position from which no transition
    violates A (outside ``exists next. !A``, the positions where A may be violated), the
    waiting term is empty, so there X is within enforce(towards). Hence when neither
    ``start & !Y & may_violate(A)`` nor ``start & !Y & enforce(towards)`` has a position, X
    lies within Y and within start: it adds no step to a chained sweep, and ``Y & start``
    is an upper bound of it for the next Z iteration's warm start.
    """

    def __init__(self, solver: Solver) -> None:
        self.solver = solver
        self._enforced: tuple[Node, Node] | None = None  # (towards, enforce(towards)) for the last towards asked

    def adds_nothing(self, start: Node, Y: Node, towards: Node, wait: _Wait) -> bool:
        outside = start & ~Y
        game = self.solver.game
        if outside == game.false:
            return True
        if outside & self.solver.may_violate_any(wait) != game.false:
            return False
        if self._enforced is None or self._enforced[0] != towards:
            self._enforced = (towards, self.solver.game.enforce(towards))
        return bool(outside & self._enforced[1] == game.false)  # dd's BDDs are Any to mypy


@dataclass
class _Wait:
    """What one inner fixpoint X waits for: the environment goals ``members`` (by index; one,
    or a group, see ``_waits``), violated forever; ``assumption`` is their conjunction (a
    transition violates it when it violates one of them)."""

    index: int  # the first member's: the key of the fixpoint's warm starts
    members: list[int]
    assumption: Node
    ignores_outputs: bool


# Games with more environment goals than this wait for the goals of a group in one inner
# fixpoint (see _waits); with fewer, every goal has its own, and small specifications keep the
# attractor steps, and so the strategies, they always had.
GROUPED_WAITS_FROM = 16


# A group's fixpoint is one per sweep: it pays where its goals' positions are found side by
# side in the first sweeps (the arbiter: any client may be waiting, and one grouped sweep
# finds them all: 64 clients solve in 0.25 s grouped, 4.9 s with 64 fixpoints per sweep).
# Where they follow each other (a chain of capabilities: each capability's positions move on
# to the next one's), the group finds one capability per sweep, N sweeps of a BDD that may
# grow with each (the diamonds of 160: 24 s, 9,000 nodes), while single fixpoints in
# alternating sweeps (_sweep_order) find the chain in two or three (1.9 s). A group that still
# adds positions in this sweep of a goal (counted from 0) is given up, and the solve starts
# again with one fixpoint per assumption.
GROUP_SWEEPS = 3
# ... and a group's X past this many nodes per proposition, at any sweep: a memory guard (where
# the goals' positions combine freely, as in a fan-out, the group's BDD grows with each sweep).
GROUPED_NODES_PER_PROPOSITION = 64


class _GroupTooLarge(ControlFlowSignal):
    """Not an error: a group's fixpoint still adds positions after GROUP_SWEEPS sweeps, or is
    too large (GROUPED_NODES_PER_PROPOSITION); the solve starts again with one fixpoint per
    assumption."""


def _check_group(X: Node, new_positions: bool, sweep: int, propositions: int) -> None:
    """Raise _GroupTooLarge when the group's X of this sweep is too large, or adds positions
    at sweep GROUP_SWEEPS or later."""
    if (new_positions and sweep >= GROUP_SWEEPS) or len(X) > GROUPED_NODES_PER_PROPOSITION * propositions:
        raise _GroupTooLarge()


def ungrouped(solver: Solver) -> list[_Wait]:
    """One inner fixpoint per environment goal."""
    game = solver.game
    return [_Wait(i, [i], goal, game.env_goal_ignores_outputs[i]) for i, goal in enumerate(game.env_goals)]


def _waits(solver: Solver) -> list[_Wait]:
    """The inner fixpoints of a sweep: one per environment goal, except that goals whose
    violations are confined to disjoint parts of the game are waited for together.

    A capability robot has an assumption per capability ("a running capability ends"), and a
    capability can be started again after it ended: at N capabilities the attractor holds
    about N^2/2 kinds of positions (capability i running after j have ended), each added by
    its own goal's fixpoint, so every sweep ran a fixpoint for almost every goal (the chain
    of 80: 3,319 fixpoints, 3 relational products each). Where goal i can be violated only at
    positions M_i = ``exists next. !A_i``, no legal transition ends where two M_i meet, and
    none that violates A_i ends in another goal's M_j, a play that keeps to transitions
    violating some goal of the group from some point on violates one goal forever (from M_i
    it moves on such transitions to M_i, or to where no goal of the group can be violated, and
    so cannot go on; in M_i no other goal can be violated). Then the union of the goals'
    fixpoints is the one fixpoint of ``towards | (!(A_1 & ... & A_k) & X')``: the same Y,
    reached in one fixpoint per sweep, and a strategy that stays in X waits for one goal.
    (A robot's capabilities, which run one after another, are found sooner by single fixpoints
    in alternating sweeps: its group is given up after GROUP_SWEEPS sweeps.)
    """
    game = solver.game
    singles = ungrouped(solver)
    if len(singles) <= GROUPED_WAITS_FROM:
        return singles
    group, covered = [], game.false
    for wait in singles:
        violable = solver.may_violate(wait.index)
        if not _legal_transition_into(game, game.prime(violable & covered)):
            group.append(wait)
            covered |= violable
    group = [wait for wait in group if not _legal_transition_into(
        game, ~wait.assumption & game.prime(covered & ~solver.may_violate(wait.index)))]
    if len(group) < 2:
        return singles
    assumption = game.true
    for wait in group:
        assumption &= wait.assumption
    grouped = _Wait(group[0].index, [wait.index for wait in group], assumption,
                    all(wait.ignores_outputs for wait in group))
    grouped_members = set(grouped.members)
    return [grouped if wait is group[0] else wait for wait in singles
            if wait is group[0] or wait.index not in grouped_members]


def _legal_transition_into(game: SymbolicGame, transitions: Node) -> bool:
    """Whether some transition allowed by both safety sections is among ``transitions``."""
    return bool(game.sys_invariant & ~game.enforce(~game.system_can_respond(transitions)) != game.false)


def _wait_for_assumption(solver: Solver, can_move_towards_goal: Node, assumption: Node, start: Node,
                         system_independent: bool) -> tuple[Node, Node]:
    """Inner greatest fixpoint X: positions that can move towards the goal, or else stay in X
    on transitions that violate environment goal ``assumption``.

    X descends from ``start``, an upper bound of the fixpoint within Z (Z itself, or the
    previous Z iteration's X): positions outside Z lose anyway, so restricting X to Z leaves
    the outer fixpoint unchanged, and X := X & cox(...) reaches the greatest fixpoint below
    any upper bound. Returns X and the system's responses (over current variables and next
    inputs) that keep to these transitions.
    """
    game = solver.game
    if assumption == game.true:
        # No assumption to wait for (no ENV_LIVENESS: slugs' single goal TRUE): the responses
        # do not depend on X, so the first step is the fixpoint. Iterating would only price
        # the moves into ``start`` (a relational product) and confirm it (GenBuf 48 senders
        # without the receivers' fairness: 552 -> 498 products, 895 -> 498 enforcements).
        return start & solver.enforce(can_move_towards_goal), can_move_towards_goal
    X = start
    while True:
        if system_independent:
            # The assumption constrains no next output, so it factors out of exists y'.
            responses = can_move_towards_goal | (~assumption & solver.system_can_move_into(X))
        else:
            responses = can_move_towards_goal | game.system_can_respond(game.prime(X) & ~assumption)
        next_X = X & solver.enforce(responses)
        if next_X == X:
            return X, responses
        X = next_X


@dataclass
class EnvironmentLevel:
    """One iteration k of the environment's outer least fixpoint.

    ``blocking[j]`` is Y_{k,j}: positions where the environment keeps goal j false or drops to
    a lower level. ``moves[j][i]`` lists, by increasing X rank, the environment moves (over
    current variables and next inputs) that work towards its assumption i while doing so.
    """

    below: Node  # Z_{k-1}: positions won at lower levels
    blocking: list[Node] = field(default_factory=list)
    moves: list[list[list[Node]]] = field(default_factory=list)


@dataclass
class EnvironmentSolution:
    """Positions from which the environment wins, with the levels of its attractor."""

    winning: Node
    levels: list[EnvironmentLevel] = field(default_factory=list)


def solve_environment_game(solver: Solver) -> EnvironmentSolution:
    """The dual (counter-strategy) game, as slugs' ``--counterStrategy``:

        mu Z. \\/_j nu Y. /\\_i mu X. env_cox( (Z' | !G_j) & Y' & (X' | A_i) )

    (The solver's memo and care set are the system's: this game uses only its plan.)

    It runs without dynamic reordering, on the order the system game left: its iterates
    are small, but the intermediate BDDs of its products set off sifting pass after pass
    (lift, 64 floors: 8 passes, 6.0 of the game's 7.7 s CPU; the counter-strategy 6.8 ->
    1.6 s, byte for byte the same; GenBuf 32 senders and the gridworlds as fast, GenBuf 48
    senders about 5% slower). slugs sifts through its counter-game and stops only to extract.
    """
    solver.reordering.stop()
    game = solver.game
    winning = game.false
    levels: list[EnvironmentLevel] = []
    while True:
        level = EnvironmentLevel(below=winning)
        next_winning = game.false
        for goal in game.sys_goals:
            blocking, moves = _block_goal(game, goal, winning)
            level.blocking.append(blocking)
            level.moves.append(moves)
            next_winning |= blocking
        if next_winning == winning:
            return EnvironmentSolution(winning, levels)
        levels.append(level)
        winning = next_winning


def _block_goal(game: SymbolicGame, goal: Node, winning: Node) -> tuple[Node, list[list[Node]]]:
    """Middle greatest fixpoint Y: positions where the environment keeps goal ``goal`` false
    (or reaches Z) while satisfying every one of its own goals infinitely often."""
    avoid_goal = ~goal | game.prime(winning)
    blocking = game.true
    while True:
        kept = avoid_goal & game.prime(blocking)
        next_blocking = blocking
        moves = []
        for assumption in game.env_goals:
            reach, reach_moves = _reach_assumption(game, kept, assumption)
            next_blocking &= reach
            moves.append(reach_moves)
        if next_blocking == blocking:
            return blocking, moves
        blocking = next_blocking


def _reach_assumption(game: SymbolicGame, kept: Node, assumption: Node) -> tuple[Node, list[Node]]:
    """Inner least fixpoint X: positions from which the environment reaches a transition that
    satisfies its goal ``assumption`` while keeping within ``kept``."""
    reach = game.false
    steps = []
    while True:
        moves = game.env_cox(kept & (game.prime(reach) | assumption))
        steps.append(moves)
        next_reach = game.exist_next_inputs(moves)
        if next_reach == reach:
            return reach, steps
        reach = next_reach
