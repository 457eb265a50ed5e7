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

from ltl_synthesizer.gr1 import EnvironmentSolution, SystemSolution
from ltl_synthesizer.symbolic import SymbolicGame

FORMAT_VERSION = 0
SLUGS_VERSION = '0.0.1'


def goal_steps(game: SymbolicGame, solution: SystemSolution) -> list:
    """Per system goal, its attractor steps by increasing rank."""
    steps = [[] for _ in game.sys_goals]
    for step in solution.attractor_steps:
        steps[step.goal_index].append(step)
    return steps


def goal_moves(game: SymbolicGame, steps, env_moves, legal):
    """The positional strategy of one goal at one position: each environment move is
    answered with the moves of the first attractor step (lowest rank) that offers a response.

    ``env_moves`` (the position's state cube conjoined with env_trans) and ``legal`` (with
    sys_trans too) are small, and every operation here is conjoined with them, so a step
    costs little. Building the strategy relation over all positions costs far more than the
    few positions a strategy visits (seconds on multi-goal tasks), and so does the union of
    the steps' responses that bisecting for the answering steps would need. Conjoining
    rather than cofactoring by the state (``let``) saves a Python-level pass over all
    variables per step. The scan ends at the latest at the first step whose waiting set
    holds the position: that step answers every environment move.
    """
    moves = answered = game.false
    for step in steps:
        offered = step.responses & env_moves
        new_cases = offered & ~answered
        if new_cases == game.false:
            continue
        moves |= step.transitions_among(game, new_cases & legal)
        answered |= offered
        if answered == env_moves:
            break  # every environment move is answered
    return moves


def enumerate_states(game: SymbolicGame, states, names, limit: int | None = None):
    """The assignments to ``names`` in ``states`` (all, or the first ``limit``), smallest first
    (``states`` must depend only on names)."""
    found = []
    while states != game.false and (limit is None or len(found) < limit):
        assignment, single = game.pick(states, names)
        found.append(assignment)
        states &= ~single
    return found


def _successor_goal(game: SymbolicGame, goals, rank: int, transition: dict[str, bool]) -> int:
    """The goal pursued after ``transition``: advance past every goal it satisfies."""
    goal = rank
    first_try = True
    while (goal != rank or first_try) and game.evaluate(goals[goal], transition):
        goal = (goal + 1) % len(goals)
        first_try = False
    return goal


def _moves_from(game: SymbolicGame, state: dict[str, bool]):
    """The moves from one position allowed by env_trans, and those allowed by both safety
    sections, each as the position's state cube conjoined with the relation."""
    env_moves = game.cube(state)
    for cluster in game.env_partition.clusters:
        env_moves &= cluster
    legal = env_moves
    for cluster in game.sys_partition.clusters:
        legal &= cluster
    return env_moves, legal


def extract_strategy(game: SymbolicGame, solution: SystemSolution) -> dict:
    """The explicit strategy as slugs' JSON object (``nodes`` keyed by decimal strings)."""
    steps = goal_steps(game, solution)
    variables = game.variables
    next_names = game.next_inputs + game.next_outputs
    index: dict[tuple, int] = {}
    queue: deque = deque()

    def node_id(values: tuple, rank: int) -> int:
        key = (values, rank)
        if key not in index:
            index[key] = len(index)
            queue.append(key)
        return index[key]

    initial = solution.winning & game.env_init & game.sys_init
    for state in enumerate_states(game, initial, variables):
        node_id(tuple(state[name] for name in variables), 0)

    nodes = {}
    while queue:
        values, rank = queue.popleft()
        game.interrupt.check()
        state = dict(zip(variables, values))
        env_moves, legal = _moves_from(game, state)
        # Without the state cube, the picks below work on smaller BDDs.
        moves = game.bdd.exist(variables, goal_moves(game, steps[rank], env_moves, legal))
        successors = []
        while moves != game.false:
            choice, _ = game.pick(moves, next_names)
            transition = dict(state)
            transition.update(choice)
            next_rank = _successor_goal(game, game.sys_goals, rank, transition)
            next_values = tuple(choice[game.to_next[name]] for name in variables)
            successors.append(node_id(next_values, next_rank))
            # One response per environment move: drop every move with the same next inputs.
            moves &= ~game.cube({name: choice[name] for name in game.next_inputs})
        nodes[str(index[(values, rank)])] = {
            'rank': rank, 'state': [int(v) for v in values], 'trans': successors}
    return {'version': FORMAT_VERSION, 'slugs': SLUGS_VERSION, 'variables': list(variables),
            'nodes': nodes}


