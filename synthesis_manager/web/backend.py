"""``SynthesisBackend``: the GUI's robot systems, and one object per concern behind the routes.

Each concern is its own module, and the routes call it directly:

    backend.jobs         web/job_queue.py     start, follow and cancel synthesis jobs
    backend.downloads    web/downloads.py     a finished job's downloads
    backend.simulations  web/simulations.py   runs of a job's machine on the simulated robot
    backend.repairs      web/repairs.py       "Suggest fixes"
    backend.plays        web/plays.py         playing a finished job
    backend.form         web/request_form.py  what the request form offers, and its goal check
"""

from __future__ import annotations

import threading
from pathlib import Path

from respec.vocabulary.errors import quoted
from respec.robot import RobotSystem, SystemCatalog
from synthesis_manager.web.downloads import Downloads
from synthesis_manager.web.errors import NotFoundError
from synthesis_manager.web.job_queue import GoalRunner, JobQueue
from synthesis_manager.web.plays import Plays
from synthesis_manager.web.repairs import REPAIR_TIME_BUDGET, RepairSearches
from synthesis_manager.web.request_form import RequestForm
from synthesis_manager.web.simulations import SimulationRuns


class SynthesisBackend:
    """The GUI's work: jobs run by ``run_goal(request, feedback, cancel) -> JobOutcome`` (see
    web/job_queue.py), on the robot systems of the suite (``systems``: SuiteSystems, served over
    ROS, when attached to a running suite) or else of ``config_dir`` (a SystemCatalog).

    The concerns return records (Job, Simulation, the job's StateMachine); the routes turn them
    into JSON. The limits: ``max_jobs`` kept, ``max_unfinished_jobs`` at once; per job
    ``max_simulations_per_job`` runs kept, ``max_running_simulations`` at once; ``max_goal_checks``
    goal checks and as many plays at once; ``max_repairs`` searches of ``repair_time_budget`` s.
    """

    def __init__(self, run_goal: GoalRunner, config_dir: str | Path | None = None, systems=None,
                 max_jobs: int = 100, max_unfinished_jobs: int = 50, description: str = '',
                 max_running_simulations: int = 2, max_simulations_per_job: int = 5,
                 max_goal_checks: int = 2, max_repairs: int = 2, repair_time_budget: float = REPAIR_TIME_BUDGET):
        self.catalog = systems if systems is not None else SystemCatalog(config_dir or None)
        self.description = description
        self.stopping = threading.Event()
        self.jobs = JobQueue(run_goal, self.systems, self.stopping, max_jobs, max_unfinished_jobs)
        self.downloads = Downloads(self.jobs, self.catalog)
        self.simulations = SimulationRuns(self.jobs, self.catalog, self.stopping, max_running_simulations,
                                          max_simulations_per_job)
        self.repairs = RepairSearches(self.systems, self.robot_system, self.stopping, max_repairs,
                                      repair_time_budget)
        self.plays = Plays(self.robot_system, self.jobs, max_goal_checks)
        self.form = RequestForm(self.catalog, self.robot_system, self.simulations.available, max_goal_checks)

    def systems(self) -> list[str]:
        return self.catalog.names()

    def robot_system(self, system: str) -> RobotSystem:
        """The robot system of a request, as the suite synthesizes for it (NotFoundError if unknown)."""
        names = self.systems()
        if system not in names:
            raise NotFoundError(f'unknown system {quoted(system)} (known systems: {", ".join(names)})', str(system))
        return self.catalog.load(system)

    def stop(self):
        """The server is stopping: cancel every unfinished job (its goal too), end the running
        simulations, repair searches and the event streams."""
        self.stopping.set()
        self.jobs.cancel_unfinished()
        self.simulations.stop_all()
        self.repairs.stop_all()
