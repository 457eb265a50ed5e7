"""An independent check of an explicit GR(1) strategy (slugs' JSON shape), for benchmarks.

It shares nothing with ltl_synthesizer but the formula trees: formulas are translated to BDDs
here, in a manager of its own, and the strategy graph is checked directly:

1. initial coverage: every initial input valuation (ENV_INIT) has an initial node whose
   state satisfies ENV_INIT and SYS_INIT (slugs' standard semantics);
2. every move of every node is allowed by SYS_TRANS, and every next input that ENV_TRANS
   allows at the node's state is answered by some successor;
3. fairness: for each system goal j, no strongly connected part of the graph without
   goal-j transitions has transitions satisfying every environment assumption (such a part
   holds a play that meets the assumptions and misses goal j forever).

Scales to strategies of hundreds of thousands of nodes (one BDD evaluation per edge).

Explicit strategies grow beyond that on the larger family instances, so
``check_symbolic_strategy`` checks the strategy as relations
(``ltl_synthesizer.strategy.symbolic_strategy``: its positions and, per goal j, the pieces of
moves it allows), with other algorithms than the synthesizer's fixpoints, on all of the
strategy's positions at once (so on every position a play can reach): the initial positions
are among them, every environment move allowed by ENV_TRANS is answered by a move allowed
by SYS_TRANS, no move leaves them, and an Emerson-Lei fair-path search finds no path of
goal-j moves that misses goal j forever and meets every assumption infinitely often.
Relations stay in parts (clusters of conjuncts) and every product quantifies early.
The relations are copied into this checker's own BDD manager; every formula is translated
here. Run on a specification file:

    python bench/strategy_check.py FILE.slugsin    # synthesize, then check symbolically
"""

from __future__ import annotations

from dd import cudd

from respec.ltl import And, Const, Iff, Implies, Next, Not, Or, Var, evaluate


class _Formulas:
    def __init__(self, spec):
        self.bdd = cudd.BDD()
        self.bdd.configure(reordering=False)
        self.variables = list(spec.env_props) + list(spec.sys_props)
        for name in self.variables:
            self.bdd.declare(name, name + "'")
        self._memo = {}

    def game(self, spec):
        """The specification's initial conditions, safety relations and liveness lists as BDDs."""
        true = self.bdd.true
        return (self.conjunction(spec.env_init), self.conjunction(spec.sys_init),
                self.conjunction(spec.env_trans), self.conjunction(spec.sys_trans),
                [self.translate(f) for f in spec.env_liveness] or [true],
                [self.translate(f) for f in spec.sys_liveness] or [true])

    def translate(self, formula, in_next=False):
        key = (id(formula), in_next)
        if key in self._memo:
            return self._memo[key][1]
        bdd = self.bdd
        if isinstance(formula, Const):
            result = bdd.true if formula.value else bdd.false
        elif isinstance(formula, Var):
            result = bdd.var(formula.name + ("'" if in_next else ''))
        elif isinstance(formula, Not):
            result = ~self.translate(formula.arg, in_next)
        elif isinstance(formula, (And, Or)):
            parts = [self.translate(arg, in_next) for arg in formula.args]
            result = bdd.true if isinstance(formula, And) else bdd.false
            for part in parts:
                result = result & part if isinstance(formula, And) else result | part
        elif isinstance(formula, Implies):
            result = ~self.translate(formula.left, in_next) | self.translate(formula.right, in_next)
        elif isinstance(formula, Iff):
            result = self.translate(formula.left, in_next).equiv(self.translate(formula.right, in_next))
        elif isinstance(formula, Next):
            result = self.translate(formula.arg, True)
        else:
            raise TypeError(f'unexpected formula node {type(formula).__name__}')
        self._memo[key] = (formula, result)  # keeps the node alive: ids stay unique
        return result

    def conjunction(self, formulas):
        result = self.bdd.true
        for formula in formulas:
            result &= self.translate(formula)
        return result


