"""Play a finished job (``POST /api/jobs/{id}/play``): the user against the environment or the machine.

An unrealizable job is played as the robot against the environment's counter-strategy
(``ltl_specification.play.RobotPlay``, its task compiled again here, ROS-free, on the job's
robot system); a job with a state machine is played as the environment, reporting the active
state's outcomes (``sm_generation.play.play_machine``). Both are stateless for the client,
which sends every move so far; the server keeps the few newest counter-strategies (solving the
environment's game is the costly part) and plays each under its own lock, since a CUDD manager
serves one thread at a time.
"""

from __future__ import annotations

import threading
from collections import OrderedDict

from ltl_specification import compile_task
from ltl_specification.play import PlayError, RobotPlay
from respec.vocabulary.errors import CodedError, ErrorCode, quoted
from sm_generation.play import MachinePlayError, play_machine
from synthesis_manager.limits import BusyError
from synthesis_manager.web.errors import GuiRequestError, InvalidJobRequestError, NotAvailableError
from synthesis_manager.web.job_queue import JobQueue
from synthesis_manager.web.jobs import Job, checked_body
from synthesis_manager.web.request_form import GOAL_CHECK_RETRY_AFTER
from synthesis_manager.web.robot_game import game_turn

ROBOT, ENVIRONMENT = 'robot', 'environment'   # whom the user plays
KEPT_COUNTER_STRATEGIES = 4


class MoveError(GuiRequestError):
    """A move the play does not have (an index out of range, an outcome the state lacks)."""

    kind = 'BAD_MOVE'


def play_body_moves(body) -> list:
    """The ``moves`` of a play request: a list of move indices or outcome names."""
    if not isinstance(body, dict) or set(body) - {'moves'}:
        raise InvalidJobRequestError('the body must be {"moves": [...]}', 'body')
    moves = body.get('moves', [])
    if not isinstance(moves, list):
        raise InvalidJobRequestError('field "moves" must be a list', 'moves')
    return moves


class Plays:
    """The plays of ``jobs``' finished jobs; ``robot_system(name)`` loads the job's RobotSystem.

    A play is computed in the request's thread, like the goal check (it solves the
    environment's game once): at most ``max_at_once`` at once."""

    def __init__(self, robot_system, jobs: JobQueue, max_at_once: int = 2):
        self.robot_system = robot_system
        self.jobs = jobs
        self.max_at_once = max_at_once
        self._slots = threading.BoundedSemaphore(max_at_once)
        self._lock = threading.Lock()
        self._counter_strategies: OrderedDict[str, tuple[RobotPlay, threading.Lock, object]] = OrderedDict()

    def play(self, job_id: str, body) -> dict:
        """The turn of a play of a finished job after the body's ``moves``.

        Beyond max_at_once plays at once: BusyError (429, Retry-After)."""
        job = self.jobs.job(job_id)
        moves = play_body_moves(checked_body({} if body is None else body))
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        if not self._slots.acquire(blocking=False):
            raise BusyError(f'{self.max_at_once} plays are being computed (at most {self.max_at_once} at once); '
                            'try again in a moment', 'plays', retry_after=GOAL_CHECK_RETRY_AFTER)
        try:
            return self.turn(job, moves)
        finally:
            self._slots.release()

    def turn(self, job: Job, moves: list) -> dict:
        """The turn after ``moves``, with ``play`` saying whom the user plays."""
        outcome = job.finished_outcome
        if outcome.machine is not None:
            return {'play': ENVIRONMENT, **self._machine_turn(job, moves)}
        if outcome.error_name == ErrorCode.SPEC_UNSYNTHESIZABLE:
            return {'play': ROBOT, **self._robot_turn(job, moves)}
        raise NotAvailableError(f'job {quoted(job.id)} ({outcome.error_name}) has nothing to play: neither a state '
                                'machine nor an unrealizable specification', job.id)

    def _machine_turn(self, job: Job, moves: list) -> dict:
        if not all(isinstance(move, str) for move in moves):
            raise InvalidJobRequestError('the moves of a machine play are outcome names', 'moves')
        machine = job.finished_outcome.machine
        assert machine is not None  # turn() plays a machine only where there is one
        try:
            return play_machine(machine, moves).to_dict()
        except MachinePlayError as error:
            raise MoveError(str(error), 'moves') from error

    def _robot_turn(self, job: Job, moves: list) -> dict:
        if not all(isinstance(move, int) and not isinstance(move, bool) for move in moves):
            raise InvalidJobRequestError('the moves of a robot play are move indices (integers)', 'moves')
        play, lock, spec = self._counter_strategy(job)
        with lock:
            try:
                return game_turn(play, spec, play.meanings, moves)
            except PlayError as error:
                raise MoveError(str(error), 'moves') from error

    def _counter_strategy(self, job: Job) -> tuple[RobotPlay, threading.Lock, object]:
        with self._lock:
            if job.id in self._counter_strategies:
                self._counter_strategies.move_to_end(job.id)
                return self._counter_strategies[job.id]
        request = job.request
        try:
            spec = compile_task(self.robot_system(request.system), list(request.initial_conditions),
                                list(request.goals), sm_outcomes=request.sm_outcomes,
                                strict_order=not request.unordered, custom_ltl=request.custom_ltl)
            play = RobotPlay(spec, spec.provenance.meanings if spec.provenance is not None else {})
        except (CodedError, PlayError) as error:  # e.g. the system's files changed since the job
            raise NotAvailableError(f'cannot play job {quoted(job.id)}: {error}', job.id) from error
        with self._lock:
            self._counter_strategies[job.id] = (play, threading.Lock(), spec)
            while len(self._counter_strategies) > KEPT_COUNTER_STRATEGIES:
                self._counter_strategies.popitem(last=False)
            return self._counter_strategies[job.id]
