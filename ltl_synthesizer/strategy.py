"""Explicit-state strategies and counter-strategies in slugs' JSON shape.

A strategy node is a pair (valuation of all propositions, index of the system goal being
pursued); the node's ``rank`` is that goal index. From node (s, j) the system answers every
environment move allowed by env_trans with the first move of the goal-j attractor (closest
to goal j) allowed by sys_trans; when the transition satisfies goal j the successor pursues
the next goal (skipping further goals the same transition already satisfies, as slugs'
"stuttering avoidance" does). Choices are made by ``SymbolicGame.pick`` (False before True, in
declared order) and nodes are numbered breadth-first from the sorted initial states, so the
result is deterministic.
"""

from __future__ import annotations

from collections import deque
from operator import itemgetter
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Iterator, Mapping

from ltl_synthesizer.cudd_import import Node
from ltl_synthesizer.gr1 import AttractorStep, EnvironmentSolution, SystemSolution
from ltl_synthesizer.symbolic import SymbolicGame

FORMAT_VERSION = 0
#: A node of a counter-strategy: the propositions' values (the outputs None at a deadlock) and its
#: rank (the assumption pursued, the system goal blocked), as ``EnvironmentStrategy.successors`` gives it.
Position = tuple[tuple[bool | None, ...], tuple[int, int]]
SLUGS_VERSION = '0.0.1'


def goal_steps(game: SymbolicGame, solution: SystemSolution) -> list[list[AttractorStep]]:
    """Per system goal, its attractor steps by increasing rank."""
    steps: list[list[AttractorStep]] = [[] for _ in game.sys_goals]
    for step in solution.attractor_steps:
        steps[step.goal_index].append(step)
    return steps


def goal_moves(game: SymbolicGame, steps: _GoalSteps, at_state: Callable[[Node], Node], env_moves: Node,
               legal: Node) -> Node:
    """The positional strategy of one goal at one position: each environment move is answered
    with the moves of the first attractor step (lowest rank) that offers a response.

    ``env_moves`` (env_trans at the position) and ``legal`` (with sys_trans too) are small,
    and every operation here is on them and on the steps' sets at the position
    (``at_state``), so a step costs little. The position is given either as cofactors by its
    state (``at_state``: an _AtState; the moves are then over next-step variables), or as the
    state's cube conjoined with env_moves and legal (``at_state``: ``_unchanged``), cheaper
    for games of few variables (COFACTORED_FROM). Building the strategy relation over all
    positions costs far more than the few positions a strategy visits (seconds on multi-goal
    tasks), and so does the union of the steps' responses that bisecting for the answering
    steps would need.
    Cofactors have no current variables: conjoined with the state's cube instead, every set
    held the cube's chain of nodes, one per current variable (a chain of 160 capabilities:
    322), and making those nodes took most of the extraction. The scan ends at the latest
    at the first step whose waiting set holds the position: that step answers every
    environment move.
    """
    moves = answered = game.false
    unanswered = env_moves
    for step in steps.offering(lambda: unanswered, at_state):
        offered = at_state(step.responses) & env_moves
        new_cases = offered & ~answered
        if new_cases == game.false:
            continue
        moves |= step.transitions_among(new_cases & legal, at_state)
        answered |= offered
        if answered == env_moves:
            break  # every environment move is answered
        unanswered = env_moves & ~answered
    return moves


#: Games of more variables than this extract their strategies on cofactors by the state
#: (goal_moves), those of fewer on the state's cube: a cofactor costs a cube built afresh
#: (about 20 us, most of a gridworld's step), a conjunction with the cube a chain of nodes.
COFACTORED_FROM = 64


def _no_values(state: Mapping[str, bool]) -> tuple[()]:
    return ()


def _unchanged(u: Node) -> Node:
    return u


class _AtState:
    """Sets of transitions cofactored by one position's state (each once), by the values of
    the current variables they mention (``supports``): building the cube of all of them took
    two thirds of a cofactor (48 of 70 us at the sensor chain of 80). The cofactors are
    shared by the positions (``shared``, by set and values): a set mentions a part of the
    state, whose values recur (the sensor chain of 80: 2,154 distinct cofactors of 11,496)."""

    def __init__(self, game: SymbolicGame, state: Mapping[str, bool], supports: _NodeMemo,
                 shared: _Cofactors) -> None:
        self.let, self.state, self.supports, self.shared = game.bdd.let, state, supports, shared
        self.found: dict[int, tuple[Node, Node]] = {}

    def __call__(self, u: Node) -> Node:
        found = self.found.get(int(u))
        if found is None:
            names, values = self.supports(u)
            if not names:
                found = self.found[int(u)] = (u, u)
            else:
                key = (int(u), values(self.state))
                found = self.shared.found.get(key)
                if found is None:
                    found = self.shared.remember(key, (u, self.let(dict(zip(names, key[1])), u)))
                self.found[int(u)] = found
        return found[1]