def check_strategy(spec, strategy: dict, limit: int = 20) -> list[str]:
    """Problems found (at most ``limit``); empty when the strategy is winning."""
    formulas = _Formulas(spec)
    bdd = formulas.bdd
    names = strategy['variables']
    if sorted(names) != sorted(formulas.variables):
        return [f'strategy variables {names} are not the specification\'s']
    inputs = list(spec.env_props)
    # The safety sections stay lists, never one BDD: in the declared order (all inputs, then
    # all outputs) a capability robot's relation is exponential (every completion input is
    # far from its memory output), and the checker must not borrow the synthesizer's order.
    # ENV_TRANS is cofactored by each node's state; SYS_TRANS is evaluated on each edge.
    env_init, sys_init = formulas.conjunction(spec.env_init), formulas.conjunction(spec.sys_init)
    env_parts = [formulas.translate(f) for f in spec.env_trans]
    assumptions = [formulas.translate(f) for f in spec.env_liveness] or [bdd.true]
    goals = [formulas.translate(f) for f in spec.sys_liveness] or [bdd.true]
    labels_of = _Labels(bdd, assumptions, goals)
    nodes = strategy['nodes']
    problems = []

    def state_of(name):
        return {variable: bool(value) for variable, value in zip(names, nodes[name]['state'])}

    def next_cube(state):
        return bdd.cube({variable + "'": value for variable, value in state.items()})

    # 1. Initial coverage: the initial nodes are those with rank 0 that are initial states.
    covered_inputs = bdd.false
    for name in nodes:
        state = state_of(name)
        if bdd.let(state, env_init & sys_init) == bdd.true:
            covered_inputs |= bdd.cube({variable: state[variable] for variable in inputs})
    initial_inputs = bdd.exist(list(spec.sys_props), env_init)
    if initial_inputs & ~covered_inputs != bdd.false:
        problems.append('some initial input valuation has no initial node')

    # 2. Moves, 3. edge labels for the fairness check. Nodes differ from one another in their
    # goal counter, not always in their state: what a state or a pair of states gives is worked
    # out once (an explicit AMBA strategy has thousands of nodes over far fewer states).
    next_sys = [v + "'" for v in spec.sys_props]
    per_state: dict = {}
    per_move: dict = {}
    edges = {name: [] for name in nodes}
    for name in nodes:
        here = tuple(nodes[name]['state'])
        if here not in per_state:
            state = state_of(name)
            env_here = bdd.true
            for part in env_parts:
                env_here &= bdd.let(state, part)
            per_state[here] = (state, bdd.exist(next_sys, env_here), {})
        state, allowed_inputs, answered_by = per_state[here]
        successors = tuple(str(successor) for successor in nodes[name]['trans'])
        for successor_name in successors:
            there = tuple(nodes[successor_name]['state'])
            if there not in per_move:
                following = state_of(successor_name)
                move = next_cube(following)
                per_move[there] = (following, move_values(move, bdd), bdd.exist(next_sys, move))
            following, values, _ = per_move[there]
            if (here, there) not in answered_by:
                answered_by[(here, there)] = (all(evaluate(f, state, following) for f in spec.sys_trans),
                                              labels_of({**state, **values}))
            follows_sys_trans, labels = answered_by[(here, there)]
            if not follows_sys_trans:
                problems.append(f'node {name} -> {successor_name} violates SYS_TRANS')
            edges[name].append((successor_name, labels))
        answered = bdd.false
        for there in {tuple(nodes[s]['state']) for s in successors}:
            answered |= per_move[there][2]
        if allowed_inputs & ~answered != bdd.false:
            problems.append(f'node {name}: some next input allowed by ENV_TRANS has no successor')
        if len(problems) >= limit:
            return problems
    problems += _fairness_problems(edges, len(assumptions), len(goals))
    return problems[:limit]


