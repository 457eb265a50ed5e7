"""Human-readable reasons why a specification is unrealizable.

The explanation names (a) the initial positions that lose, (b) the system liveness goal the
environment can block, by index and infix text, (c) a short environment play that
demonstrates it, and (d) a system deadlock (a reachable position where the environment can
move so that no output satisfies SYS_TRANS), naming a minimal set of conflicting SYS_TRANS
formulas.
"""

from __future__ import annotations

from typing import Any, Iterable, Sequence

from respec.ltl import to_infix

from ltl_synthesizer.gr1 import EnvironmentSolution, SystemSolution
from ltl_synthesizer.strategy import enumerate_states, extract_counterstrategy, losing_initial_positions
from ltl_synthesizer.cudd_import import Node
from ltl_synthesizer.symbolic import SymbolicGame

MAX_LISTED_STATES = 3
PLAY_LENGTH = 8
PLAY_HEADING = 'Environment play (counter-strategy'


def _true_set(names: Iterable[str], values: Iterable[object]) -> str:
    chosen = [name for name, value in zip(names, values) if value]
    return '{' + ', '.join(chosen) + '}'


def _goal_text(game: SymbolicGame, index: int) -> str:
    goals = game.spec.sys_liveness
    if not goals:
        return 'the implicit system goal TRUE'
    return f"system liveness #{index} '{to_infix(goals[index])}'"


def explain_unrealizable(game: SymbolicGame, system: SystemSolution,
                         environment: EnvironmentSolution, robotics_semantics: bool) -> str:
    lines = _initial_conditions(game, system, environment, robotics_semantics)
    play = extract_counterstrategy(game, environment, robotics_semantics, play_length=PLAY_LENGTH)
    lines += _blocked_goal_and_play(game, play)
    return '\n'.join(lines)


def without_play(explanation: str) -> str:
    """``explanation`` without its environment play (and the deadlock found at the play's end),
    for a caller that tells its own play of the same counter-strategy: what remains is what the
    synthesizer adds (the losing initial states, the goal the environment blocks)."""
    lines = explanation.split('\n')
    heading = next((i for i, line in enumerate(lines) if line.startswith(PLAY_HEADING)), None)
    if heading is None:
        return explanation
    return '\n'.join(lines[:heading])


def _initial_conditions(game: SymbolicGame, system: SystemSolution, environment: EnvironmentSolution,
                        robotics_semantics: bool) -> list[str]:
    initial = game.env_init & game.sys_init
    if game.env_init == game.false:
        return ['ENV_INIT is unsatisfiable.']
    if initial == game.false:
        return ['No initial state satisfies both ENV_INIT and SYS_INIT '
                '(the system initial conditions contradict the environment ones).']
    if system.complete and system.winning == game.false:
        where = 'reachable ' if system.reachable_only else ''
        header = f'No {where}position is winning for the system (the environment wins from everywhere).'
    else:
        header = None
    losing = losing_initial_positions(game, environment.winning, robotics_semantics)
    if losing == game.false:
        # The system solver stopped early; fall back to its own view of the initial positions.
        losing = initial & ~system.winning
    lines = [header] if header else []
    # Counted symbolically and listed up to a few: there may be astronomically many.
    if robotics_semantics:
        count = _count(game, losing, game.variables)
        lines.append(f'{count} initial state(s) allowed by ENV_INIT and SYS_INIT are losing '
                     '(robotics semantics requires all to be winning); true propositions:')
        for state in enumerate_states(game, losing, game.variables, limit=MAX_LISTED_STATES):
            lines.append('  ' + _true_set(game.variables, [state[v] for v in game.variables]))
    else:
        losing_inputs = game.bdd.exist(game.outputs, losing)
        count = _count(game, losing_inputs, game.inputs)
        lines.append(f'For {count} initial input valuation(s) allowed by ENV_INIT no system '
                     'initial values allowed by SYS_INIT are winning; true inputs:')
        for state in enumerate_states(game, losing_inputs, game.inputs, limit=MAX_LISTED_STATES):
            lines.append('  ' + _true_set(game.inputs, [state[v] for v in game.inputs]))
    if count > MAX_LISTED_STATES:
        lines.append(f'  ... and {count - MAX_LISTED_STATES} more')
    return lines


def _count(game: SymbolicGame, u: Node, names: Sequence[str]) -> int:
    """The number of assignments to ``names`` in ``u`` (which depends on no other variable)."""
    return int(game.bdd.count(u, nvars=len(names))) if names else int(u == game.true)


def _blocked_goal_and_play(game: SymbolicGame, play: dict[str, Any]) -> list[str]:
    nodes = play['nodes']
    if not nodes:
        return []
    first = nodes['0']
    _, blocked = first['rank']
    lines = []
    names = game.variables
    n_inputs = len(game.inputs)
    steps = []
    deadlock = None
    node_name = '0'
    visited = []
    while node_name in nodes and node_name not in visited:
        visited.append(node_name)
        node = nodes[node_name]
        steps.append(node)
        if None in node['state']:
            deadlock = (steps[-2] if len(steps) > 1 else None, node)
            break
        if not node['trans']:
            break
        node_name = str(node['trans'][0])
    if deadlock is None:
        lines.append(f'The environment can prevent {_goal_text(game, blocked)} from holding '
                     'infinitely often, while satisfying all of its own assumptions.')
    lines.append(f'{PLAY_HEADING}; inputs chosen by the environment, '
                 'outputs one legal system response):')
    for step, node in enumerate(steps):
        inputs = _true_set(names[:n_inputs], node['state'][:n_inputs])
        if None in node['state']:
            lines.append(f'  step {step}: inputs {inputs} -> no output satisfies SYS_TRANS (deadlock)')
            continue
        outputs = _true_set(names[n_inputs:], node['state'][n_inputs:])
        alternatives = node.get('responses', len(node['trans']))
        lines.append(f'  step {step}: inputs {inputs} outputs {outputs}'
                     + (f'  ({alternatives} system responses next)' if alternatives > 1 else ''))
    if node_name in visited and deadlock is None:
        lines.append(f'  ... step {len(steps)} repeats step {visited.index(node_name)}: '
                     'the environment can loop forever.')
    if deadlock is not None and deadlock[0] is not None:
        lines += _deadlock(game, deadlock[0], deadlock[1])
    return lines


def _deadlock(game: SymbolicGame, before: dict[str, Any], dead: dict[str, Any]) -> list[str]:
    """Name a minimal set of SYS_TRANS formulas that no output can satisfy together."""
    state = {name: bool(value) for name, value in zip(game.variables, before['state'])}
    for name, value in zip(game.inputs, dead['state']):
        state[game.to_next[name]] = bool(value)
    restricted = [(index, game.bdd.let(state, part)) for index, part in enumerate(game.sys_trans_parts)]
    conflict = [(index, part) for index, part in restricted if part != game.true]
    # Deletion-based minimisation: drop each formula that is not needed for the conflict.
    position = 0
    while position < len(conflict):
        rest = conflict[:position] + conflict[position + 1:]
        together = game.true
        for _, part in rest:
            together &= part
        if together == game.false:
            conflict = rest
        else:
            position += 1
    lines = ['System deadlock (a safety requirement cannot be met): in state '
             + _true_set(game.variables, before['state'])
             + ' the environment can set the inputs to '
             + _true_set(game.inputs, dead['state'][:len(game.inputs)])
             + ', and then no outputs satisfy these SYS_TRANS formulas together:']
    for index, _ in conflict:
        lines.append(f'  sys_trans #{index}: {to_infix(game.spec.sys_trans[index])}')
    return lines