class _Cofactors:
    """Cofactors of sets by the values of the variables they mention (keyed by the set's node
    and the values, the set kept with its cofactor, so that its node is not reused); forgotten
    all at once beyond ``limit`` entries, to bound the memory of a huge strategy."""

    def __init__(self, limit: int = 2**16) -> None:
        self.limit = limit
        self.found: dict[tuple[int, Any], tuple[Node, Node]] = {}

    def remember(self, key: tuple[int, Any], found: tuple[Node, Node]) -> tuple[Node, Node]:
        if len(self.found) >= self.limit:
            self.found.clear()
        self.found[key] = found
        return found


class _GoalSteps:
    """One goal's attractor steps (``_StepMoves``) by increasing rank, and the unions of the
    responses of halves, quarters, ... of them (built on first use, only for many steps), so
    that a position skips, a range at a time, the steps that offer none of its environment
    moves. A capability robot of N capabilities has O(N^2) steps of which a position uses a
    few: scanning them one by one took most of its extraction (80 capabilities: 3.4 of 4.1 s)."""

    def __init__(self, game: SymbolicGame, steps: list[_StepMoves]) -> None:
        self.game, self.steps = game, steps
        self._unions: dict[tuple[int, int], Node] = {}

    def offering(self, unanswered: Callable[[], Node], at_state: Callable[[Node], Node]) -> Iterator[_StepMoves]:
        """The steps, in order, without ranges none of whose responses meets the environment
        moves ``unanswered()`` (asked again as the scan goes on: the moves no earlier step
        answers; over next-step variables, as the unions cofactored by ``at_state``); a
        skipped step would offer no new case, and goal_moves passes over those."""
        if len(self.steps) <= INDEXED_STEPS:
            yield from self.steps
            return
        stack = [(0, len(self.steps))]
        while stack:
            low, high = stack.pop()
            if at_state(self._union(low, high)) & unanswered() == self.game.false:
                continue
            if high - low <= INDEXED_STEPS:
                yield from self.steps[low:high]
                continue
            middle = (low + high) // 2
            stack += [(middle, high), (low, middle)]

    def _union(self, low: int, high: int) -> Node:
        found = self._unions.get((low, high))
        if found is None:
            if high - low <= INDEXED_STEPS:
                found = self.game.false
                for step in self.steps[low:high]:
                    found |= step.responses
            else:
                middle = (low + high) // 2
                found = self._union(low, middle) | self._union(middle, high)
            self._unions[(low, high)] = found
        return found


# Goals with at most this many attractor steps are scanned step by step (and so are ranges of
# this many steps): an index would cost more than it saves.
INDEXED_STEPS = 16


class _StepMoves:
    """One attractor step (gr1.AttractorStep) as extraction uses it, at many positions: its
    transitions ``(goal & Z') | closer' | (waiting' & !assumption)`` kept as three parts (their
    union is never needed), the position sets primed once, on first use. Priming instead the
    few moves of each position, twice per step and position, cost more (a variable swap is
    about 11 us whatever the size: 0.46 of the 2.4 s of the arbiter with 8 clients)."""

    def __init__(self, game: SymbolicGame, step: AttractorStep) -> None:
        self.game, self.step = game, step
        self.responses = step.responses
        self._primed: tuple[Node, Node] | None = None

    def transitions_among(self, moves: Node, at_state: Callable[[Node], Node]) -> Node:
        """The ``moves`` (a small set of next steps from one position, over next-step
        variables) that are transitions of this step from there (``at_state``: the
        position's cofactors)."""
        if self._primed is None:
            step = self.step
            self._primed = (self.game.prime(step.closer),
                            self.game.prime(step.waiting) & ~step.assumption)
        into_closer, into_waiting = self._primed
        return (moves & at_state(self.step.goal_transitions)) | (moves & into_closer) | \
            (moves & at_state(into_waiting))


@dataclass
class StrategyPiece:
    """The moves of one attractor step: at the positions and environment moves of ``offered``
    (over current variables and next inputs; those no step of lower rank offers), every
    system move allowed by sys_trans into ``target`` (transitions, over current and next
    variables)."""

    offered: Node
    target: Node


@dataclass
class SymbolicStrategy:
    """The strategy as relations: on the positions ``winning``, while it pursues system goal
    j, the system may take any move of the pieces ``pieces[j]`` (their union, with sys_trans).
    Kept as pieces: their union conjoined with sys_trans is a far larger BDD than all of
    them together (factory 5x5: 7.3 million nodes), and nothing needs it whole."""

    winning: Node
    pieces: list[list[StrategyPiece]]


def symbolic_strategy(game: SymbolicGame, solution: SystemSolution) -> SymbolicStrategy:
    """The strategy as relations, one list of pieces per system goal j: from each winning
    position, for each environment move, the moves allowed by sys_trans of the first
    attractor step (lowest rank) that offers one -- the moves ``goal_moves`` chooses among,
    at every position at once. Every such move reaches the goal, a lower rank, or stays at
    its rank on a transition that violates the step's assumption, so any choice among them
    wins (checked independently by bench/strategy_check.py). For analysis and checks, not
    for extraction."""
    pieces = []
    for steps in goal_steps(game, solution):
        answered = game.false
        goal_pieces = []
        for step in steps:
            game.interrupt.check()
            offered = step.responses & ~answered
            if offered == game.false:
                continue
            target = step.goal_transitions | game.prime(step.closer) | \
                (game.prime(step.waiting) & ~step.assumption)
            goal_pieces.append(StrategyPiece(offered, target))
            answered |= step.responses
        pieces.append(goal_pieces)
    return SymbolicStrategy(solution.winning, pieces)


