"""``JobQueue``: the GUI's synthesis jobs, each run by ``run_goal`` in a worker thread."""

from __future__ import annotations

import itertools
import logging
import threading
import uuid
from collections import OrderedDict
from typing import Callable

from respec.vocabulary.errors import INTERNAL_ERROR, ErrorCode, quoted
from sm_generation.state_machine import StateMachine
from synthesis_manager.limits import BusyError
from synthesis_manager.web.errors import NotAvailableError, NotFoundError
from synthesis_manager.web.jobs import Job, JobRequest, ProgressNote, update_record
from synthesis_manager.web.outcome import JobOutcome

logger = logging.getLogger(__name__)

GoalRunner = Callable[[JobRequest, Callable[[str, float], None], threading.Event], JobOutcome]


class JobQueue:
    """Jobs run by ``run_goal(request, feedback, cancel) -> JobOutcome`` in worker threads.

    ``run_goal`` calls ``feedback(status, progress)`` as the pipeline advances and stops
    (returning a PREEMPTED outcome) once ``cancel`` is set. ``systems()`` names the systems a
    request may name. At most ``max_jobs`` are kept (the oldest finished ones are forgotten, and
    ``on_forget(job_id)`` callbacks drop what hangs on them), at most ``max_unfinished`` at once.

    Test hook: ``gate`` is a set Event; while a test clears it, new jobs wait in the ``queued``
    state before anything is sent, which makes cancelling them deterministic.
    """

    def __init__(self, run_goal: GoalRunner, systems: Callable[[], list[str]], stopping: threading.Event,
                 max_jobs: int = 100, max_unfinished: int = 50):
        self.run_goal = run_goal
        self.systems = systems
        self.stopping = stopping
        self.max_jobs = max_jobs
        self.max_unfinished = max_unfinished
        self.gate = threading.Event()
        self.gate.set()
        self.on_forget: list[Callable[[str], None]] = []
        self._jobs: OrderedDict[str, Job] = OrderedDict()
        self._lock = threading.Lock()
        self.counter = itertools.count(1)  # ids of jobs and of their simulations

    def start(self, body) -> Job:
        if self.stopping.is_set():
            raise BusyError('the server is stopping', 'jobs')
        request = JobRequest.from_json(body, self.systems())
        job = Job(id=f'{next(self.counter)}-{uuid.uuid4().hex[:8]}', request=request)
        with self._lock:
            unfinished = sum(1 for other in self._jobs.values() if not other.finished)
            if unfinished >= self.max_unfinished:
                raise BusyError(f'{unfinished} jobs are unfinished (at most {self.max_unfinished}); '
                                'try again when one has finished', 'jobs')
            self._jobs[job.id] = job
            self._forget_old_jobs()
        threading.Thread(target=self._work, args=(job,), name=f'gui-job-{job.id}', daemon=True).start()
        return job

    def cancel(self, job_id: str) -> Job:
        job = self.job(job_id)
        if job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has already finished '
                                    f'({job.finished_outcome.error_name})', job_id)
        job.cancel_requested.set()
        self._note(job, 'Cancel requested', job.progress)
        return job

    def cancel_unfinished(self) -> None:
        """The server is stopping: cancel every unfinished job (its goal too)."""
        with self._lock:
            unfinished = [job for job in self._jobs.values() if not job.finished]
        for job in unfinished:
            job.cancel_requested.set()

    def job(self, job_id: str) -> Job:
        """The job called ``job_id`` (NotFoundError if unknown or forgotten)."""
        with self._lock:
            job = self._jobs.get(job_id)
        if job is None:
            raise NotFoundError(f'unknown job {quoted(job_id)}', job_id)
        return job

    def finished_job(self, job_id: str) -> Job:
        """The job called ``job_id`` once it has finished (NotAvailableError before)."""
        job = self.job(job_id)
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        return job

    def revision(self, job_id: str) -> int:
        return self.job(job_id).revision

    def state_machine(self, job_id: str) -> StateMachine:
        """The job's state machine (its tree, as the job's outcome holds it)."""
        job = self.finished_job(job_id)
        machine = job.finished_outcome.machine
        if machine is None:
            raise NotAvailableError(f'job {quoted(job_id)} ({job.finished_outcome.error_name}) has no state machine',
                                    job_id)
        return machine

    def _forget_old_jobs(self):
        """Drop the oldest finished jobs beyond max_jobs, and what hangs on them. Holds _lock."""
        finished = [job_id for job_id, job in self._jobs.items() if job.finished]
        for job_id in finished[:max(0, len(self._jobs) - self.max_jobs)]:
            del self._jobs[job_id]
            for forget in self.on_forget:
                forget(job_id)

    def _work(self, job: Job):
        while not self.gate.wait(0.05):
            if job.cancel_requested.is_set():
                break
        if job.cancel_requested.is_set():  # never sent: nothing to cancel downstream
            self._finish(job, JobOutcome.local(ErrorCode.PREEMPTED, 'cancelled before it was sent',
                                               job.seconds_since_created()))
            return
        update_record(job, self._lock, state='running', status='sending the goal')

        try:
            outcome = self.run_goal(job.request, lambda status, progress: self._note(job, status, progress),
                                    job.cancel_requested)
        except Exception as error:  # the GUI keeps serving whatever the runner does
            logger.exception('job %s failed', job.id)
            outcome = JobOutcome.local(INTERNAL_ERROR, f'the GUI could not run the goal: {error}',
                                       job.seconds_since_created())
        self._finish(job, outcome)

    def _note(self, job: Job, status: str, progress: float):
        """A new status of ``job``: shown now and kept in its timeline."""
        note = ProgressNote(job.seconds_since_created(), status, round(float(progress), 4))
        update_record(job, self._lock, status=status, progress=float(progress), timeline=job.timeline + [note])

    def _finish(self, job: Job, outcome: JobOutcome):
        if outcome.cancelled:
            self._note(job, 'Cancelled', job.progress)
        update_record(job, self._lock, state='finished', outcome=outcome, status=outcome.error_name,
                      finished_after=job.seconds_since_created(),
                      progress=1.0 if outcome.succeeded else job.progress)
