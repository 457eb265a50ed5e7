"""Playing the robot against the environment as a game with an end (the page's side of
``ltl_specification.play.RobotPlay``, which walks the environment's counter-strategy).

The counter-strategy's turn is told in the task's words (a state that stops, not ``stand_a off``),
the moves that make progress first (a state starts), then the others, then the loops and the
dead ends; the line saying which goal the environment blocks is given once, when it is new; and
every play ends with a verdict within MAX_GAME_MOVES moves: the environment wins by a deadlock,
by a loop (the robot came back to a position of the play, so it can go round forever), or by
keeping a goal from holding for MAX_GAME_MOVES moves; or "you reached every goal".
"""

from __future__ import annotations

import re

from ltl_specification.play import PlayError
from respec.ltl import Or, Var, partial_evaluate, to_infix
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES, activated

MAX_GAME_MOVES = 12
ACTIVATION_STARTS = ' starts'
_OFF = re.compile(r'^(\S+) off$')
_BLOCKED = re.compile(r'system goal (\d+) \(')


def game_turn(play, spec, meanings: dict, moves: list[int]) -> dict:
    """The turn after ``moves`` as the page shows it (RobotTurn's fields, reworded and ordered,
    plus ``verdict``, ``max_moves`` and ``goals``)."""
    if len(moves) > MAX_GAME_MOVES:
        raise PlayError(f'a play ends within {MAX_GAME_MOVES} moves; {len(moves)} were sent')
    turn = play.turn(moves).to_dict()
    raw_blocked = turn['blocked_goal']
    words = _Words(spec, meanings)
    goals = [words.goal(formula) for formula in spec.sys_liveness]
    path = [play.turn(moves[:k]).values for k in range(len(moves))] + [turn['values']]
    reached = [any(_holds(formula, values) for values in path) for formula in spec.sys_liveness]
    previous = play.turn(moves[:-1]).to_dict() if moves else None
    looped = previous is not None and any(m['index'] == moves[-1] and m['repeats'] for m in previous['moves'])
    turn['history'] = [words.move(line) for line in turn['history']]
    turn['max_moves'] = MAX_GAME_MOVES
    turn['goals'] = [{'words': text, 'reached': done} for text, done in zip(goals, reached)]
    turn['blocked_goal'] = words.blocked(turn['blocked_goal'], goals)
    if previous is not None and words.blocked(previous['blocked_goal'], goals) == turn['blocked_goal']:
        turn['blocked_goal'] = ''  # said already: no line repeated at every step
    blocked = _blocked_index(raw_blocked)
    unreached = next((i for i, done in enumerate(reached) if not done), None)
    goal = blocked if blocked is not None else unreached
    goal_words = f'goal {goal + 1} ({goals[goal]})' if goal is not None else 'a goal'
    if turn['lost']:
        turn['verdict'] = f'the environment wins: {turn["lost"]}'
    elif all(reached):
        turn['verdict'] = 'you reached every goal'
    elif looped:
        turn['verdict'] = (f'the environment wins: the robot came back to a position of this play, so the '
                           f'environment can go round with it forever and {goal_words} never holds')
    elif len(moves) >= MAX_GAME_MOVES:
        turn['verdict'] = (f'the environment wins: after {len(moves)} moves (the most a play has) '
                           f'{goal_words} has never held')
    else:
        turn['verdict'] = ''
    if turn['verdict']:
        turn['moves'], turn['more_moves'] = [], 0
    else:
        turn['moves'] = [{**move, 'words': words.move(move['words'])} for move in _progress_first(turn['moves'])]
    return turn


def _progress_first(moves: list[dict]) -> list[dict]:
    """Moves that start a state first, then the other live moves, the loops, the dead ends."""
    def rank(move):
        if move['dead_end']:
            return 3
        if move['repeats']:
            return 2
        return 0 if ACTIVATION_STARTS + ',' in move['words'] + ',' else 1
    return sorted(moves, key=rank)


def _holds(formula, values: dict) -> bool:
    return partial_evaluate(formula, {name: bool(value) for name, value in values.items() if value is not None}, {}) \
        is True


def _blocked_index(text: str) -> int | None:
    match = _BLOCKED.search(text or '')
    return int(match.group(1)) - 1 if match else None


class _Words:
    """The task's words for propositions (``Provenance.meanings``), goals and moves."""

    def __init__(self, spec, meanings: dict):
        # The state machine's outcomes in words where the task's meanings have none (CNU's robots).
        self.meanings = {**{o: f'the state machine ends {o}' for o in DEFAULT_SM_OUTCOMES if o in spec.sys_props},
                         **meanings}
        self.names = set(spec.env_props) | set(spec.sys_props)

    def off(self, name: str) -> str:
        meaning = self.meanings.get(name, '')
        if activated(name) and meaning.endswith(ACTIVATION_STARTS):
            return meaning[:-len(ACTIVATION_STARTS)] + ' stops'
        if activated(name):
            return f'state {activated(name)} stops'
        return f'{meaning or name} no longer holds'

    def move(self, line: str) -> str:
        """A move's or history line's words, each "<proposition> off" told in the task's words."""
        parts = []
        for part in line.split(', '):
            match = _OFF.match(part)
            parts.append(self.off(match.group(1)) if match and match.group(1) in self.names else part)
        return ', '.join(parts)

    def goal(self, formula) -> str:
        """A system goal in words: a disjunction of propositions as their meanings joined by "or"."""
        disjuncts = _disjuncts(formula)
        if all(isinstance(d, Var) and d.name in self.meanings for d in disjuncts):
            return ' or '.join(self.meanings[d.name] for d in disjuncts)
        return to_infix(formula)

    def blocked(self, text: str, goals: list[str]) -> str:
        index = _blocked_index(text)
        if index is None or index >= len(goals):
            return text or ''
        return (f'the environment keeps goal {index + 1} ({goals[index]}) from ever holding, '
                'whichever move the robot makes')


def _disjuncts(formula) -> list:
    if isinstance(formula, Or):
        return [d for arg in formula.args for d in _disjuncts(arg)]
    return [formula]