def enumerate_states(game: SymbolicGame, states: Node, names: Iterable[str],
                     limit: int | None = None) -> list[dict[str, bool]]:
    """The assignments to ``names`` in ``states`` (all, or the first ``limit``), smallest first
    (``states`` must depend only on names)."""
    found: list[dict[str, bool]] = []
    while states != game.false and (limit is None or len(found) < limit):
        assignment, single = game.pick(states, names)
        found.append(assignment)
        states &= ~single
    return found


def _successor_goal(game: SymbolicGame, goals: list[Node], rank: int, transition: Mapping[str, bool | None],
                    supports: list[set[str]] | None = None) -> int:
    """The goal pursued after ``transition``: advance past every goal it satisfies
    (``supports``: the goals' supports, when known)."""
    goal = rank
    first_try = True
    while (goal != rank or first_try) and game.evaluate(goals[goal], transition,
                                                        supports[goal] if supports else None):
        goal = (goal + 1) % len(goals)
        first_try = False
    return goal


class _Responses:
    """One response per environment move in a position's ``moves`` (over next-step variables),
    as the key of the successor node (``_node_key``: the code of the next variables' values
    and the goal pursued next), in increasing order of the next inputs (False before True, in
    declared order): for each next input valuation the smallest output valuation -- what
    repeated ``pick`` over inputs then outputs would choose. The choice is made for all inputs
    at once (``_smallest_responses``: a few BDD operations per output, not per move), split by
    the goal pursued next (a few BDD operations per goal, not an evaluation per move), then
    read off cube by cube. The choices and the valuations of each BDD are remembered:
    positions share them (the arbiter with 8 clients: 7,972 distinct moves at 11,264
    positions; a lift with 8 floors: 2,284 at 7,041)."""

    def __init__(self, game: SymbolicGame) -> None:
        self.game, self.goals = game, len(game.sys_goals)
        names = game.next_inputs + game.next_outputs
        self._smallest = _NodeMemo(lambda moves: _smallest_responses(game, moves))
        # Outputs the responses leave unmentioned are False (see _smallest_responses).
        self._codes = _NodeMemo(lambda part: _codes(game, part, names, set(game.next_inputs)))

    def __call__(self, moves: Node, goals_here: '_GoalsAt', rank: int) -> list[int]:
        chosen = self._smallest(moves)
        if chosen == self.game.false:
            return []
        goals = self.goals
        keys, parts = [], 0
        for next_rank, part in goals_here.split_by_successor_goal(chosen, rank):
            keys += [code * goals + next_rank for code in self._codes(part)]  # as _node_key
            parts += 1
        if parts > 1:  # each part's codes are in order already
            keys.sort()  # one response per input valuation: the codes never tie
        return keys


def _node_key(code: int, rank: int, goals: int) -> int:
    """A strategy node (values coded as ``_codes`` does, goal pursued) as one integer, in the
    order of its values: hashed and compared far faster than a tuple of booleans (numbering
    3.1 million edges took most of the extraction of 7 free inputs)."""
    return code * goals + rank


class _NodeMemo:
    """A function of BDDs with its results remembered by node (the BDD is kept with its result,
    so its node is not reused for another); forgotten all at once beyond ``limit`` entries, to
    bound the memory a huge strategy takes."""

    def __init__(self, function: Callable[[Node], Any], limit: int = 2**16) -> None:
        self.function, self.limit = function, limit
        self.found: dict[int, tuple[Node, Any]] = {}

    def __call__(self, u: Node) -> Any:
        found = self.found.get(int(u))
        if found is None:
            if len(self.found) >= self.limit:
                self.found.clear()
            found = self.found[int(u)] = (u, self.function(u))
        return found[1]


def _codes(game: SymbolicGame, u: Node, names: list[str], either: set[str]) -> list[int]:
    """The valuations of ``names`` in ``u`` (a BDD over them), increasing, each coded as the
    integer whose bits are the values, the first name's the most significant (so codes
    compare as the tuples of values do, False before True), read cube by cube: a name of
    ``either`` that ``u`` leaves free takes both values, any other is False."""
    support = game.bdd.support(u)
    bit_of = {name: 1 << (len(names) - 1 - index) for index, name in enumerate(names)}
    free = [bit_of[name] for name in names if name in either and name not in support]
    codes = []
    for cube in game.bdd._pick_iter(u):  # noqa: SLF001 - dd.cudd's cube iterator without the public copy of each cube
        # The cube's True names (a capability robot's moves: a few of hundreds).
        found = [sum([bit_of.get(name, 0) for name, value in cube.items() if value])]
        for bit in free:  # each free name doubles the valuations
            found += [code | bit for code in found]
        codes += found
    codes.sort()
    return codes


