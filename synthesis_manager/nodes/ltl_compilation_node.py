"""The ``ltl_compilation`` service node (GenerateLTLSpecification): a thin adapter around compile_task.

Compiling custom formulas is pure Python and takes about 2 s per MB: in the node's process it
would hold the GIL of a whole suite (20 goals of 4 MB froze ``serve`` for minutes, issue 34
item 2). A request whose custom formulas add up to over ``SMALL_CUSTOM_BYTES`` is compiled in
a child process (``synthesis_manager.ros.child_stage``), killed at the node's time or memory
limit or at shutdown; the others (every request without custom formulas) are compiled here at once, so a
normal goal never waits behind large ones.

It also serves ``propose_repairs`` (ProposeRepairs): verified changes that make a refused task
possible (``ltl_specification.repair``), searched in a child process on the robot system this
node compiles for, within the request's time budget.
"""

from __future__ import annotations

import json
import threading
import time

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from std_msgs.msg import String

from ltl_specification import compile_task
from ltl_specification.provenance import provenance_to_json
from ltl_specification.repair import TaskRequest
from ltl_specification.repair_process import RepairSearch, RepairSearchError, repair_settings
from ltl_specification.systems import task_system_errors
from respec.vocabulary.errors import ErrorCode
from respec.robot import SystemCatalog, catalog_to_json
from respec.robot.files import SystemConfigError
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES
from respec.nesting import run_with_deep_stack
from synthesis_manager.ros.child_stage import ChildStage, StageStopped
from synthesis_manager.ros.conversions import error_code, msg_to_sections, sections_to_msg
from synthesis_manager.limits import check_message, check_timeout, utf8_length
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.robot_systems import create_systems_publisher
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker
from synthesis_manager.settings import LTL_COMPILATION
from synthesis_msgs.srv import CancelSynthesis, GenerateLTLSpecification, ProposeRepairs

#: Custom formulas (bytes, all sections) up to which a request is compiled in the node's process.
SMALL_CUSTOM_BYTES = 64 * 1024
#: Robot files (bytes) up to which a request is compiled in the node's process: a 4 MiB system
#: file (the most accepted) takes about 4 s and 250 MiB to read and check.
SMALL_ROBOT_BYTES = 256 * 1024
#: Proposals a ProposeRepairs request gets when it names no number.
DEFAULT_REPAIR_PROPOSALS = 3
#: The longest search a request may ask for (seconds).
MAX_REPAIR_TIME_BUDGET = 60.0


def compiled_sections(system: str, initial_conditions: list, goals: list, sm_outcomes: tuple, strict_order: bool,
                      custom_ltl: dict | None, catalog: SystemCatalog) -> tuple[dict, str]:
    """The compiled specification's text sections and its provenance (JSON): plain data, so
    that a child process can send them back. The node's edge: ``system`` is a name of ``catalog``."""
    with task_system_errors():
        robot = catalog.load(system)
    spec = compile_task(robot, initial_conditions, goals, sm_outcomes=sm_outcomes, strict_order=strict_order,
                        custom_ltl=custom_ltl)
    # CNU capability systems record none: their unrealizable specifications are diagnosed by formula.
    provenance = provenance_to_json(spec.provenance) if spec.provenance is not None else ''
    return spec.to_text_sections(), provenance


def _compiled_in_child(*args) -> tuple[dict, str]:
    """compiled_sections in a child process's thread with room for deep formulas."""
    return run_with_deep_stack(compiled_sections, *args)


