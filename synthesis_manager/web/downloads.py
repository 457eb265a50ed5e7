"""``Downloads``: a finished job's downloads (web/artifacts.py), each built once and kept with the job."""

from __future__ import annotations

import logging
import threading

from respec.vocabulary.errors import CodedError, quoted
from synthesis_manager.web.artifacts import ARTIFACTS, Artifact, download_filename
from synthesis_manager.web.errors import ArtifactFailedError, NotAvailableError, NotFoundError
from synthesis_manager.web.job_queue import JobQueue

logger = logging.getLogger(__name__)


class Downloads:
    """The downloads of ``jobs``' finished jobs; ``catalog`` loads a job's robot system (its FlexBE mapping)."""

    def __init__(self, jobs: JobQueue, catalog):
        self.jobs = jobs
        self.catalog = catalog
        self._built: dict[tuple[str, str], Artifact] = {}
        self._lock = threading.Lock()
        jobs.on_forget.append(self.forget_job)

    def artifact(self, job_id: str, name: str) -> Artifact:
        job = self.jobs.job(job_id)
        if name not in ARTIFACTS:
            raise NotFoundError(f'unknown artifact {quoted(name)} (artifacts: {", ".join(ARTIFACTS)})', name)
        if not job.finished:
            raise NotAvailableError(f'job {quoted(job_id)} has not finished yet', job_id)
        kind = ARTIFACTS[name]
        if not kind.present(job.finished_outcome):
            raise NotAvailableError(
                f'job {quoted(job_id)} ({job.finished_outcome.error_name}) has no {name}', name)
        key = (job_id, name)
        with self._lock:
            built = self._built.get(key)
        if built is None:
            try:
                content = kind.build(job.outcome, job.request, self.catalog)
            except Exception as error:  # e.g. RenderError when Graphviz is missing; keep serving
                if not isinstance(error, CodedError):
                    logger.exception('building %s of job %s failed', name, job_id)
                raise ArtifactFailedError(f'cannot make {name}: {error}',
                                          getattr(error, 'item', '') or name) from error
            built = Artifact(content, kind.media_type, download_filename(job.request, name))
            with self._lock:
                self._built[key] = built
        return built

    def forget_job(self, job_id: str) -> None:
        """Drop the downloads of a forgotten job."""
        with self._lock:
            for key in [k for k in self._built if k[0] == job_id]:
                del self._built[key]
