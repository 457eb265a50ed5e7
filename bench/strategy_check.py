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
"""

from __future__ import annotations

from dd import cudd

from respec.ltl import And, Const, Iff, Implies, Next, Not, Or, Var


class _Formulas:
    def __init__(self, spec):
        self.bdd = cudd.BDD()
        self.bdd.configure(reordering=False)
        self.variables = list(spec.env_props) + list(spec.sys_props)
        for name in self.variables:
            self.bdd.declare(name, name + "'")
        self._memo = {}

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
    env_init = formulas.conjunction(spec.env_init)
    sys_init = formulas.conjunction(spec.sys_init)
    env_trans = formulas.conjunction(spec.env_trans)
    sys_trans = formulas.conjunction(spec.sys_trans)
    assumptions = [formulas.translate(f) for f in spec.env_liveness] or [bdd.true]
    goals = [formulas.translate(f) for f in spec.sys_liveness] or [bdd.true]
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

    # 2. Moves, 3. edge labels for the fairness check.
    edges = {name: [] for name in nodes}
    for name in nodes:
        state = state_of(name)
        env_here = bdd.let(state, env_trans)
        sys_here = bdd.let(state, sys_trans)
        answered = bdd.false
        for successor in nodes[name]['trans']:
            successor_name = str(successor)
            move = next_cube(state_of(successor_name))
            if bdd.let(move_values(move, bdd), sys_here) != bdd.true:
                problems.append(f'node {name} -> {successor_name} violates SYS_TRANS')
            answered |= bdd.exist([v + "'" for v in spec.sys_props], move)
            transition = {**state, **move_values(move, bdd)}
            labels = (tuple(bdd.let(transition, a) == bdd.true for a in assumptions),
                      tuple(bdd.let(transition, g) == bdd.true for g in goals))
            edges[name].append((successor_name, labels))
        allowed_inputs = bdd.exist([v + "'" for v in spec.sys_props], env_here)
        if allowed_inputs & ~answered != bdd.false:
            problems.append(f'node {name}: some next input allowed by ENV_TRANS has no successor')
        if len(problems) >= limit:
            return problems
    problems += _fairness_problems(edges, len(assumptions), len(goals))
    return problems[:limit]


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
