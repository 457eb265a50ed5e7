"""The ``ltl_synthesis`` service node (SynthesizeAutomaton): a thin adapter around the
synthesis service (ltl_synthesizer.service).

Like the original it writes the byproducts ``<spec_name>.structuredslugs``, ``.slugsin`` and
``.json`` to a directory (see synthesis_manager.byproducts for names and retention). An
unrealizable specification that comes with its provenance is diagnosed, with this node's
settings, and the diagnosis leads the answer's message (ltl_specification.diagnosis).
"""

from __future__ import annotations

import threading
import time
import uuid

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ltl_specification.diagnosis import CORE_NOT_COMPUTED, explain_unsynthesizable, explain_well_separation
from ltl_specification.provenance import provenance_from_json
from ltl_synthesizer.isolated import SynthesisProcesses
from ltl_synthesizer.service import Explainers, SynthesisJob, SynthesisService, SynthesisSettings, answer_cache
from respec.child_processes.runner import SERVER_CHILD_NICENESS, WORKING_CHILDREN_MEMORY
from respec.vocabulary.errors import CodedError
from respec.nesting import run_with_deep_stack
from respec.parsing import ParseError
from synthesis_manager.byproducts import ByproductStore
from synthesis_manager.limits import capped_timeout, check_message, check_timeout
from synthesis_manager.ros.conversions import automaton_to_msg, error_code, msg_to_sections
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.ros.stage_calls import LookTimer
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker
from synthesis_manager.settings import LTL_SYNTHESIS
from synthesis_msgs.srv import CancelSynthesis, SynthesizeAutomaton

#: How the node's answers are explained (run in a synthesis child process).
EXPLAINERS = Explainers(diagnose=explain_unsynthesizable, check_well_separation=explain_well_separation,
                        read_provenance=provenance_from_json, incomplete_mark=CORE_NOT_COMPUTED)