#: Initial states read off at once up to this many; more are enumerated one at a time.
MAX_INITIAL_CODES = 2**16


def _initial_codes(game: SymbolicGame, initial: Node) -> Iterable[int]:
    """The codes (``_codes``) of the initial positions, smallest first. Beyond
    MAX_INITIAL_CODES, one at a time, each after a look at the limits: reading off a huge set
    at once (2^200 positions of a runaway specification) could not be stopped."""
    variables = game.variables
    if game.bdd.count(initial, nvars=len(variables)) <= MAX_INITIAL_CODES:
        return _codes(game, initial, variables, set(variables))
    bits = [1 << (len(variables) - 1 - index) for index in range(len(variables))]
    return (sum(bit for bit, name in zip(bits, variables) if state[name])
            for state in enumerate_states(game, initial, variables))


def _values(code: int, count: int) -> tuple[bool, ...]:
    """The ``count`` values (booleans) that ``code`` codes (see ``_codes``)."""
    return tuple(map('1'.__eq__, format(code, f'0{count}b')))  # its binary digits, first name first


def _smallest_responses(game: SymbolicGame, moves: Node) -> Node:
    """``moves`` narrowed to the smallest output valuation of each input valuation, the outputs
    decided in declared order (False when ``moves`` allows it, as ``SymbolicGame.pick``); the
    outputs ``moves`` leaves free stay unmentioned (they are read as False). Output k may be
    False where some move with the earlier outputs' choices and output k False exists (the
    later outputs quantified). An output the moves already fix (all False, or all True) needs
    no quantification: skipping it made this 2-4x faster (arbiter, moving obstacle)."""
    bdd = game.bdd
    support = bdd.support(moves)
    decided = [name for name in game.next_outputs if name in support]
    # Few outputs are all tested one by one (a gridworld's 9: the search costs more).
    free = _free_names(game, moves, decided) if len(decided) > FREE_NAMES_SEARCHED_FROM else set(decided)
    chosen = moves
    for index, name in enumerate(decided):
        if name not in free:
            continue  # every move (and so every chosen one) has the same value
        low_moves = chosen & ~bdd.var(name)
        if low_moves == chosen or low_moves == game.false:
            continue
        can_be_low = bdd.exist(decided[index:], low_moves)
        chosen = bdd.ite(can_be_low, low_moves, chosen)
    return chosen


#: From this many outputs on, _smallest_responses first finds those its moves leave free.
FREE_NAMES_SEARCHED_FROM = 32


def _free_names(game: SymbolicGame, u: Node, names: list[str]) -> set[str]:
    """The ``names`` that take both values in ``u`` (not FALSE): those of one of its cubes
    that leaves them out, and those whose literal in that cube ``u`` does not imply: read off
    its assignments when it has few, else found a half at a time. Testing the names one by one
    cost most of the responses' choice (a chain of 160 capabilities: 322 outputs per position,
    of which 2-3 free), and so did the halves' cubes (each over all variables: six times the
    reading of a chain's 1-3 assignments)."""
    bdd = game.bdd
    assignments = bdd._pick_iter(u)  # noqa: SLF001 - dd.cudd's cube iterator (as _codes)
    sample = next(assignments)
    free = {name for name in names if name not in sample}
    # A literal that every assignment (over u's support) has is one u implies: read a few
    # of them first (a capability robot's moves have 1-3), and search only if there are more.
    common = set(sample.items())
    read_all = False
    for _ in range(FREE_NAMES_READ):
        assignment = next(assignments, None)
        if assignment is None:
            read_all = True
            break
        common.intersection_update(assignment.items())
    free |= {name for name in names if name in sample and (name, sample[name]) not in common}
    if read_all:
        return free
    stack = [[name for name in names if name in sample and name not in free]]
    while stack:
        group = stack.pop()
        if not group or u & ~bdd.cube({name: sample[name] for name in group}) == game.false:
            continue  # u implies the group's literals: none is free
        if len(group) == 1:
            free.add(group[0])
            continue
        middle = len(group) // 2
        stack += [group[:middle], group[middle:]]
    return free


#: _free_names reads up to this many more assignments before it searches.
FREE_NAMES_READ = 8


