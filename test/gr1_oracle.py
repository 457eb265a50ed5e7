"""An independent explicit-state GR(1) solver and strategy checker, for the tests only.

It shares nothing with ltl_synthesizer but the formula trees: valuations are enumerated,
formulas are evaluated on (current, next) valuation pairs with numpy, and realizability is
decided by a DIFFERENT algorithm than the synthesizer's three nested fixpoints:

1. The GR(1) game (slugs' semantics: the environment picks the next inputs allowed by
   env_trans, then the system picks outputs allowed by sys_trans; whoever cannot move loses;
   livenesses are predicates on transitions, so they may mention next-step variables) is
   turned into an explicit two-player arena.
2. The winning condition  (/\\_i GF A_i) -> (/\\_j GF G_j)  is degeneralized with two round-robin
   counters (i waits for A_i, j waits for G_j). Each transition gets a priority: 2 if it
   advances j, else 1 if it advances i, else 0. The system wins exactly the plays whose
   highest priority seen infinitely often is even, a max-parity game with priorities 0..2.
3. That parity game is solved with Zielonka's recursive algorithm (attractors only).

Arena (S states = valuations, X input valuations, Y output valuations):
  env vertex  (s, i, j, p): p = priority of the transition that entered s; env picks x'.
  sys vertex  (s, x', i, j): sys picks y', moving to env vertex (x'y', i', j', p').

Sizes grow as S*S, so this is meant for specifications of up to about 12 propositions.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import networkx as nx
import numpy as np

from respec.ltl import And, Const, Formula, Iff, Implies, Next, Not, Or, Var

SYS, ENV = 0, 1


# --- evaluation ---------------------------------------------------------------------------

def evaluate(formula: Formula, current, following, in_next: bool = False):
    """Truth of ``formula`` where ``current`` / ``following`` map names to bools or bool arrays
    (broadcastable): the valuations of this step and the next one."""
    if isinstance(formula, Const):
        return np.bool_(formula.value)
    if isinstance(formula, Var):
        return (following if in_next else current)[formula.name]
    if isinstance(formula, Next):
        return evaluate(formula.arg, current, following, True)
    if isinstance(formula, Not):
        return np.logical_not(evaluate(formula.arg, current, following, in_next))
    if isinstance(formula, (And, Or)):
        values = [evaluate(arg, current, following, in_next) for arg in formula.args]
        combine = np.logical_and if isinstance(formula, And) else np.logical_or
        result = values[0]
        for value in values[1:]:
            result = combine(result, value)
        return result
    left = evaluate(formula.left, current, following, in_next)
    right = evaluate(formula.right, current, following, in_next)
    if isinstance(formula, Implies):
        return np.logical_or(np.logical_not(left), right)
    if isinstance(formula, Iff):
        return np.equal(left, right)
    raise TypeError(f'not a formula: {formula!r}')


# --- the explicit game --------------------------------------------------------------------

@dataclass
class ExplicitGame:
    """All valuations of a specification and its formulas evaluated on all (state, next state).

    State index s reads the propositions (inputs, then outputs) as binary digits, first
    proposition most significant, so s = x * Y + y for input valuation x, output valuation y.
    """

    spec: object

    def __post_init__(self):
        self.names = list(self.spec.env_props) + list(self.spec.sys_props)
        self.n_inputs = len(self.spec.env_props)
        self.n_outputs = len(self.spec.sys_props)
        self.X, self.Y = 2 ** self.n_inputs, 2 ** self.n_outputs
        self.S = self.X * self.Y
        states = np.arange(self.S)
        width = len(self.names)
        self.bits = {name: ((states >> (width - 1 - k)) & 1).astype(bool)
                     for k, name in enumerate(self.names)}

    def valuation(self, s: int) -> tuple[bool, ...]:
        return tuple(bool(self.bits[name][s]) for name in self.names)

    def index(self, valuation) -> int:
        s = 0
        for value in valuation:
            s = 2 * s + int(bool(value))
        return s

    def _on_states(self, formulas) -> np.ndarray:
        current = {name: column for name, column in self.bits.items()}
        result = np.ones(self.S, dtype=bool)
        for formula in formulas:
            result &= np.broadcast_to(evaluate(formula, current, current), (self.S,))
        return result

    def _on_transitions(self, formulas) -> np.ndarray:
        current = {name: column[:, None] for name, column in self.bits.items()}
        following = {name: column[None, :] for name, column in self.bits.items()}
        result = np.ones((self.S, self.S), dtype=bool)
        for formula in formulas:
            result &= np.broadcast_to(evaluate(formula, current, following), (self.S, self.S))
        return result

    @cached_property
    def init(self) -> np.ndarray:
        """States allowed by env_init and sys_init."""
        return self._on_states(self.spec.env_init) & self._on_states(self.spec.sys_init)

    @cached_property
    def env_init(self) -> np.ndarray:
        return self._on_states(self.spec.env_init)

    @cached_property
    def env_trans(self) -> np.ndarray:
        """(S, S): env_trans between states (it cannot read next outputs, slugs rule)."""
        return self._on_transitions(self.spec.env_trans)

    @cached_property
    def sys_trans(self) -> np.ndarray:
        return self._on_transitions(self.spec.sys_trans)

    @cached_property
    def env_moves(self) -> np.ndarray:
        """(S, X): next input valuations the environment may choose."""
        return self.env_trans.reshape(self.S, self.X, self.Y).any(axis=2)

    @cached_property
    def sys_moves(self) -> np.ndarray:
        """(S, X, Y): output valuations allowed after each environment choice."""
        return (self.sys_trans & self.env_trans).reshape(self.S, self.X, self.Y)

    @cached_property
    def env_livenesses(self) -> list[np.ndarray]:
        """(S, S) each; an empty section means one TRUE liveness (as slugs does)."""
        return [self._on_transitions([f]) for f in self.spec.env_liveness] or [self._on_transitions([])]

    @cached_property
    def sys_livenesses(self) -> list[np.ndarray]:
        return [self._on_transitions([f]) for f in self.spec.sys_liveness] or [self._on_transitions([])]


# --- vertex sets and attractors ------------------------------------------------------------

@dataclass
class Vertices:
    """A set of arena vertices: env vertices E[s, i, j, p] and sys vertices M[s, x', i, j]."""

    env: np.ndarray
    sys: np.ndarray

    def __or__(self, other):
        return Vertices(self.env | other.env, self.sys | other.sys)

    def __sub__(self, other):
        return Vertices(self.env & ~other.env, self.sys & ~other.sys)

    def __and__(self, other):
        return Vertices(self.env & other.env, self.sys & other.sys)

    def empty(self) -> bool:
        return not (self.env.any() or self.sys.any())

    def __eq__(self, other):
        return np.array_equal(self.env, other.env) and np.array_equal(self.sys, other.sys)


class ParityArena:
    """The degeneralized GR(1) game as a max-parity game with priorities 0, 1, 2."""

    def __init__(self, game: ExplicitGame):
        self.game = game
        self.I, self.J = len(game.env_livenesses), len(game.sys_livenesses)
        g = game
        self.none = Vertices(np.zeros((g.S, self.I, self.J, 3), bool), np.zeros((g.S, g.X, self.I, self.J), bool))
        self.all = Vertices(~self.none.env, ~self.none.sys)

    def priority_set(self, priority: int) -> Vertices:
        env = np.zeros_like(self.none.env)
        env[..., priority] = True
        return Vertices(env, np.zeros_like(self.none.sys) if priority else ~self.none.sys)

    def successors_in(self, target_env: np.ndarray, i: int, j: int) -> np.ndarray:
        """(S, X, Y): whether the sys move y' from sys vertex (s, x', i, j) enters target_env.

        The entered env vertex is (x'y', i', j', p): j advances if G_j holds on the
        transition (priority 2), else i advances if A_i holds (priority 1), else priority 0."""
        g = self.game
        goal, fair = g.sys_livenesses[j], g.env_livenesses[i]
        i_next, j_next = (i + 1) % self.I, (j + 1) % self.J
        # Each target column is a function of the next state s'; broadcast along the rows s.
        reached = np.where(
            goal,
            np.where(fair, target_env[:, i_next, j_next, 2][None, :], target_env[:, i, j_next, 2][None, :]),
            np.where(fair, target_env[:, i_next, j, 1][None, :], target_env[:, i, j, 0][None, :]))
        return reached.reshape(g.S, g.X, g.Y)

    def attractor(self, player: int, target: Vertices, region: Vertices) -> Vertices:
        """Vertices of ``region`` from which ``player`` can force a visit to ``target``,
        moving inside ``region`` (a vertex without moves in the region loses for its owner)."""
        g = self.game
        attracted = target & region
        moves_in_region = {(i, j): g.sys_moves & self.successors_in(region.env, i, j)
                           for i in range(self.I) for j in range(self.J)}
        while True:
            sys_part = attracted.sys.copy()
            env_part = attracted.env.copy()
            for i in range(self.I):
                for j in range(self.J):
                    moves = moves_in_region[i, j]
                    into = moves & self.successors_in(attracted.env, i, j)
                    if player == SYS:
                        forced = into.any(axis=2)
                    else:
                        forced = ~(moves & ~into).any(axis=2)
                    sys_part[:, :, i, j] |= forced
                    env_choices = g.env_moves & region.sys[:, :, i, j]
                    env_into = env_choices & attracted.sys[:, :, i, j]
                    if player == ENV:
                        forced_env = env_into.any(axis=1)
                    else:
                        forced_env = ~(env_choices & ~env_into).any(axis=1)
                    env_part[:, i, j, :] |= forced_env[:, None]
            grown = Vertices(env_part, sys_part) & region
            if grown == attracted:
                return attracted
            attracted = grown

    def zielonka(self, region: Vertices) -> tuple[Vertices, Vertices]:
        """(system's winning vertices, environment's) of the subgame on ``region``
        (a region without dead ends), by Zielonka's recursive algorithm."""
        if region.empty():
            return self.none, self.none
        top = 0
        for priority in (2, 1):
            if (region.env[..., priority]).any():
                top = priority
                break
        player, opponent = (SYS, ENV) if top % 2 == 0 else (ENV, SYS)
        dominion = self.attractor(player, self.priority_set(top) & region, region)
        won = dict(zip((SYS, ENV), self.zielonka(region - dominion)))
        if won[opponent].empty():
            result = {player: region, opponent: self.none}
        else:
            # The opponent wins its part of the subgame and everything it can force there.
            lost = self.attractor(opponent, won[opponent], region)
            rest = dict(zip((SYS, ENV), self.zielonka(region - lost)))
            result = {opponent: rest[opponent] | lost, player: rest[player]}
        return result[SYS], result[ENV]

    def system_winning(self) -> Vertices:
        # Dead ends first: the environment loses where it cannot move, the system likewise.
        env_stuck = self.attractor(SYS, self.none, self.all)
        rest = self.all - env_stuck
        sys_stuck = self.attractor(ENV, self.none, rest)
        won_by_system, _ = self.zielonka(rest - sys_stuck)
        return won_by_system | env_stuck


# --- public API ---------------------------------------------------------------------------

class Oracle:
    """The explicit game of one specification, solved once, queried for both semantics."""

    def __init__(self, spec):
        self.game = ExplicitGame(spec)

    @cached_property
    def winning(self) -> np.ndarray:
        """Boolean vector over states: the system wins the game starting there."""
        return ParityArena(self.game).system_winning().env[:, 0, 0, 0]

    def realizable(self, robotics_semantics: bool = True) -> bool:
        game, winning = self.game, self.winning
        if robotics_semantics:
            # Every state allowed by both init sections must be winning.
            return bool(np.all(winning[game.init]))
        # For every allowed initial input valuation some allowed completion is winning.
        good = (game.init & winning).reshape(game.X, game.Y).any(axis=1)
        env_allowed = game.env_init.reshape(game.X, game.Y).any(axis=1)
        return bool(np.all(good | ~env_allowed))

    def check_strategy(self, strategy: dict, robotics_semantics: bool = True) -> list[str]:
        game = self.game
        problems = _check_shape(game, strategy, allow_missing_outputs=False)
        if problems:
            return problems
        nodes = strategy['nodes']
        state_of = {name: game.index(node['state']) for name, node in nodes.items()}
        problems += _check_initial_coverage(game, set(state_of.values()), robotics_semantics)
        problems += _check_moves(game, nodes, state_of)
        problems += _check_fair_cycles(game, nodes, state_of)
        return problems

    def check_counterstrategy(self, counterstrategy: dict, robotics_semantics: bool = True) -> list[str]:
        game = self.game
        problems = _check_shape(game, counterstrategy, allow_missing_outputs=True)
        if problems:
            return problems
        return _check_counterstrategy(game, counterstrategy['nodes'], robotics_semantics)


def solve(spec, robotics_semantics: bool = True) -> bool:
    """Realizability of ``spec`` under slugs' robotics (default) or standard init semantics."""
    return Oracle(spec).realizable(robotics_semantics)


def winning_states(spec) -> np.ndarray:
    return Oracle(spec).winning


def check_strategy(spec, strategy: dict, robotics_semantics: bool = True) -> list[str]:
    """Violations of a slugs explicit JSON strategy against ``spec`` (empty list: correct):
    initial states covered, every allowed environment move answered, both safety sections on
    every edge, and no cycle that satisfies all environment livenesses but misses a goal."""
    return Oracle(spec).check_strategy(strategy, robotics_semantics)


def check_counterstrategy(spec, counterstrategy: dict, robotics_semantics: bool = True) -> list[str]:
    """Violations of an environment counter-strategy (ltl_synthesizer's JSON: one environment
    move per node, every system response listed, ``null`` outputs for a system deadlock)."""
    return Oracle(spec).check_counterstrategy(counterstrategy, robotics_semantics)


def _check_shape(game, strategy: dict, allow_missing_outputs: bool) -> list[str]:
    if strategy.get('variables') != game.names:
        return [f"variables {strategy.get('variables')} differ from inputs+outputs {game.names}"]
    problems = []
    nodes = strategy.get('nodes', {})
    for name, node in nodes.items():
        values = node.get('state', [])
        inputs, outputs = values[:game.n_inputs], values[game.n_inputs:]
        deadlock = allow_missing_outputs and outputs and all(v is None for v in outputs)
        if (len(values) != len(game.names) or any(v not in (0, 1) for v in inputs)
                or not (deadlock or all(v in (0, 1) for v in outputs))):
            problems.append(f'node {name}: malformed state {values}')
        for successor in node.get('trans', []):
            if str(successor) not in nodes:
                problems.append(f'node {name}: successor {successor} does not exist')
    return problems


def _check_initial_coverage(game, covered: set[int], robotics_semantics: bool) -> list[str]:
    if robotics_semantics:
        missing = [s for s in np.flatnonzero(game.init) if s not in covered]
        return [f'initial state {_show(game, s)} has no strategy node' for s in missing]
    problems = []
    for x in range(game.X):
        if not game.env_init[x * game.Y]:
            continue
        if not any(game.init[x * game.Y + y] and x * game.Y + y in covered for y in range(game.Y)):
            problems.append(f'initial inputs {_show(game, x * game.Y)[:game.n_inputs]} have no '
                            'strategy node satisfying sys_init')
    return problems


def _check_moves(game, nodes, state_of) -> list[str]:
    problems = []
    for name, node in nodes.items():
        s = state_of[name]
        answered = set()
        for successor in node.get('trans', []):
            t = state_of[str(successor)]
            if not game.env_trans[s, t]:
                problems.append(f'edge {name}->{successor}: env_trans violated '
                                f'{_show(game, s)} -> {_show(game, t)}')
            if not game.sys_trans[s, t]:
                problems.append(f'edge {name}->{successor}: sys_trans violated '
                                f'{_show(game, s)} -> {_show(game, t)}')
            answered.add(t // game.Y)
        for x in np.flatnonzero(game.env_moves[s]):
            if x not in answered:
                problems.append(f'node {name} {_show(game, s)}: environment move to inputs '
                                f'{_bits(x, game.n_inputs)} has no answer')
    return problems


def _check_fair_cycles(game, nodes, state_of) -> list[str]:
    """No cycle may satisfy every environment liveness but miss a system liveness forever:
    for each goal, drop the edges that satisfy it and look for a strongly connected part
    whose internal edges still satisfy every environment liveness."""
    edges = [(name, str(successor)) for name, node in nodes.items() for successor in node.get('trans', [])]
    problems = []
    for j, goal in enumerate(game.sys_livenesses):
        graph = nx.DiGraph()
        graph.add_edges_from((a, b) for a, b in edges if not goal[state_of[a], state_of[b]])
        for component in nx.strongly_connected_components(graph):
            inside = [(a, b) for a, b in graph.subgraph(component).edges]
            if not inside:
                continue
            if all(any(fair[state_of[a], state_of[b]] for a, b in inside) for fair in game.env_livenesses):
                problems.append(f'fair cycle through nodes {sorted(component, key=_node_key)} never '
                                f'satisfies system liveness {j}')
    return problems


def _check_counterstrategy(game, nodes, robotics_semantics: bool) -> list[str]:
    """The environment must start where the system loses, move legally and uniquely, face every
    legal system response, and win every infinite play: each cycle satisfies all environment
    livenesses and misses some system liveness."""
    def deadlock(node):
        return all(v is None for v in node['state'][game.n_inputs:])

    state_of = {name: game.index(node['state']) for name, node in nodes.items() if not deadlock(node)}
    problems = []
    covered = set(state_of.values())
    if robotics_semantics:
        starts = any(game.init[s] for s in covered)
    else:
        starts = any(game.env_init[x * game.Y]
                     and all(not game.init[x * game.Y + y] or x * game.Y + y in covered for y in range(game.Y))
                     for x in range(game.X))
    if not starts:
        problems.append('no initial state from which the environment wins is covered')

    edges = []
    for name, node in nodes.items():
        successors = [str(t) for t in node.get('trans', [])]
        if deadlock(node):
            if successors:
                problems.append(f'deadlock node {name} has successors')
            continue
        s = state_of[name]
        if not successors:
            problems.append(f'node {name} {_show(game, s)}: the environment makes no move')
            continue
        chosen = {tuple(nodes[t]['state'][:game.n_inputs]) for t in successors}
        if len(chosen) != 1:
            problems.append(f'node {name}: the environment chooses several inputs {sorted(chosen)}')
            continue
        x = game.index(chosen.pop()) if game.n_inputs else 0
        if not game.env_moves[s, x]:
            problems.append(f'node {name}: inputs {_bits(x, game.n_inputs)} violate env_trans')
        allowed = {x * game.Y + y for y in range(game.Y) if game.sys_moves[s, x, y]}
        listed = {state_of[t] for t in successors if t in state_of}
        if not allowed and not any(deadlock(nodes[t]) for t in successors):
            problems.append(f'node {name}: the system is stuck but no deadlock node follows')
        if listed != allowed:
            problems.append(f'node {name}: system responses listed {sorted(map(lambda t: _show(game, t), listed))}'
                            f' differ from those allowed {sorted(map(lambda t: _show(game, t), allowed))}')
        edges += [(name, t) for t in successors if t in state_of]

    graph = nx.DiGraph(edges)
    for component in nx.strongly_connected_components(graph):
        inside = list(graph.subgraph(component).edges)
        if inside and all(any(goal[state_of[a], state_of[b]] for a, b in inside) for goal in game.sys_livenesses):
            problems.append(f'cycle through {sorted(component, key=_node_key)} satisfies every system liveness')
    for i, fair in enumerate(game.env_livenesses):
        unfair = nx.DiGraph([(a, b) for a, b in edges if not fair[state_of[a], state_of[b]]])
        for component in nx.strongly_connected_components(unfair):
            if unfair.subgraph(component).number_of_edges():
                problems.append(f'cycle through {sorted(component, key=_node_key)} never satisfies '
                                f'environment liveness {i}')
    return problems


def _node_key(name: str):
    return (len(name), name)


def _bits(value: int, width: int) -> str:
    return format(value, f'0{width}b') if width else ''


def _show(game, s: int) -> str:
    return ''.join('1' if v else '0' for v in game.valuation(s))


# --- random formulas and specifications for property tests -------------------------------

def formulas(names, with_next: bool = True, max_leaves: int = 8, next_names=None):
    """Hypothesis strategy: formulas over ``names`` built with respec.ltl's constructors,
    with ``next`` (never nested) over ``next_names`` (default: ``names``) when ``with_next``."""
    from hypothesis import strategies as st

    from respec.ltl import FALSE, TRUE, conj, disj, iff, implies, neg, next_, var

    def combine(children):
        return st.one_of(
            children.map(neg),
            st.lists(children, min_size=2, max_size=3).map(conj),
            st.lists(children, min_size=2, max_size=3).map(disj),
            st.tuples(children, children).map(lambda pair: implies(*pair)),
            st.tuples(children, children).map(lambda pair: iff(*pair)))

    atoms = st.sampled_from([var(n) for n in names] + [TRUE, FALSE])
    current = st.recursive(atoms, combine, max_leaves=max_leaves)
    if not with_next:
        return current
    next_names = names if next_names is None else next_names
    next_atoms = st.sampled_from([var(n) for n in next_names] + [TRUE, FALSE])
    leaves = st.one_of(atoms, next_atoms.map(next_),
                       st.recursive(next_atoms, combine, max_leaves=3).map(next_))
    return st.recursive(leaves, combine, max_leaves=max_leaves)