class LTLSynthesisNode(Node):
    """Synthesizes automata from GR(1) specifications.

    Its settings (ROS parameters) are ``synthesis_manager.settings.LTL_SYNTHESIS``; what it
    answers is ``ltl_synthesizer.service``'s (see ``SynthesisService.cache_key`` for what an
    identical request is and which answers are kept); the node adapts messages to it.

    Syntheses run in the node's own worker threads, awaited by an async service callback,
    so the executor stays free for cancel requests and the other nodes of the process. Each
    builtin synthesis runs in a child process (ltl_synthesizer.isolated), which a cancel, the
    time limit or shutdown kills at once, even in the middle of a long CUDD operation.
    """

    def __init__(self, **kwargs):
        super().__init__('ltl_synthesis', **kwargs)
        self.log = QuickLogger(self.get_logger())  # a line per failed request
        self.settings = declare_settings(self, LTL_SYNTHESIS)
        self._running: dict[str, threading.Event] = {}
        self._lock = threading.Lock()
        self.workers = WorkerPool(self.settings.parallel_syntheses, self.settings.queued_syntheses,
                                  name='synthesis')
        # The bound of this process's whole tree (compilations, repairs and a GUI's simulations
        # too, when they run in the same process).
        WORKING_CHILDREN_MEMORY.limit = self.settings.memory_sum_limit_mb * 2**20 or None
        warn = lambda text: self.get_logger().warning(text)  # noqa: E731
        self.service = SynthesisService(
            self.synthesis_settings, self.byproduct_store, answer_cache(
                int(self.settings.strategy_cache_mb * 2**20), self.settings.strategy_cache_dir,
                self.settings.strategy_cache_key_file, warn),
            SynthesisProcesses(niceness=SERVER_CHILD_NICENESS), EXPLAINERS, warn)
        self._prune_leftovers()
        if self.settings.backend == 'builtin':
            self.service.processes.prepare()
        group = ReentrantCallbackGroup()
        # Wakes the executor while requests wait for a worker, so they see their deadline or cancel pass.
        self.looks = LookTimer(self)
        self.create_service(SynthesizeAutomaton, 'ltl_synthesis', self.on_request, callback_group=group,
                            qos_profile=service_qos())
        self.create_service(CancelSynthesis, 'ltl_synthesis/cancel', self.on_cancel_request,
                            callback_group=group, qos_profile=service_qos())

    def _prune_leftovers(self):
        """Delete what cut-short writes left in the byproducts directory (a full disk, a kill)."""
        try:
            deleted = self.byproduct_store().prune_leftovers()
        except (OSError, CodedError) as error:  # e.g. an unsafe directory: every synthesis will say so
            self.get_logger().warning(f'byproduct leftovers not pruned: {error}'[:300])
            return
        if deleted:
            self.get_logger().info(f'pruned {len(deleted)} byproduct leftovers (.part files, empty markers)')

    def stop_work(self):
        """Stop every running synthesis (at shutdown, so the process exits promptly)."""
        with self._lock:
            for event in self._running.values():
                event.set()
        self.service.processes.close()

    def destroy_node(self):
        self.service.processes.close()
        return super().destroy_node()

    def active_requests(self) -> list[str]:
        """Ids of the requests whose synthesis is running or waiting now."""
        with self._lock:
            return sorted(self._running)

    def byproduct_store(self) -> ByproductStore:
        return ByproductStore(self.settings.byproducts_dir, keep_last=self.settings.keep_byproducts,
                              max_age=self.settings.byproducts_max_age)

    def on_cancel_request(self, request, response):
        with self._lock:
            event = self._running.get(request.request_id)
        response.cancelled = event is not None
        if event is not None:
            event.set()
        return response

    @property
    def strategy_cache(self):
        return self.service.cache

    def synthesis_settings(self) -> SynthesisSettings:
        return SynthesisSettings(**{name: getattr(self.settings, name) for name in SynthesisSettings.__dataclass_fields__})

    async def on_request(self, request, response):
        cancel = threading.Event()
        # Anonymous requests are tracked too, so that stop_work() reaches them.
        request_id = request.request_id or f'anonymous-{uuid.uuid4().hex}'
        with self._lock:
            self._running[request_id] = cancel
        try:
            check_message(request)
            # A request asking more than max_timeout gets the cap (as a goal gets max_goal_timeout).
            timeout = capped_timeout(check_timeout(request.timeout, 'request.timeout') or self.settings.timeout,
                                     self.settings.max_timeout)
            check_timeout(request.diagnosis_timeout, 'request.diagnosis_timeout')
            # The time limit starts now: waiting for a worker counts.
            job = SynthesisJob(msg_to_sections(request.ltl_specification), request.spec_name, timeout,
                               time.monotonic() + timeout, request.provenance, request.diagnosis_timeout, cancel)
            answer, key = self.service.cached_answer(job)  # a hit: no worker, no synthesis process
            if answer is None:
                try:
                    # Formulas are parsed, printed and pickled to the synthesis process on a deep stack.
                    with self.looks.waiting():
                        answer = await self.workers.run(run_with_deep_stack, self.service.answer, job, key,
                                                        wake=executor_waker(self), give_up=job.stopped)
                except Abandoned:  # stopped while waiting for a worker
                    answer = job.stopped_answer()
            response.synthesizable = answer.synthesizable
            if answer.automaton is not None:
                response.automaton = automaton_to_msg(answer.automaton)
            response.error_code = error_code(answer.code, answer.message)
        except ParseError as error:  # the parsers' own code, as in every other stage
            response.synthesizable = False
            response.error_code = error_code(error.code, f'malformed specification: {error}')
        except Exception as error:  # noqa: BLE001 - every failure becomes an error code; the node keeps serving
            response.synthesizable = False
            response.error_code = reported_error(error, self.get_logger(), 'synthesis failed')
        finally:
            with self._lock:
                self._running.pop(request_id, None)
        if response.error_code.message:
            self.log.warning(response.error_code.message)
        return response


def main():
    node_main(LTLSynthesisNode, 'ltl_synthesis')