def check_counterstrategy(spec, strategy: dict, robotics_semantics: bool = False,
                          limit: int = 20) -> list[str]:
    """Problems found (at most ``limit``) in the environment's explicit counter-strategy
    (slugs' ``--counterStrategy --jsonOutput`` shape); empty when it wins against every
    system move:

    1. initial: some initial input (standard semantics; robotics: some initial position) has
       a node for every initial output the system may pick;
    2. moves: at every node, the environment picks one next input allowed by ENV_TRANS (all
       successors share it); every output SYS_TRANS allows in answer has a successor, each
       successor is such an output, or the one successor is a deadlock node (outputs
       ``null``) because SYS_TRANS allows none;
    3. winning plays: every cycle meets every assumption (the graph without the
       transitions of assumption i has no cycle) and misses some goal (no strongly
       connected part has internal transitions of every goal).
    """
    formulas = _Formulas(spec)
    bdd = formulas.bdd
    names = strategy['variables']
    if sorted(names) != sorted(formulas.variables):
        return [f'counter-strategy variables {names} are not the specification\'s']
    inputs, outputs = list(spec.env_props), list(spec.sys_props)
    # The safety sections stay lists of formulas, cofactored by each node's state before they
    # are conjoined: as one BDD in the declared order, GenBuf's SYS_TRANS alone is huge.
    env_init, sys_init = formulas.conjunction(spec.env_init), formulas.conjunction(spec.sys_init)
    env_parts = [formulas.translate(f) for f in spec.env_trans]
    sys_parts = [formulas.translate(f) for f in spec.sys_trans]
    assumptions = [formulas.translate(f) for f in spec.env_liveness] or [bdd.true]
    goals = [formulas.translate(f) for f in spec.sys_liveness] or [bdd.true]
    labels_of = _Labels(bdd, assumptions, goals)
    nodes = strategy['nodes']
    problems = []

    def cofactor(parts, assignment):
        result = bdd.true
        for part in parts:
            result &= bdd.let(assignment, part)
        return result

    def state_of(name):
        return {variable: None if value is None else bool(value)
                for variable, value in zip(names, nodes[name]['state'])}

    def deadlock(state):
        return any(state[variable] is None for variable in outputs)

    # 1. Initial positions with a node.
    covered = bdd.false
    for name in nodes:
        state = state_of(name)
        if not deadlock(state):
            covered |= bdd.cube(state)
    if robotics_semantics:
        won_initially = env_init & sys_init & covered != bdd.false
    else:
        won_initially = bdd.exist(outputs, env_init) & bdd.forall(outputs, ~sys_init | covered) \
            != bdd.false
    if not won_initially:
        problems.append('no initial input (position) has nodes for every initial system choice')

    # 2. Moves; labels of the transitions for 3.
    edges = {}
    for name in nodes:
        state = state_of(name)
        if deadlock(state):
            continue
        successors = [str(successor) for successor in nodes[name]['trans']]
        if not successors:
            problems.append(f'node {name} has no successor')
            continue
        chosen = {v + "'": state_of(successors[0])[v] for v in inputs}
        if any(state_of(s)[v] != chosen[v + "'"] for s in successors for v in inputs):
            problems.append(f'node {name}: successors differ in their inputs')
            continue
        here = {**state, **chosen}
        if cofactor(env_parts, here) != bdd.true:
            problems.append(f'node {name}: its next input violates ENV_TRANS')
        sys_answers = cofactor(sys_parts, here)  # a function of the next outputs only
        if any(deadlock(state_of(s)) for s in successors):
            if len(successors) != 1 or sys_answers != bdd.false:
                problems.append(f'node {name}: a deadlock successor where the system can move')
            edges[name] = []
            continue
        answered = bdd.false
        edges[name] = []
        for successor in successors:
            following = state_of(successor)
            move = {v + "'": following[v] for v in outputs}
            if bdd.let(move, sys_answers) != bdd.true:
                problems.append(f'node {name} -> {successor} violates SYS_TRANS')
            answered |= bdd.cube(move)
            transition = {**state, **{v + "'": following[v] for v in names}}
            edges[name].append((successor, labels_of(transition)))
        if sys_answers & ~answered != bdd.false:
            problems.append(f'node {name}: some system answer allowed by SYS_TRANS has no successor')
        if len(problems) >= limit:
            return problems
    problems += _counter_fairness_problems(edges, len(assumptions), len(goals))
    return problems[:limit]


