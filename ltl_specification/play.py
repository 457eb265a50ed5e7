"""Play the robot against the environment of an unrealizable task, step by step (ROS-free).

LTLMoP's "Mopsy" and Spectra's counter-strategy walker let a user feel why a specification is
unrealizable: the user makes the system's moves, the tool answers with the environment's
winning moves. Here the environment follows its counter-strategy (``ltl_synthesizer``'s
``EnvironmentStrategy``, slugs' ``--counterStrategy`` unfolded only along the user's play):
at every step it has chosen its next inputs, and the user picks one of the responses the
robot's safety requirements allow. Whatever the user picks, the environment keeps one system
goal from ever holding (the counter-strategy's rank names it) or leaves the robot no allowed
response at all (a deadlock).

A play is given by the indices of the moves chosen so far, so the HTTP API above it is
stateless: ``RobotPlay(spec, meanings).turn([2, 0, 1])``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Mapping, Sequence

from respec.ltl import to_infix
from respec.spec import GR1Specification
from ltl_synthesizer.gr1 import Solver, solve_environment_game
from ltl_synthesizer.interrupt import Limits
from ltl_synthesizer.strategy import EnvironmentStrategy, Position, losing_initial_positions
from ltl_synthesizer.symbolic import SymbolicGame

MAX_MOVES = 64          # responses listed at one step (the first ones, deterministic order)
MAX_PLAY_STEPS = 500    # a play longer than this is refused (the API is stateless)


class PlayError(ValueError):
    """A play that does not exist: a move index out of range, a play too long, a realizable task."""


@dataclass
class Move:
    """One response the robot may choose: its index and what it does, in words."""

    index: int
    words: str
    dead_end: bool = False   # the environment can answer it so that no response is allowed
    repeats: bool = False    # it returns to a position of this play: the play goes round in a loop


@dataclass
class RobotTurn:
    """Where a play stands: the position in words, and the robot's choices from here."""

    step: int
    values: dict[str, bool | None]       # every proposition at this position
    happened: str                        # what turned true on the way here
    environment_next: str                # what the environment does next, whatever the robot does
    moves: list[Move] = field(default_factory=list)
    more_moves: int = 0                  # responses not listed (beyond MAX_MOVES)
    blocked_goal: str = ''               # the system goal the environment keeps from holding
    lost: str = ''                       # set when the robot has no allowed move left
    history: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class RobotPlay:
    """The environment's counter-strategy for ``spec`` (which must be unrealizable), walked along
    the user's moves. ``meanings`` say what a proposition turning true means in words
    (``Provenance.meanings``); other propositions are named as they are."""

    def __init__(self, spec: GR1Specification, meanings: Mapping[str, str] | None = None,
                 robotics_semantics: bool = True, limits: Limits = Limits()) -> None:
        self.game = SymbolicGame(spec, None, limits.interrupt())
        solution = solve_environment_game(Solver(self.game))
        initial = losing_initial_positions(self.game, solution.winning, robotics_semantics)
        if initial == self.game.false:
            raise PlayError('the task is realizable: the environment has no winning play to show')
        self.environment = EnvironmentStrategy(self.game, solution)
        self.meanings = dict(meanings or {})
        self.goals = [to_infix(goal) for goal in spec.sys_liveness]
        first, _ = self.game.pick(initial, self.game.variables)
        self.start: Position = (tuple(first[name] for name in self.game.variables),
                      (0, self.environment.first_blockable_goal(first)))

    def turn(self, moves: Sequence[int]) -> RobotTurn:
        """The position after the robot's ``moves`` (indices into each step's moves)."""
        if len(moves) > MAX_PLAY_STEPS:
            raise PlayError(f'a play of {len(moves)} steps is longer than {MAX_PLAY_STEPS}')
        previous: dict[str, bool | None]
        history: list[str]
        position, previous, history = self.start, {}, []
        visited = {position}
        for step, chosen in enumerate(moves):
            successors = self._successors(position)
            if not successors or not isinstance(chosen, int) or not 0 <= chosen < len(successors):
                raise PlayError(f'move {chosen!r} at step {step} does not exist '
                                f'({len(successors)} move(s) there)')
            history.append(self._changed(self._values(position), self._values(successors[chosen])) or
                           'nothing changes')
            previous, position = self._values(position), successors[chosen]
            visited.add(position)
        return self._describe(position, previous, history, len(moves), visited)

    # --- the counter-strategy along the play ----------------------------------------------------

    def _successors(self, position: Position) -> list[Position]:
        values, rank = position
        if None in values:
            return []
        return self.environment.successors(dict(zip(self.game.variables, values)), rank, False)

    def _is_dead_end(self, position: Position) -> bool:
        following = self.environment.successors(self._values(position), position[1], True)
        return bool(following) and None in following[0][0]

    def _values(self, position: Position) -> dict[str, bool | None]:
        return dict(zip(self.game.variables, position[0]))

    def _describe(self, position: Position, previous: Mapping[str, bool | None], history: list[str], step: int,
                  visited: set[Position]) -> RobotTurn:
        values = self._values(position)
        happened = self._changed(previous, values) if step else self._changed({}, values) or 'nothing holds'
        turn = RobotTurn(step, values, happened or 'nothing changes', '', history=history)
        successors = self._successors(position)
        if None in position[0]:
            turn.lost = ('The environment answered so that no response of the robot is allowed by its '
                         'safety requirements: the robot is stuck (a deadlock).')
            return turn
        inputs = set(self.game.inputs)
        following = self._values(successors[0])
        turn.environment_next = self._changed(values, {k: v for k, v in following.items() if k in inputs},
                                              only=inputs) or 'no input changes'
        if None in successors[0][0]:
            answer = '' if turn.environment_next == 'no input changes' else f' with {turn.environment_next}'
            turn.lost = (f'Whatever the robot does now, the environment answers{answer} so that no '
                         'response is allowed by its safety requirements (a deadlock).')
            return turn
        outputs = {name for name in self.game.variables if name not in inputs}
        for index, successor in enumerate(successors[:MAX_MOVES]):
            chosen = self._values(successor)
            words = self._changed(values, chosen, only=outputs, with_off=True) or 'keep every output as it is'
            turn.moves.append(Move(index, words, self._is_dead_end(successor), successor in visited))
        turn.moves.sort(key=lambda move: move.dead_end)   # the moves worth trying first
        turn.more_moves = max(0, len(successors) - MAX_MOVES)
        goal = position[1][1]
        if goal < len(self.goals):
            turn.blocked_goal = (f'the environment keeps system goal {goal + 1} ({self.goals[goal]}) from ever '
                                 'holding, whichever move the robot makes')
        return turn

    def _changed(self, before: Mapping[str, bool | None], after: Mapping[str, bool | None],
                 only: set[str] | None = None, with_off: bool = False) -> str:
        """What turned true (in words), and with ``with_off`` what turned false."""
        names = [n for n in self.game.variables if n in after and (only is None or n in only)]
        on = [self.meanings.get(n, n) for n in names if after[n] and not before.get(n)]
        off = [f'{n} off' for n in names if with_off and not after[n] and before.get(n)]
        return ', '.join(on + off)