class _GoalsAt:
    """Goals (the system's, or the environment's assumptions) cofactored by one position's
    state (and, for the environment, its chosen input), so that the position's transitions
    are split by the rest of their next step alone."""

    def __init__(self, game: SymbolicGame, state: Mapping[str, bool | None], goals: list[Node],
                 supports: list[list[str]] | None = None) -> None:
        self.game, self.state, self.goals, self.supports = game, state, goals, supports
        self.cofactors: dict[int, Node] = {}

    def cofactor(self, goal: int) -> Node:
        """Goal ``goal`` cofactored by the state (by the variables it mentions, when their
        list ``supports[goal]`` is known: a cube of a few variables, not of all)."""
        if goal not in self.cofactors:
            state = self.state if self.supports is None else \
                {name: self.state[name] for name in self.supports[goal]}
            self.cofactors[goal] = self.game.bdd.let(state, self.goals[goal]) if state else self.goals[goal]
        return self.cofactors[goal]

    def split_by_successor_goal(self, following: Node, rank: int) -> Iterator[tuple[int, Node]]:
        """``following`` (next steps of transitions from this position) split by the goal
        pursued after them, as ``_successor_goal`` decides it: pairs (goal, part), each
        non-empty part of the transitions that satisfy goals rank, rank + 1, ... up to (not
        including) that goal; those that satisfy every goal keep pursuing ``rank``."""
        goals = len(self.goals)
        for offset in range(goals):
            goal = (rank + offset) % goals
            satisfied = following & self.cofactor(goal)
            if satisfied != following:
                yield goal, following & ~satisfied
            if satisfied == self.game.false:
                return
            following = satisfied
        yield rank, following


def _moves_from(game: SymbolicGame, state: dict[str, bool]) -> tuple[Node, Node]:
    """The moves from one position allowed by env_trans, and those allowed by both safety
    sections, each as the position's state cube conjoined with the relation."""
    env_moves = game.cube(state)
    for cluster in game.env_partition.clusters:
        env_moves &= cluster
    legal = env_moves & game.sys_invariant
    for cluster in game.sys_partition.clusters:
        legal &= cluster
    return env_moves, legal


class _SafetyAt:
    """The moves from one position allowed by env_trans, and those allowed by both safety
    sections (``moves_from``), each as the relation cofactored by the position's state.

    Each cluster is cofactored by the values of the current variables it mentions, and the
    cofactors (and their conjunctions) are remembered by those values: a cluster mentions a
    part of the state, whose values recur across the strategy's positions (the mix of 80
    capabilities: 10-88 distinct values per cluster over 597 positions). Conjoining the state
    cube with every cluster at every position took half of its extraction."""

    def __init__(self, game: SymbolicGame, limit: int = 2**16) -> None:
        self.game, self.limit = game, limit
        self.env_parts = list(game.env_partition.clusters)
        self.sys_parts = [game.sys_invariant] + list(game.sys_partition.clusters)
        supports = [game.bdd.support(part) for part in self.env_parts + self.sys_parts]
        # The current variables each part mentions, in declared order.
        self.supports = [[name for name in game.variables if name in support] for support in supports]
        # Each reads the values of those variables off a state (of one: the value).
        self._projections: list[Callable[[Mapping[str, bool]], Any]] = [
            itemgetter(*support) if support else _no_values for support in self.supports]
        self._cofactors: dict[tuple[int, Any], Node] = {}
        self._conjunctions: dict[tuple[int, ...], tuple[Node, Node, list[Node]]] = {}

    def moves_from(self, state: Mapping[str, bool]) -> tuple[Node, Node]:
        if len(self._cofactors) + len(self._conjunctions) >= self.limit:
            self._cofactors.clear()  # bounds the memory of a huge strategy
            self._conjunctions.clear()
        parts = [self._cofactor(index, part, state)
                 for index, part in enumerate(self.env_parts + self.sys_parts)]
        key = tuple(int(part) for part in parts)
        found = self._conjunctions.get(key)
        if found is None:
            env_moves = self.game.true
            for part in parts[:len(self.env_parts)]:
                env_moves &= part
            legal = env_moves
            for part in parts[len(self.env_parts):]:
                legal &= part
            # The cofactors are kept with their conjunctions, so that their nodes (the key)
            # are not reused for other functions.
            found = self._conjunctions[key] = (env_moves, legal, parts)
        return found[0], found[1]

    def _cofactor(self, index: int, part: Node, state: Mapping[str, bool]) -> Node:
        support = self.supports[index]
        if not support:
            return part
        values = self._projections[index](state)
        found = self._cofactors.get((index, values))
        if found is None:
            found = self._cofactors[index, values] = \
                self.game.bdd.let({name: state[name] for name in support}, part)
        return found


class _Numbering:
    """Nodes (by a key: valuation and rank) numbered in order of discovery, breadth-first:
    ``queue`` holds the keys of the discovered nodes not yet expanded."""

    def __init__(self) -> None:
        self.index: dict[Any, int] = {}   # a key (an int, or a tuple) -> its number
        self.queue: deque[Any] = deque()

    def number(self, key: Any) -> int:
        found = self.index.get(key)
        if found is None:
            found = self.index[key] = len(self.index)
            self.queue.append(key)
        return found


def _strategy_json(variables: Iterable[str], nodes: Any) -> dict[str, Any]:  # nodes: a dict or an iterator
    return {'version': FORMAT_VERSION, 'slugs': SLUGS_VERSION, 'variables': list(variables),
            'nodes': nodes}


def extract_strategy(game: SymbolicGame, solution: SystemSolution) -> dict[str, Any]:
    """The explicit strategy as slugs' JSON object (``nodes`` keyed by decimal strings)."""
    return _strategy_json(game.variables, dict(strategy_nodes(game, solution)))