def _counter_fairness_problems(edges: dict, assumption_count: int, goal_count: int) -> list[str]:
    problems = []
    for assumption in range(assumption_count):
        graph = {name: [(target, labels) for target, labels in out if not labels[0][assumption]]
                 for name, out in edges.items()}
        for component in _components(graph):
            if any(target in component for name in component for target, _ in graph[name]):
                problems.append(f'a cycle through node {min(component, key=int)} never meets '
                                f'assumption {assumption}')
                break
    for component in _components(edges):
        seen = [False] * goal_count
        internal = False
        for name in component:
            for target, labels in edges[name]:
                if target in component:
                    internal = True
                    seen = [a or b for a, b in zip(seen, labels[1])]
        if internal and all(seen):
            problems.append(f'a cycle through node {min(component, key=int)} meets every goal')
            break
    return problems


def move_values(cube, bdd) -> dict:
    """The valuation of a cube over next-step variables (``{"x'": True, ...}``)."""
    return bdd.pick(cube)


def _fairness_problems(edges: dict, assumption_count: int, goal_count: int) -> list[str]:
    problems = []
    for goal in range(goal_count):
        # The graph without goal-``goal`` transitions; a component of it whose internal
        # edges satisfy every assumption holds a fair play that misses the goal.
        graph = {name: [(target, labels[0]) for target, labels in out if not labels[1][goal]]
                 for name, out in edges.items()}
        for component in _components(graph):
            seen = [False] * assumption_count
            for name in component:
                for target, assumption_labels in graph[name]:
                    if target in component:
                        seen = [a or b for a, b in zip(seen, assumption_labels)]
            internal = any(target in component for name in component for target, _ in graph[name])
            if internal and all(seen):
                problems.append(f'a fair cycle through node {min(component, key=int)} '
                                f'never reaches system goal {goal}')
                break
    return problems


def _components(graph: dict) -> list[set]:
    """Strongly connected components (iterative Tarjan)."""
    index, low, on_stack, stack, components = {}, {}, set(), [], []
    counter = 0
    for root in graph:
        if root in index:
            continue
        work = [(root, 0)]
        while work:
            node, position = work.pop()
            if position == 0:
                index[node] = low[node] = counter
                counter += 1
                stack.append(node)
                on_stack.add(node)
            successors = graph[node]
            if position < len(successors):
                work.append((node, position + 1))
                target = successors[position][0]
                if target not in index:
                    work.append((target, 0))
                elif target in on_stack:
                    low[node] = min(low[node], index[target])
                continue
            if low[node] == index[node]:
                component = set()
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.add(member)
                    if member == node:
                        break
                components.append(component)
            if work:
                parent = work[-1][0]
                low[parent] = min(low[parent], low[node])
    return components


