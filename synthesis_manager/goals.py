"""What the action servers do with a goal, apart from ROS (ROS-free): what a goal produced
(:class:`PipelineOutcome`), how many goals run at once (:class:`GoalAdmission`), when a
refused goal gets suggested fixes, and the names and texts a goal's pipeline uses.
"""

from __future__ import annotations

import contextlib
import threading
from dataclasses import dataclass, field
from typing import Any, Callable

from ltl_specification.repair import REPAIRABLE
from respec.vocabulary.errors import ErrorCode
from synthesis_manager.client_shares import ClientShares, Ticket
from synthesis_manager.limits import BusyError
from synthesis_manager.requests import SynthesisTask

#: Seconds past synthesis_timeout the synthesis node has to answer (a goal's own limit gets none).
SYNTHESIS_ANSWER_GRACE = 1.0
#: Fixes a refused goal's result suggests, and how long their search may take: its budget (the
#: problem's diagnosis included), plus a child interpreter's start and its answer.
MAX_SUGGESTED_FIXES = 3
REPAIR_DEADLINE_FACTOR = 1.0
REPAIR_STARTUP_GRACE = 3.0


@dataclass
class PipelineOutcome:
    """What a goal produced, whichever action it came through (``ltl_specification`` and
    ``automaton``: the stages' messages, None until a stage gave them)."""

    code: ErrorCode = ErrorCode.SUCCESS
    message: str = ''
    ltl_specification: Any = None      # synthesis_msgs' LTLSpecification (generated, untyped)
    automaton: Any = None              # synthesis_msgs' FSAutomaton
    states: list = field(default_factory=list)
    notes: list = field(default_factory=list)  # what the result should tell, e.g. detected initial conditions
    fixes: list = field(default_factory=list)  # verified fixes of a refused task, one sentence each

    def message_with_fixes(self) -> str:
        """The message, followed by the suggested fixes when there are any."""
        if not self.fixes:
            return self.message
        return (f'{self.message}\n\nVerified fixes (each compiled and synthesized, and found realizable; '
                '`behavior-synthesis repair` with the same task lists more):\n'
                + '\n'.join(f'  {line}' for line in self.fixes))

    @property
    def succeeded(self) -> bool:
        return self.code == ErrorCode.SUCCESS

    def fail(self, code: ErrorCode, message: str):
        self.code, self.message = code, message

    def suggest(self, summaries) -> None:
        """Keep the verified fixes a repair search found (their one-sentence summaries)."""
        self.fixes = [f'Suggested fix {number}: {summary}' for number, summary in enumerate(summaries, 1)]


def wants_fixes(budget: float, outcome: PipelineOutcome, task: SynthesisTask) -> bool:
    """Whether a failed goal's task is searched for verified fixes: refused as impossible (a
    REPAIRABLE code), not a given specification, and with a search budget."""
    return budget > 0 and str(outcome.code) in REPAIRABLE and task.option != 'ltl_synthesis_only'


def repair_wait(budget: float) -> float:
    """Seconds to wait for a repair search of ``budget`` seconds."""
    return budget * REPAIR_DEADLINE_FACTOR + REPAIR_STARTUP_GRACE


def byproduct_name(task: SynthesisTask, goal_id: str) -> str:
    """The spec name a goal's byproduct files get: the task's, else its system and goal id's start."""
    return task.byproduct_stem or f'{task.system or "behavior"}_{goal_id[:8]}'


def share_waiting_message(shares: ClientShares, ticket: Ticket, place: int) -> str:
    """The feedback of a goal waiting for its client's running goals."""
    return (f'Waiting: {shares.running(ticket.origin)} goals of this client are running '
            f'(max_client_goals {shares.max_running}, max_client_goal_seconds '
            f'{shares.max_seconds:g}); this goal is number {place} of its waiting goals')


class GoalAdmission:
    """How many goals a server takes at once (``max_active()``, read at each goal): beyond
    that many running, the next ones are answered BUSY (a result); beyond twice that many
    accepted and unfinished (a flood), they are rejected on arrival."""

    def __init__(self, max_active: Callable[[], int]):
        self.max_active = max_active
        self._lock = threading.Lock()
        self._active = 0
        self._accepted = 0  # accepted and not finished: running, or waiting for the executor

    def accept(self) -> bool:
        """Whether a goal arriving now is accepted (counted until :meth:`finished`)."""
        with self._lock:
            if self._accepted >= 2 * self.max_active():
                return False
            self._accepted += 1
        return True

    def finished(self) -> None:
        with self._lock:
            self._accepted -= 1

    @contextlib.contextmanager
    def running(self):
        """Count a goal in while it runs; raise BusyError when max_active goals are running."""
        limit = self.max_active()
        with self._lock:
            if self._active >= limit:
                raise BusyError(f'the server is busy: {self._active} goals in progress '
                                f'(max_active_goals {limit}); try again later')
            self._active += 1
        try:
            yield
        finally:
            with self._lock:
                self._active -= 1