class LTLCompilationNode(Node):
    """Compiles partial tasks into complete GR(1) specifications.

    Settings (ROS parameters): ``synthesis_manager.settings.LTL_COMPILATION``. Publishes the
    systems of ``config_dir`` on ``robot_systems`` (latched; checked for edits every
    ``SYSTEMS_PERIOD`` seconds), so clients elsewhere see the systems it compiles for.
    """

    SYSTEMS_PERIOD = 2.0

    def __init__(self, **kwargs):
        super().__init__('ltl_compilation', **kwargs)
        self.log = QuickLogger(self.get_logger())  # a line per failed request
        self.settings = declare_settings(self, LTL_COMPILATION)
        self._stopping = threading.Event()
        self.repairs = WorkerPool(self.settings.parallel_repairs, 8, name='repair')
        self._repair_searches: set[RepairSearch] = set()
        self.children = ChildStage(self, 'ltl_specification', self.settings.parallel_compilations,
                                   self.settings.queued_compilations, name='compilation',
                                   what='LTL compilation', failed=ErrorCode.LTL_SPEC_COMPILATION_FAILED)
        group = ReentrantCallbackGroup()
        self.create_service(GenerateLTLSpecification, 'ltl_compilation', self.on_request,
                            callback_group=group, qos_profile=service_qos())
        self.create_service(CancelSynthesis, 'ltl_compilation/cancel', self.on_cancel_request,
                            callback_group=group, qos_profile=service_qos())
        self.create_service(ProposeRepairs, 'propose_repairs', self.on_repair_request,
                            callback_group=group, qos_profile=service_qos())
        self._systems_publisher = create_systems_publisher(self)
        self._published_systems = None
        self._systems_fingerprint: tuple | None = None  # of the files the last list was read from
        self.publish_systems()
        self.create_timer(self.SYSTEMS_PERIOD, self.publish_systems)

    def stop_work(self):
        """Stop every compilation in a child process (at shutdown, so the process exits promptly)."""
        self._stopping.set()
        self.children.stop()
        for search in list(self._repair_searches):
            search.stop()

    def destroy_node(self):
        self.children.stop()
        return super().destroy_node()

    def catalog(self) -> SystemCatalog:
        return SystemCatalog(self.settings.config_dir or None)

    def publish_systems(self) -> None:
        """Publish the systems when they changed (a system file edited, added or removed); while
        no file under the config folders changed, nothing is read again."""
        try:
            catalog = self.catalog()
            fingerprint = catalog.fingerprint()
            if fingerprint == self._systems_fingerprint:
                return
            text = catalog_to_json(catalog)
        except (OSError, SystemConfigError) as error:  # e.g. a config directory vanished: keep the last list
            self.get_logger().warning(f'cannot read the robot systems: {error}')
            return
        self._systems_fingerprint = fingerprint
        if text != self._published_systems:
            self._systems_publisher.publish(String(data=text))
            self._published_systems = text

    def on_cancel_request(self, request, response):
        """``ltl_compilation/cancel``: stop a large compilation by its request id (PREEMPTED)."""
        response.cancelled = self.children.cancel(request.request_id)
        return response

    async def on_request(self, request, response):
        try:
            arrival = time.monotonic()
            check_message(request)
            requested = check_timeout(request.timeout, 'request.timeout')  # 0: the node's own limit
            arguments = (request.system, list(request.initial_conditions), list(request.goals),
                         tuple(request.sm_outcomes) or DEFAULT_SM_OUTCOMES, not request.unordered_goals,
                         msg_to_sections(request.custom_ltl) or None, self.catalog())
            custom_bytes = sum(utf8_length(formula) for section in (arguments[5] or {}).values()
                               for formula in section)
            robot_bytes = self.catalog().files_bytes(request.system) if isinstance(request.system, str) else 0
            if custom_bytes <= SMALL_CUSTOM_BYTES and robot_bytes <= SMALL_ROBOT_BYTES:
                # Formulas may nest MAX_FORMULA_NESTING deep: compiled on a deep stack.
                sections, provenance = run_with_deep_stack(compiled_sections, *arguments)
            else:
                size = (f'{custom_bytes:,} bytes of custom formulas' if custom_bytes > SMALL_CUSTOM_BYTES else
                        f'{robot_bytes:,} bytes of robot files')
                try:
                    sections, provenance = await self.children.run(
                        _compiled_in_child, arguments, size=size, arrival=arrival,
                        requested=requested, request_id=request.request_id)
                except StageStopped as stopped:
                    response.error_code = stopped.error_code
                    self.log.warning(response.error_code.message)
                    return response
        except Exception as error:  # noqa: BLE001 - every failure becomes an error code; the node keeps serving
            response.error_code = reported_error(error, self.get_logger(), 'LTL compilation failed')
            self.log.warning(response.error_code.message)
            return response
        response.ltl_specification = sections_to_msg(sections)
        response.provenance = provenance
        response.error_code = error_code()
        return response

    async def on_repair_request(self, request, response):
        """Verified proposals for the request's task (at most ``max_proposals``) as sentences and
        as the whole ``Repairs.to_dict()`` in JSON; every failure is an error code."""
        try:
            check_message(request)
            system = self.catalog().load(request.system)
            budget = min(request.time_budget or self.settings.repair_time_budget,
                         MAX_REPAIR_TIME_BUDGET)
            task = TaskRequest(system.name, tuple(request.initial_conditions), tuple(request.goals),
                               tuple(request.sm_outcomes) or DEFAULT_SM_OUTCOMES, request.unordered_goals)
            settings = repair_settings(system, task.to_dict(), msg_to_sections(request.custom_ltl) or None, budget,
                                       request.max_proposals or DEFAULT_REPAIR_PROPOSALS)
            with self.children.looks.waiting():  # the search sees a shutdown
                repairs = await self.repairs.run(self._search_repairs, settings, wake=executor_waker(self),
                                                 give_up=self._stopping.is_set)
        except (RepairSearchError, Abandoned) as error:
            response.error_code = error_code(ErrorCode.TIMEOUT, f'repair search stopped: {error or "shutdown"}')
            return response
        except Exception as error:  # noqa: BLE001 - every failure becomes an error code; the node keeps serving
            response.error_code = reported_error(error, self.get_logger(), 'repair search failed')
            self.log.warning(response.error_code.message)
            return response
        response.summaries = [proposal['summary'] for proposal in repairs['proposals']]
        response.repairs = json.dumps(repairs, sort_keys=True)
        response.error_code = error_code()
        return response

    def _search_repairs(self, settings: dict) -> dict:
        """One repair search in its child process (RepairSearch), stopped at shutdown."""
        search = RepairSearch(settings)
        self._repair_searches.add(search)
        try:
            if self._stopping.is_set():
                raise RepairSearchError('shutdown before it started')
            return search.run()
        finally:
            self._repair_searches.discard(search)



def main():
    node_main(LTLCompilationNode, 'ltl_compilation')