def check_symbolic_strategy(spec, strategy, source: cudd.BDD) -> list[str]:
    """Problems found (empty when the strategy is winning, standard initial semantics).

    ``strategy`` (an ``ltl_synthesizer.strategy.SymbolicStrategy`` of manager ``source``)
    claims: on its positions ``winning``, while pursuing system goal j the system may take
    any move allowed by SYS_TRANS into the target of a piece of ``pieces[j]`` whose
    ``offered`` set holds the position and the environment's move. Checked here, for every
    goal j and on all of its positions (so on every position a play can reach): each
    environment move allowed by ENV_TRANS has such a move, no such move leaves the
    positions, the initial positions are among them, and no path of goal-j moves that never
    meets goal j meets every assumption infinitely often (an Emerson-Lei greatest fixpoint).
    Then every play of the strategy from an initial position satisfies the specification.
    Relations stay in parts (clusters of conjuncts): each product is one image or preimage
    computed with early quantification, never the strategy's whole relation.
    """
    formulas = _Formulas(spec)
    bdd = formulas.bdd
    # The check works in the synthesizer's final variable order, sifted for these very
    # relations, without sifting of its own: translating and copying into another order, or
    # sifting during the check, can take far longer than the check (moving obstacle 24x24:
    # 14 s of sifting for a 0.2 s check). The order is no part of the logic.
    cudd.reorder(bdd, {name: source.level_of_var(name) for name in bdd.vars})
    current = list(spec.env_props) + list(spec.sys_props)
    next_inputs = {name + "'" for name in spec.env_props}
    next_outputs = {name + "'" for name in spec.sys_props}
    to_next = {name: name + "'" for name in current}
    env_init, sys_init = formulas.conjunction(spec.env_init), formulas.conjunction(spec.sys_init)
    env_trans = _clusters(bdd, [formulas.translate(f) for f in spec.env_trans])
    sys_trans = _clusters(bdd, [formulas.translate(f) for f in spec.sys_trans])
    assumptions = [formulas.translate(f) for f in spec.env_liveness] or [bdd.true]
    goals = [formulas.translate(f) for f in spec.sys_liveness] or [bdd.true]
    if len(strategy.pieces) != len(goals):
        return [f'{len(strategy.pieces)} strategy relations for {len(goals)} system goals']
    winning = source.copy(strategy.winning, bdd)
    pieces = [[(source.copy(piece.offered, bdd), source.copy(piece.target, bdd)) for piece in goal]
              for goal in strategy.pieces]
    problems = []
    if env_init & ~bdd.exist(list(spec.sys_props), env_init & sys_init & winning) != bdd.false:
        problems.append('some initial input valuation has no initial position in the strategy')
    leaving = ~bdd.let(to_next, winning)

    def preimage(moves, targets):
        """Positions with a move that is a transition of ``targets``: ``moves`` are pairs
        (positions and environment moves, transitions), each taken with SYS_TRANS."""
        found = bdd.false
        for offered, transitions in moves:
            found |= _product(bdd, [offered, transitions & targets] + env_trans + sys_trans,
                              next_inputs | next_outputs)
        return found
    for j, goal_pieces in enumerate(pieces):
        responses = bdd.false
        for offered, target in goal_pieces:
            responses |= offered & _product(bdd, [target] + sys_trans, next_outputs)
        if winning & _product(bdd, [~responses] + env_trans, next_inputs) != bdd.false:
            problems.append(f'goal {j}: some environment move allowed at a position of the '
                            f'strategy has no answer')
        # The positions are conjoined last: conjoined into a piece first, 10 million nodes.
        if winning & preimage(goal_pieces, leaving) != bdd.false:
            problems.append(f'goal {j}: a move leaves the positions of the strategy')
        if goals[j] != bdd.true:
            # The fair-path search takes hundreds of preimages: of fewer, merged relations
            # (evasion 48x16: 63 pieces, 216,298 nodes merged). The goal and the positions
            # stay out of them (conjoined into them: 10 million nodes and more).
            merged = [(bdd.true, relation) for relation in _merged(goal_pieces)]
            missing_goal = ~goals[j]
            if _fair_path(bdd, winning, lambda targets: preimage(merged, missing_goal & targets),
                          assumptions, to_next):
                problems.append(f'goal {j}: a path of the strategy meets every assumption '
                                f'and never the goal')
    return problems


def _clusters(bdd, parts: list, limit: int = 2000) -> list:
    """Consecutive conjuncts merged while the merged BDD stays under ``limit`` nodes."""
    clusters = []
    for part in parts:
        if clusters and len(merged := clusters[-1] & part) <= limit:
            clusters[-1] = merged
        else:
            clusters.append(part)
    return clusters