def streamed_strategy(game: SymbolicGame, solution: SystemSolution) -> dict[str, Any]:
    """As ``extract_strategy``, but ``nodes`` is an iterator of ``(name, node)`` pairs made as
    they are read (``strategy_json_chunks`` writes them out): memory holds the numbering of
    the nodes, not their edges."""
    return _strategy_json(game.variables, strategy_nodes(game, solution))


def strategy_nodes(game: SymbolicGame, solution: SystemSolution) -> Iterator[tuple[str, dict[str, Any]]]:
    """The strategy's nodes ``(name, node)`` in increasing number (breadth-first order)."""
    steps = [_GoalSteps(game, [_StepMoves(game, step) for step in goal]) for goal in goal_steps(game, solution)]
    variables, goals = game.variables, len(game.sys_goals)
    responses = _Responses(game)
    safety = _SafetyAt(game)
    by_cofactors = len(variables) > COFACTORED_FROM
    # The current variables each step's set mentions (_AtState; the steps' sets live as long
    # as the extraction, and finding a support walks the whole BDD).
    current_supports = _NodeMemo(lambda u: _mentioned(game, u))
    cofactors = _Cofactors()
    # The current variables each goal mentions: cofactoring by them alone (_GoalsAt) saves
    # building a cube of every variable per goal and position.
    goal_supports = [[name for name in variables if name in support]
                     for support in map(game.bdd.support, game.sys_goals)]
    numbering = _Numbering()
    for code in _initial_codes(game, solution.winning & game.env_init & game.sys_init):
        numbering.number(_node_key(code, 0, goals))

    number = numbering.number
    while numbering.queue:
        key = numbering.queue.popleft()
        game.interrupt.check()
        code, rank = divmod(key, goals)
        values = _values(code, len(variables))
        state = dict(zip(variables, values))
        if by_cofactors:
            env_moves, legal = safety.moves_from(state)
            at_state = _AtState(game, state, current_supports, cofactors)
            moves = goal_moves(game, steps[rank], at_state, env_moves, legal)
        else:  # the same moves, from the transitions conjoined with the state's cube
            env_moves, legal = _moves_from(game, state)
            moves = game.bdd.exist(variables, goal_moves(game, steps[rank], _unchanged, env_moves, legal))
        successors = [number(successor) for successor in
                      responses(moves, _GoalsAt(game, state, game.sys_goals, goal_supports), rank)]
        yield str(numbering.index[key]), {
            'rank': rank, 'state': list(map(int, values)), 'trans': successors}


def _mentioned(game: SymbolicGame, u: Node) -> tuple[list[str], Callable[[Mapping[str, bool]], Any]]:
    """The current variables ``u`` mentions, in declared order, and a function reading their
    values off a state (as a tuple)."""
    support = game.bdd.support(u)
    names = [name for name in game.variables if name in support]
    return names, (itemgetter(*names) if len(names) > 1 else lambda state: tuple(state[name] for name in names))


def extract_counterstrategy(game: SymbolicGame, solution: EnvironmentSolution,
                            robotics_semantics: bool, play_length: int | None = None) -> dict[str, Any]:
    """The environment's explicit winning strategy (slugs' ``--counterStrategy`` as JSON).

    A node is (valuation, i, j) and its ``rank`` is ``[i, j]``: the environment works towards
    its assumption i while blocking system goal j (see EnvironmentStrategy). Each node lists
    the system responses allowed by sys_trans to the environment's chosen next input. When the
    environment can pick an input to which no output is allowed by sys_trans, the successor
    is a deadlock node whose outputs are ``null`` and which has no successors.

    With ``play_length``, only one play is unfolded: from the first initial node, always the
    first successor, for at most that many nodes (used to explain unrealizability cheaply);
    its nodes also count the system's responses (``responses``).
    """
    environment = EnvironmentStrategy(game, solution)
    one_play = play_length is not None
    numbering = _Numbering()
    initial = losing_initial_positions(game, solution.winning, robotics_semantics)
    for state in enumerate_states(game, initial, game.variables, limit=1 if one_play else None):
        numbering.number((tuple(state[name] for name in game.variables),
                          (0, environment.first_blockable_goal(state))))
    nodes: dict[str, dict[str, Any]] = {}
    while numbering.queue and not (play_length is not None and len(nodes) >= play_length):  # one_play
        values, rank = numbering.queue.popleft()
        game.interrupt.check()
        node: dict[str, Any] = {'rank': list(rank), 'state': [None if v is None else int(v) for v in values],
                'trans': []}
        nodes[str(numbering.index[(values, rank)])] = node
        if None in values:  # a deadlock node: nothing follows
            continue
        successors = environment.successors(dict(zip(game.variables, values)), rank, one_play)
        if one_play:
            node['responses'] = environment.responses_counted
        node['trans'] = [numbering.number(successor) for successor in successors]
    return _strategy_json(game.variables, nodes)


