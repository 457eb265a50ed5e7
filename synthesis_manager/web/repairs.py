"""``RepairSearches``: "Suggest fixes" (``POST /api/repair``), verified changes that make a job's
request possible (``ltl_specification.repair``), each search in a child process."""

from __future__ import annotations

import dataclasses
import logging
import queue
import threading

from ltl_specification.repair_process import RepairSearch, RepairSearchError, repair_settings
from respec.vocabulary.errors import CodedError
from synthesis_manager.limits import BusyError
from synthesis_manager.web.errors import NotAvailableError
from synthesis_manager.web.jobs import JobRequest

logger = logging.getLogger(__name__)

REPAIR_TIME_BUDGET = 10.0   # seconds a "Suggest fixes" search may take (ltl_specification.repair's default)
REPAIR_MAX_PROPOSALS = 5


@dataclasses.dataclass
class RepairRun:
    """A running repair search (``RepairSearches.start``): its answers, and a stop."""

    answers: queue.Queue = dataclasses.field(default_factory=queue.Queue)
    stopped: threading.Event = dataclasses.field(default_factory=threading.Event)
    search: RepairSearch | None = None

    def stop(self) -> None:
        """End the search now (its child is killed); no answer comes after."""
        self.stopped.set()
        if self.search is not None:
            self.search.stop()


class RepairSearches:
    """Repair searches on the robot systems the GUI has (perhaps a remote suite's): ``systems()``
    names them, ``robot_system(name)`` loads one. A search takes a child process and a core for
    up to ``time_budget`` seconds: at most ``max_at_once`` run at once."""

    def __init__(self, systems, robot_system, stopping: threading.Event, max_at_once: int = 2,
                 time_budget: float = REPAIR_TIME_BUDGET):
        self.systems = systems
        self.robot_system = robot_system
        self.stopping = stopping
        self.max_at_once = max_at_once
        self.time_budget = time_budget
        self._slots = threading.BoundedSemaphore(max_at_once)
        self._searches: set[RepairSearch] = set()
        self._lock = threading.Lock()

    def repair(self, body) -> dict:
        """The whole answer, as ``Repairs.to_dict()`` (see :meth:`start`)."""
        answers = self.start(body).answers
        while True:
            kind, value = answers.get()
            if kind == 'error':
                raise value
            if kind == 'result':
                return value

    def start(self, body) -> RepairRun:
        """Start searching for fixes of a job's request, for at most ``time_budget`` seconds. Its
        ``answers`` queue gets ``('proposal', dict)`` as each proposal is verified, then
        ``('result', Repairs.to_dict())`` or ``('error', GuiRequestError)``; ``stop()`` ends it
        (a client that went away).

        Beyond max_at_once: BusyError (429, Retry-After), nothing is searched."""
        from ltl_specification.repair import TaskRequest

        if self.stopping.is_set():
            raise BusyError('the server is stopping', 'repairs')
        request = JobRequest.from_json(body, self.systems())
        robot = self.robot_system(request.system)
        if not self._slots.acquire(blocking=False):
            raise BusyError(f'{self.max_at_once} repair searches are running (at most {self.max_at_once} at once); '
                            'try again when one has finished', 'repairs', retry_after=int(self.time_budget))
        task = TaskRequest(request.system, request.initial_conditions, request.goals, request.sm_outcomes,
                           request.unordered)
        settings = repair_settings(robot, task.to_dict(), request.custom_ltl, self.time_budget,
                                   REPAIR_MAX_PROPOSALS)
        run = RepairRun()
        threading.Thread(target=self._search, args=(settings, run), name='gui-repair', daemon=True).start()
        return run

    def _search(self, settings: dict, run: RepairRun):
        """One search, its slot released when it ends, however it ends."""
        answers = run.answers
        search = None
        try:
            search = run.search = RepairSearch(settings)
            with self._lock:
                self._searches.add(search)
            if self.stopping.is_set() or run.stopped.is_set():
                search.stop()
            answers.put(('result', search.run(lambda proposal: answers.put(('proposal', proposal)))))
        except CodedError as error:  # the system's files as the compiler refuses them
            answers.put(('error', NotAvailableError(str(error), error.item or settings['system'])))
        except Exception as error:  # RepairSearchError, or the child could not start
            if not isinstance(error, RepairSearchError):
                logger.exception('repair search failed')
            answers.put(('error', NotAvailableError(str(error), 'repair search')))
        finally:
            with self._lock:
                self._searches.discard(search)
            self._slots.release()

    def stop_all(self) -> None:
        """The server is stopping: end the running searches' children."""
        with self._lock:
            running = list(self._searches)
        for search in running:
            search.stop()