def extract_counterstrategy(game: SymbolicGame, solution: EnvironmentSolution,
                            robotics_semantics: bool, play_length: int | None = None) -> dict:
    """The environment's explicit winning strategy (slugs' ``--counterStrategy`` as JSON).

    A node is (valuation, i, j) and its ``rank`` is ``[i, j]``: the environment works towards
    its assumption i while blocking system goal j. The position's level k (first iteration of
    the environment's outer fixpoint that contains it) fixes which moves to use; j stays fixed
    while the play stays on that level and is chosen afresh (the first goal blockable there)
    when it drops to a lower one, so no play can satisfy every system goal. Each node lists
    the system responses allowed by sys_trans to the environment's chosen next input. When the
    environment can pick an input to which no output is allowed by sys_trans, the successor
    is a deadlock node whose outputs are ``null`` and which has no successors.

    With ``play_length``, only one play is unfolded: from the first initial node, always the
    first successor, for at most that many nodes (used to explain unrealizability cheaply).
    """
    goals, assumptions = game.sys_goals, game.env_goals
    # Per level, goal and assumption: the first (lowest X rank) environment moves at each position.
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

    def level_of(state) -> int:
        # Z_k grows with k, so the first level whose blocking sets contain the position.
        return next(k for k, level in enumerate(solution.levels)
                    if any(game.evaluate(blocking, state) for blocking in level.blocking))

    def first_blockable_goal(state, k) -> int:
        return next(j for j, blocking in enumerate(solution.levels[k].blocking)
                    if game.evaluate(blocking, state))

    variables = game.variables
    index: dict[tuple, int] = {}
    queue: deque = deque()
    nodes: dict[str, dict] = {}

    def node_id(values: tuple, rank: tuple) -> int:
        key = (values, rank)
        if key not in index:
            index[key] = len(index)
            queue.append(key)
        return index[key]

    initial = losing_initial_positions(game, solution.winning, robotics_semantics)
    for state in enumerate_states(game, initial, variables, limit=1 if play_length else None):
        values = tuple(state[name] for name in variables)
        node_id(values, (0, first_blockable_goal(state, level_of(state))))

    env_trans = game.env_trans()
    sys_trans = game.sys_trans()
    while queue:
        values, rank = queue.popleft()
        game.interrupt.check()
        if play_length is not None:
            if len(nodes) >= play_length:
                break
            queue.clear()
        assumption, goal = rank
        node = nodes.setdefault(str(index[(values, rank)]), {
            'rank': list(rank), 'state': [None if v is None else int(v) for v in values],
            'trans': []})
        if None in values:  # a deadlock node: nothing follows
            continue
        state = dict(zip(variables, values))
        allowed_env = game.bdd.let(state, env_trans)
        allowed_sys = game.bdd.let(state, sys_trans)
        deadlock_inputs = game.bdd.forall(game.next_outputs, allowed_env & ~allowed_sys)
        if deadlock_inputs != game.false:
            choice, _ = game.pick(deadlock_inputs, game.next_inputs)
            dead_values = tuple(choice[game.to_next[name]] for name in game.inputs) \
                + (None,) * len(game.outputs)
            node['trans'].append(node_id(dead_values, rank))
            continue
        level = level_of(state)
        moves = game.bdd.let(state, strategies[level][goal][assumption])
        chosen_input, input_cube = game.pick(moves, game.next_inputs)
        responses = input_cube & allowed_sys
        if play_length is not None:
            # One play: its first response is followed; the others are only counted.
            node['responses'] = int(game.bdd.count(game.bdd.exist(game.next_inputs, responses),
                                                   nvars=len(game.next_outputs)))
        while responses != game.false and not (play_length is not None and node['trans']):
            choice, single = game.pick(responses, game.next_outputs)
            transition = dict(state)
            transition.update(chosen_input)
            transition.update(choice)
            next_state = {name: transition[game.to_next[name]] for name in variables}
            next_assumption = _successor_goal(game, assumptions, assumption, transition)
            next_level = level_of(next_state)
            next_goal = goal if next_level == level else first_blockable_goal(next_state, next_level)
            next_values = tuple(next_state[name] for name in variables)
            node['trans'].append(node_id(next_values, (next_assumption, next_goal)))
            responses &= ~single
        if play_length is not None:
            queue.clear()
            first = node['trans'][0] if node['trans'] else None
            key = next((k for k, v in index.items() if v == first), None)
            if key is not None and str(first) not in nodes:
                queue.append(key)
    return {'version': FORMAT_VERSION, 'slugs': SLUGS_VERSION, 'variables': list(variables),
            'nodes': nodes}


def losing_initial_positions(game: SymbolicGame, environment_wins, robotics_semantics: bool):
    """The set of initial positions from which the environment wins.

    Robotics semantics: any position allowed by both init sections. Standard semantics: the
    environment picks an initial input for which every system completion loses.
    """
    initial = game.env_init & game.sys_init & environment_wins
    if not robotics_semantics:
        hopeless_inputs = game.bdd.forall(game.outputs, ~game.sys_init | environment_wins)
        initial &= hopeless_inputs
    return initial


def losing_initial_states(game: SymbolicGame, environment_wins, robotics_semantics: bool):
    """The losing initial positions (see losing_initial_positions) as valuations, smallest first."""
    return enumerate_states(game, losing_initial_positions(game, environment_wins, robotics_semantics),
                            game.variables)


def strategy_to_json(strategy: dict) -> str:
    """Print a (counter-)strategy exactly in slugs' ``--jsonOutput`` layout."""
    names = ', '.join(_json_string(name) for name in strategy['variables'])
    lines = [f'{{"version": {strategy["version"]},\n "slugs": {_json_string(strategy["slugs"])},\n\n',
             f' "variables": [{names}],\n\n "nodes": {{\n']
    node_ids = sorted(strategy['nodes'], key=int)
    for position, node_name in enumerate(node_ids):
        node = strategy['nodes'][node_name]
        rank = node['rank']
        rank_text = f'[{rank[0]}, {rank[1]}]' if isinstance(rank, (list, tuple)) else str(rank)
        state = ', '.join('null' if v is None else str(v) for v in node['state'])
        trans = ', '.join(str(t) for t in node['trans'])
        separator = ',' if position + 1 < len(node_ids) else ''
        lines.append(f'"{node_name}": {{\n\t"rank": {rank_text},\n\t"state": [{state}],\n'
                     f'\t"trans": [{trans}]\n}}{separator}\n\n')
    lines.append('}}\n')
    return ''.join(lines)


def _json_string(text: str) -> str:
    import json
    return json.dumps(text)