class EnvironmentStrategy:
    """The environment's winning moves, from the levels of its attractor.

    The position's level k (first iteration of the environment's outer fixpoint that contains
    it) fixes which moves to use; the blocked goal j stays fixed while the play stays on that
    level and is chosen afresh (the first goal blockable there) when it drops to a lower one,
    so no play can satisfy every system goal.
    """

    def __init__(self, game: SymbolicGame, solution: EnvironmentSolution) -> None:
        self.game = game
        self.levels = solution.levels
        self.moves = _first_environment_moves(game, solution)
        self.sys_trans = game.sys_trans()
        # The environment moves that leave the system no output allowed by sys_trans, found
        # once for all positions (per position, three BDD operations more per node).
        self.deadlock_moves = game.env_trans() & ~(game.sys_invariant & game.system_can_respond(game.true))
        self.responses_counted = 0
        # Z_k, the union of level k's blocking sets: the outer least fixpoint's iterates.
        self.won_by_level = []
        for level in self.levels:
            won = game.false
            for blocking in level.blocking:
                won |= blocking
            self.won_by_level.append(won)
        self._levels_found: dict[tuple[bool | None, ...], int] = {}
        self._goals_found: dict[tuple[tuple[bool | None, ...], int], int] = {}
        # Supports of the sets evaluated at every node (finding one walks its whole BDD).
        self._won_supports = [game.bdd.support(won) for won in self.won_by_level]
        self._blocking_supports: dict[tuple[int, int], set[str]] = {}
        self._env_goal_supports = [game.bdd.support(goal) for goal in game.env_goals]

    def level_of(self, state: Mapping[str, bool | None] | None, values: tuple[bool | None, ...] | None = None) -> int:
        """The first level whose blocking sets contain the position (``values``: its
        variables' values in order, when known). Z_k grows with k (the iterates of a least
        fixpoint), so a binary search over the Z_k finds it: a few evaluations per state
        instead of one per level and goal (remembered per state: each node's level is asked
        again by its predecessors)."""
        if values is None:
            assert state is not None  # one of the two is given
            values = tuple(state[name] for name in self.game.variables)
        key = values
        found = self._levels_found.get(key)
        if found is None:
            state = dict(zip(self.game.variables, values)) if state is None else state
            low, high = 0, len(self.won_by_level) - 1
            if not self._won_at(high, state):
                raise ValueError('the position is not won by the environment')
            while low < high:
                middle = (low + high) // 2
                if self._won_at(middle, state):
                    high = middle
                else:
                    low = middle + 1
            found = self._levels_found[key] = low
        return found

    def first_blockable_goal(self, state: Mapping[str, bool | None] | None, level: int | None = None,
                             values: tuple[bool | None, ...] | None = None) -> int:
        """The first goal the environment can block at the position (on its level),
        remembered per position: many transitions lead to the same one."""
        if values is None:
            assert state is not None  # one of the two is given
            values = tuple(state[name] for name in self.game.variables)
        level = self.level_of(state, values) if level is None else level
        key = (values, level)
        found = self._goals_found.get(key)
        if found is None:
            state = dict(zip(self.game.variables, values)) if state is None else state
            found = self._goals_found[key] = next(
                j for j, blocking in enumerate(self.levels[level].blocking)
                if self.game.evaluate(blocking, state, self._blocking_support(level, j)))
        return found

    def _won_at(self, level: int, state: Mapping[str, bool | None]) -> bool:
        return self.game.evaluate(self.won_by_level[level], state, self._won_supports[level])

    def _blocking_support(self, level: int, goal: int) -> set[str]:
        support = self._blocking_supports.get((level, goal))
        if support is None:
            support = self._blocking_supports[level, goal] = \
                self.game.bdd.support(self.levels[level].blocking[goal])
        return support

    def successors(self, state: Mapping[str, bool | None], rank: tuple[int, int], only_first: bool) -> list[Position]:
        """The successor nodes (values, rank) of node (state, rank): a deadlock node when the
        environment can leave the system no legal output, else one per system response to
        the environment's chosen input (only the first with ``only_first``)."""
        game = self.game
        deadlock = self._deadlock_input(state)
        if deadlock is not None:
            return [(deadlock, rank)]
        allowed_sys = game.bdd.let(state, self.sys_trans)
        assumption, goal = rank
        level = self.level_of(state)
        moves = game.bdd.let(state, self.moves[level][goal][assumption])
        chosen_input, input_cube = game.pick(moves, game.next_inputs)
        responses = input_cube & allowed_sys
        if only_first:  # the one-play explanation says how many answers the system had
            self.responses_counted = int(game.bdd.count(game.bdd.exist(game.next_inputs, responses),
                                                        nvars=len(game.next_outputs)))
        input_values = tuple(chosen_input[name] for name in game.next_inputs)
        successors: list[Position] = []
        for output_values, next_assumption in self._responses(state, chosen_input, responses, assumption,
                                                              only_first):
            next_values = input_values + output_values
            next_level = self.level_of(None, next_values)
            next_goal = goal if next_level == level else self.first_blockable_goal(None, next_level, next_values)
            successors.append((next_values, (next_assumption, next_goal)))
        return successors

    def _responses(self, state: Mapping[str, bool | None], chosen_input: dict[str, bool], responses: Node,
                   assumption: int,
                   only_first: bool) -> list[tuple[tuple[bool, ...], int]]:
        """The system's responses to the chosen input (output values, in next_outputs order,
        smallest first: False before True, in declared order, as repeated ``pick``s would
        give) with the assumption pursued after each; only the first with ``only_first``.
        The responses are split by that assumption symbolically (a few BDD operations per
        assumption) and read off cube by cube: per response, evaluating the assumptions and
        picking the outputs cost most of a small counter-strategy's extraction."""
        game = self.game
        if responses == game.false:
            return []
        if only_first:
            choice = game.pick(responses, game.next_outputs)[0]
            transition = {**state, **chosen_input, **choice}
            return [(tuple(choice[name] for name in game.next_outputs),
                     _successor_goal(game, game.env_goals, assumption, transition, self._env_goal_supports))]
        names = game.next_outputs
        assumptions_here = _GoalsAt(game, {**state, **chosen_input}, game.env_goals)
        found = []
        for next_assumption, part in assumptions_here.split_by_successor_goal(
                game.exist_next_inputs(responses), assumption):
            found += [(_values(code, len(names)), next_assumption)
                      for code in _codes(game, part, names, set(names))]
        found.sort()  # one entry per output valuation: the values never tie
        return found

    def _deadlock_input(self, state: Mapping[str, bool | None]) -> tuple[bool | None, ...] | None:
        """The values of a deadlock node (chosen inputs, no outputs), if the environment can
        move so that no output satisfies sys_trans."""
        game = self.game
        deadlock_inputs = game.bdd.let(state, self.deadlock_moves)
        if deadlock_inputs == game.false:
            return None
        choice, _ = game.pick(deadlock_inputs, game.next_inputs)
        return tuple(choice[game.to_next[name]] for name in game.inputs) + (None,) * len(game.outputs)


