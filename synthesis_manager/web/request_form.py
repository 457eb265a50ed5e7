"""``RequestForm``: what the page's request form offers for a system, and its live goal check."""

from __future__ import annotations

import dataclasses
import threading

from ltl_specification.diagnosis import goal_findings
from respec.vocabulary.errors import CodedError, quoted
from synthesis_manager.limits import BusyError
from synthesis_manager.web.errors import NotAvailableError, NotFoundError
from synthesis_manager.web.jobs import checked_body, names_field
from synthesis_manager.web.robot_views import common_choices, robot_view

GOAL_CHECK_RETRY_AFTER = 1  # seconds: a goal check of a shipped system takes milliseconds


class RequestForm:
    """The form's answers on the robot systems of ``catalog`` (``robot_system(name)`` loads one,
    NotFoundError if unknown). ``can_simulate``: whether the GUI can run simulations.

    The live goal check runs in the request's thread and costs CPU and memory with the system's
    size: at most ``max_goal_checks`` at once (10 large ones once took 64 s of CPU, +636 MiB)."""

    def __init__(self, catalog, robot_system, can_simulate: bool, max_goal_checks: int = 2):
        self.catalog = catalog
        self.robot_system = robot_system
        self.can_simulate = can_simulate
        self.max_goal_checks = max_goal_checks
        self._slots = threading.BoundedSemaphore(max_goal_checks)

    def choices(self, system: str) -> dict:
        """What the form offers for ``system`` and what the abstraction panel draws, as its view
        (web/robot_views.py) answers, with whether the GUI can simulate it."""
        try:
            robot = self.robot_system(system)
            view = robot_view(robot)
            choices = common_choices(robot, view)
        except NotFoundError:
            raise
        except CodedError as error:
            raise NotAvailableError(str(error), error.item or system) from error
        return {**choices, 'simulation': view.simulation_support(self.can_simulate)}

    def goal_check(self, body) -> dict:
        """Chosen goals that can never be achieved, and why each other action or mode cannot be the
        next goal (ltl_specification.diagnosis).

        Beyond max_goal_checks at once: BusyError (429, Retry-After), nothing is checked."""
        body = checked_body(body)
        if not self._slots.acquire(blocking=False):
            raise BusyError(f'{self.max_goal_checks} goal checks are running (at most {self.max_goal_checks} at once); '
                            'try again in a moment', 'goal-check', retry_after=GOAL_CHECK_RETRY_AFTER)
        try:
            return self._check_goals(body)
        finally:
            self._slots.release()

    def _check_goals(self, body: dict) -> dict:
        system = body.get('system')
        if system not in self.catalog.names():
            raise NotFoundError(f'unknown system {quoted(system)}', str(system))
        initial_conditions = names_field(body, 'initial_conditions')
        goals = names_field(body, 'goals')
        strict_order = not body.get('unordered', False)
        try:
            robot = self.catalog.load(system)
            findings = goal_findings(robot, initial_conditions, goals, strict_order)
            impossible = robot_view(robot).impossible_next(initial_conditions, goals, strict_order)
        except CodedError as error:  # e.g. an invalid abstraction: the synthesis will say it
            raise NotAvailableError(str(error), error.item or system) from error
        return {'findings': [dataclasses.asdict(f) for f in findings], 'impossible_next': impossible}