def _merged(pieces: list, limit: int = 500_000) -> list:
    """The pieces' moves (``offered & target``), merged into as few BDDs as stay under
    ``limit`` nodes each."""
    merged = []
    for offered, target in pieces:
        move = offered & target
        if merged and len(union := merged[-1] | move) <= limit:
            merged[-1] = union
        else:
            merged.append(move)
    return merged


def _product(bdd, parts: list, quantified: set):
    """``exists quantified. /\\ parts``, each variable quantified right after the last part
    that mentions it (the parts' conjunction is never built)."""
    last = {}
    for index, part in enumerate(parts):
        for name in bdd.support(part) & quantified:
            last[name] = index
    result = bdd.true
    for index, part in enumerate(parts):
        now = [name for name, at in last.items() if at == index]
        result = cudd.and_exists(result, part, now) if now else result & part
    return result


def _fair_path(bdd, positions, preimage, assumptions, to_next) -> bool:
    """Whether some position of ``positions`` starts an infinite path of moves (``preimage``
    of a set of transitions: the positions with a move among them) that takes a transition
    of every assumption infinitely often: the Emerson-Lei greatest fixpoint of positions
    that can reach, within it, a transition of each assumption into it."""
    fair = positions
    while True:
        shrunk = fair
        for assumption in assumptions:
            fair_next = bdd.let(to_next, fair)
            reach = bdd.false
            while True:
                step = preimage(fair_next & (assumption | bdd.let(to_next, reach)))
                if step == reach:
                    break
                reach = step
            shrunk &= reach
        if shrunk == fair:
            return fair != bdd.false
        fair = shrunk


def main(argv=None) -> int:
    """Synthesize FILE (ours) and check its strategy symbolically: exit 0 ok, 1 problems,
    2 unrealizable; prints one line."""
    import argparse
    import time
    parser = argparse.ArgumentParser(description='check our strategy for a specification symbolically')
    parser.add_argument('specification', help='.slugsin or .structuredslugs file')
    args = parser.parse_args(argv)
    from ltl_synthesizer.command import read_specification
    from ltl_synthesizer.gr1 import Solver, solve_system_game
    from ltl_synthesizer.strategy import symbolic_strategy
    from ltl_synthesizer.symbolic import SymbolicGame
    from ltl_synthesizer.synthesizer import initial_positions_win
    spec = read_specification(args.specification)
    start = time.process_time()
    game = SymbolicGame(spec)
    solver = Solver(game)
    solution = solve_system_game(solver)
    if not initial_positions_win(game, solution.winning, robotics_semantics=False):
        print('unrealizable')
        return 2
    solver.reordering.stop()
    strategy = symbolic_strategy(game, solution)
    built = time.process_time()
    problems = check_symbolic_strategy(spec, strategy, game.bdd)
    checked = time.process_time()
    del strategy
    print(f"{'ok' if not problems else 'FAILED: ' + problems[0]} (strategy relations "
          f'{built - start:.1f} s, check {checked - built:.1f} s)')
    return 1 if problems else 0


if __name__ == '__main__':
    import sys
    from pathlib import Path
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    sys.exit(main())


class _Labels:
    """Which assumptions and which goals an edge (a full transition's values) satisfies: what the
    fairness checks of strategies and counter-strategies read off their cycles. Each formula is
    evaluated once per valuation of the variables it depends on (strategies have hundreds of
    thousands of edges, liveness formulas a few variables)."""

    def __init__(self, bdd, assumptions, goals):
        self.bdd = bdd
        self.assumption_count = len(assumptions)
        self.formulas = [(formula, sorted(bdd.support(formula)), {}) for formula in (*assumptions, *goals)]

    def __call__(self, transition: dict) -> tuple[tuple, tuple]:
        holds = []
        for formula, support, memo in self.formulas:
            key = tuple(transition.get(variable) for variable in support)
            if key not in memo:
                values = {variable: transition[variable] for variable in support if variable in transition}
                memo[key] = (self.bdd.let(values, formula) if values else formula) == self.bdd.true
            holds.append(memo[key])
        return tuple(holds[:self.assumption_count]), tuple(holds[self.assumption_count:])