def _first_environment_moves(game: SymbolicGame, solution: EnvironmentSolution) -> list[list[list[Node]]]:
    """Per level, goal and assumption: the environment moves of lowest X rank at each position."""
    strategies = []
    for level in solution.levels:
        per_goal = []
        for moves_by_assumption in level.moves:
            per_assumption = []
            for steps in moves_by_assumption:
                strategy = game.false
                for moves in steps:
                    strategy |= moves & ~game.exist_next_inputs(strategy)
                per_assumption.append(strategy)
            per_goal.append(per_assumption)
        strategies.append(per_goal)
    return strategies


def losing_initial_positions(game: SymbolicGame, environment_wins: Node, robotics_semantics: bool) -> Node:
    """The set of initial positions from which the environment wins.

    Robotics semantics: any position allowed by both init sections. Standard semantics: the
    environment picks an initial input for which every system completion loses.
    """
    initial = game.env_init & game.sys_init & environment_wins
    if not robotics_semantics:
        hopeless_inputs = game.bdd.forall(game.outputs, ~game.sys_init | environment_wins)
        initial &= hopeless_inputs
    return initial


def strategy_to_json(strategy: dict[str, Any]) -> str:
    """Print a (counter-)strategy exactly in slugs' ``--jsonOutput`` layout."""
    return ''.join(strategy_json_chunks(strategy))


def strategy_json_chunks(strategy: dict[str, Any], nodes_per_chunk: int = 1000) -> Iterator[str]:
    """``strategy_to_json`` in pieces of ``nodes_per_chunk`` nodes, for writing as they come.
    ``strategy['nodes']`` is a dict, or an iterator of ``(name, node)`` in increasing number
    (``streamed_strategy``)."""
    names = ', '.join(_json_string(name) for name in strategy['variables'])
    yield (f'{{"version": {strategy["version"]},\n "slugs": {_json_string(strategy["slugs"])},\n\n'
           f' "variables": [{names}],\n\n "nodes": {{\n')
    nodes = strategy['nodes']
    if isinstance(nodes, dict):
        nodes = sorted(nodes.items(), key=lambda item: int(item[0]))
    lines, position = [], 0
    for position, (node_name, node) in enumerate(nodes, start=1):
        rank = node['rank']
        rank_text = f'[{rank[0]}, {rank[1]}]' if isinstance(rank, (list, tuple)) else str(rank)
        state = node['state']
        state = ', '.join(map(str, state) if None not in state else
                          ('null' if v is None else str(v) for v in state))
        trans = ', '.join(map(str, node['trans']))
        # The separator goes before each node but the first: the last is not known ahead.
        separator = ',\n\n' if position > 1 else ''
        lines.append(f'{separator}"{node_name}": {{\n\t"rank": {rank_text},\n\t"state": [{state}],\n'
                     f'\t"trans": [{trans}]\n}}')
        if len(lines) == nodes_per_chunk:
            yield ''.join(lines)
            lines = []
    lines.append('\n\n}}\n' if position else '}}\n')
    yield ''.join(lines)


def _json_string(text: str) -> str:
    import json
    return json.dumps(text)
