"""The ``ltl_synthesis`` service node (SynthesizeAutomaton): a thin adapter around the synthesizer.

Like the original it writes the byproducts ``<spec_name>.structuredslugs``, ``.slugsin`` and
``.json`` to a directory (see synthesis_manager.byproducts for names and retention). An
unrealizable specification that comes with its provenance is diagnosed here, with this node's
settings, and the diagnosis leads the answer's message (ltl_specification.diagnosis).
"""

from __future__ import annotations

import threading
import time
import uuid

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ltl_specification.diagnosis import explain_unsynthesizable, explain_well_separation
from ltl_specification.provenance import provenance_from_json
from ltl_synthesizer import Limits, SynthesisCancelledError, SynthesisError
from ltl_synthesizer.external import run_external_synthesizer
from ltl_synthesizer.isolated import SERVER_CHILD_NICENESS, SpecificationText, SynthesisProcesses, byproduct_texts
from ltl_synthesizer.strategy import strategy_to_json
from respec.automaton import automaton_from_strategy
from respec.errors import CodedError, ErrorCode
from respec.nesting import run_with_deep_stack
from respec.parsing import ParseError, spec_from_text_sections
from respec.spec import GR1Specification
from synthesis_manager.byproducts import DEFAULT_KEEP_LAST, ByproductStore, default_directory
from synthesis_manager.limits import (DEFAULT_MAX_GOAL_TIMEOUT, capped_timeout, check_message, check_timeout,
                                      utf8_length)
from synthesis_manager.ros.conversions import automaton_to_msg, error_code, msg_to_sections
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker
from synthesis_msgs.srv import CancelSynthesis, SynthesizeAutomaton

BACKENDS = ('builtin', 'slugs')

# What explains an unrealizable specification (run in a synthesis child process; a module-level
# name so that tests can put a stand-in there).
DIAGNOSIS = explain_unsynthesizable
WELL_SEPARATION = explain_well_separation
DIAGNOSIS_GRACE = 1.0  # seconds past its own time limit before the diagnosis process is killed
#: Specifications (bytes of text) over this are parsed and printed in a synthesis child process,
#: where a deadline or a cancel stops them, not in the node's (builtin backend).
LARGE_SPEC_BYTES = 64 * 1024
#: Largest strategy (transitions) a builtin synthesis sends back: about 900 B each in the
#: server (automaton, JSON byproduct, messages), so about 90 MB per goal at most.
DEFAULT_MAX_STRATEGY_EDGES = 100_000


WAKE_PERIOD = 0.1  # seconds


class LTLSynthesisNode(Node):
    """Synthesizes automata from GR(1) specifications.

    Parameters: ``byproducts_dir``; ``keep_byproducts`` (how many spec names' byproduct
    files to keep, newest first; 0 keeps none) and ``byproducts_max_age`` (seconds, 0: no
    limit); ``backend`` ('builtin' or 'slugs': an external slugs-compatible executable,
    ``slugs_executable``, called the original way); ``timeout`` (seconds, used when a
    request gives none; time spent waiting for a worker counts); ``robotics_semantics``;
    ``memory_limit_mb`` (per synthesis; beyond it the synthesis ends with SYNTHESIS_FAILED
    naming the limit, not an OOM kill); ``diagnosis_timeout`` (seconds to find why an
    unrealizable specification cannot be met, used when a request gives none; never past the
    request's time limit); ``check_well_separation`` (a realizable specification's answer
    carries, as its SUCCESS message, a warning when the controller can win by forcing the
    environment to break its assumptions: ltl_synthesizer.well_separation; checked within the
    diagnosis time); ``max_strategy_edges`` (largest builtin strategy sent back, in
    transitions; larger ones are SYNTHESIS_FAILED naming their size; 0: no limit); ``max_timeout`` (seconds: the longest time limit a request gets,
    600; 0: no cap); ``parallel_syntheses`` (run at once) and ``queued_syntheses`` (waiting beyond those;
    further requests are answered BUSY).

    Syntheses run in the node's own worker threads, awaited by an async service callback,
    so the executor stays free for cancel requests and the other nodes of the process. Each
    builtin synthesis runs in a child process (ltl_synthesizer.isolated), which a cancel, the
    time limit or shutdown kills at once, even in the middle of a long CUDD operation.
    """

    def __init__(self, **kwargs):
        super().__init__('ltl_synthesis', **kwargs)
        self.declare_parameter('byproducts_dir', str(default_directory()))
        self.declare_parameter('keep_byproducts', DEFAULT_KEEP_LAST)
        self.declare_parameter('byproducts_max_age', 0.0)
        self.declare_parameter('backend', 'builtin')
        self.declare_parameter('slugs_executable', 'slugs')
        self.declare_parameter('timeout', 60.0)
        self.declare_parameter('max_timeout', DEFAULT_MAX_GOAL_TIMEOUT)
        self.declare_parameter('max_strategy_edges', DEFAULT_MAX_STRATEGY_EDGES)
        self.declare_parameter('robotics_semantics', True)
        self.declare_parameter('memory_limit_mb', 2048)
        self.declare_parameter('diagnosis_timeout', 20.0)
        self.declare_parameter('check_well_separation', True)
        self.declare_parameter('parallel_syntheses', 8)
        self.declare_parameter('queued_syntheses', 200)
        self._running: dict[str, threading.Event] = {}
        self._lock = threading.Lock()
        self.workers = WorkerPool(self.parameter('parallel_syntheses'), self.parameter('queued_syntheses'),
                                  name='synthesis')
        self.synthesis_processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS)
        self._prune_leftovers()
        if self.parameter('backend') == 'builtin':
            self.synthesis_processes.prepare()
        group = ReentrantCallbackGroup()
        # Wakes the executor, so that requests waiting for a worker see their deadline or cancel pass.
        self.create_timer(WAKE_PERIOD, lambda: None, callback_group=group)
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
        self.synthesis_processes.close()

    def destroy_node(self):
        self.synthesis_processes.close()
        return super().destroy_node()

    def active_requests(self) -> list[str]:
        """Ids of the requests whose synthesis is running or waiting now."""
        with self._lock:
            return sorted(self._running)

    def parameter(self, name):
        return self.get_parameter(name).value

    def byproduct_store(self) -> ByproductStore:
        return ByproductStore(self.parameter('byproducts_dir'), keep_last=self.parameter('keep_byproducts'),
                              max_age=self.parameter('byproducts_max_age'))

    def on_cancel_request(self, request, response):
        with self._lock:
            event = self._running.get(request.request_id)
        response.cancelled = event is not None
        if event is not None:
            event.set()
        return response

    async def on_request(self, request, response):
        cancel = threading.Event()
        # Anonymous requests are tracked too, so that stop_work() reaches them.
        request_id = request.request_id or f'anonymous-{uuid.uuid4().hex}'
        with self._lock:
            self._running[request_id] = cancel
        try:
            check_message(request)
            # A request asking more than max_timeout gets the cap (as a goal gets max_goal_timeout).
            timeout = capped_timeout(check_timeout(request.timeout, 'request.timeout') or self.parameter('timeout'),
                                     self.parameter('max_timeout'))
            check_timeout(request.diagnosis_timeout, 'request.diagnosis_timeout')
            # The time limit starts now: waiting for a worker counts.
            deadline = time.monotonic() + timeout
            try:
                # Formulas are parsed, printed and pickled to the synthesis process on a deep stack.
                await self.workers.run(run_with_deep_stack, self._synthesize, request, response, cancel,
                                       timeout, deadline,
                                       wake=executor_waker(self),
                                       give_up=lambda: cancel.is_set() or time.monotonic() > deadline)
            except Abandoned:  # stopped while waiting for a worker
                self._stopped(response, 'cancelled' if cancel.is_set() else 'timeout', timeout)
        except ParseError as error:  # the parsers' own code, as in every other stage
            response.synthesizable = False
            response.error_code = error_code(error.code, f'malformed specification: {error}')
        except Exception as error:  # every failure becomes an error code; the node keeps serving
            response.synthesizable = False
            response.error_code = reported_error(error, self.get_logger(), 'synthesis failed')
        finally:
            with self._lock:
                self._running.pop(request_id, None)
        if response.error_code.message:
            self.get_logger().warning(response.error_code.message)
        return response


    def _synthesize(self, request, response, cancel, timeout, deadline):
        if cancel.is_set() or time.monotonic() > deadline:  # stopped while waiting for a worker
            return self._stopped(response, 'cancelled' if cancel.is_set() else 'timeout', timeout)
        sections = msg_to_sections(request.ltl_specification)
        backend = self.parameter('backend')
        if backend == 'builtin' and sum(utf8_length(line) for lines in sections.values() for line in lines) > \
                LARGE_SPEC_BYTES:
            spec = SpecificationText(sections)  # parsed in the synthesis children
            try:
                structuredslugs, slugsin, inputs, outputs = self.synthesis_processes.call(
                    byproduct_texts, (spec,), cancel=cancel, deadline=deadline)
            except SynthesisCancelledError as stopped:
                return self._stopped(response, stopped.reason, timeout)
            variables = GR1Specification(env_props=inputs, sys_props=outputs)  # what the automaton names
        else:
            spec = variables = spec_from_text_sections(sections)
            structuredslugs, slugsin = spec.to_structuredslugs(), spec.to_slugsin()
        with self.byproduct_store().open_set(request.spec_name) as files:
            files.write('structuredslugs', structuredslugs)
            slugsin_path = files.write('slugsin', slugsin)
            del structuredslugs, slugsin
            robotics = self.parameter('robotics_semantics')
            if backend == 'builtin':
                try:
                    result = self.synthesis_processes.synthesize(spec, robotics, Limits(
                        cancel, deadline, self.parameter('memory_limit_mb') * 2**20),
                        max_strategy_edges=self.parameter('max_strategy_edges'))
                except SynthesisCancelledError as stopped:
                    return self._stopped(response, stopped.reason, timeout)
                realizable, strategy, explanation = result.realizable, result.strategy, result.explanation
            elif backend == 'slugs':
                realizable, strategy, stderr = run_external_synthesizer(
                    self.parameter('slugs_executable'), slugsin_path, files.paths['json'],
                    robotics_semantics=robotics, timeout=max(0.0, deadline - time.monotonic()),
                    cancel=cancel)
                explanation = stderr.strip()
            else:
                response.error_code = error_code(
                    ErrorCode.SYNTHESIS_FAILED, f'unknown backend {backend!r} (use one of {", ".join(BACKENDS)})')
                return
            response.synthesizable = realizable
            if not realizable:
                details = f'specification {files.name!r} is unrealizable: {explanation}'.rstrip(': ')
                try:
                    message = self._diagnosed(details, spec, request, robotics, cancel, deadline)
                except SynthesisCancelledError as stopped:
                    return self._stopped(response, stopped.reason, timeout)
                response.error_code = error_code(ErrorCode.SPEC_UNSYNTHESIZABLE, message)
                return
            files.write('json', strategy_to_json(strategy))
        try:
            warning = self._well_separation_warning(spec, request, cancel, deadline)
        except SynthesisCancelledError as stopped:
            return self._stopped(response, stopped.reason, timeout)
        response.automaton = automaton_to_msg(automaton_from_strategy(strategy, variables))
        response.error_code = error_code(ErrorCode.SUCCESS, warning)

    def _well_separation_warning(self, spec, request, cancel: threading.Event, deadline: float) -> str:
        """The warning that the controller can win by forcing the environment to break its
        assumptions ('' when it cannot, when check_well_separation is off, or when the check
        does not end within the diagnosis time and the request's time limit: the automaton
        stands without it). The check runs in a synthesis child process, with the memory
        limit; a cancel raises SynthesisCancelledError."""
        if not self.parameter('check_well_separation'):
            return ''
        limit = request.diagnosis_timeout or self.parameter('diagnosis_timeout')
        check_deadline = min(time.monotonic() + limit, deadline)
        if check_deadline <= time.monotonic():
            return ''
        limits = Limits(deadline=check_deadline, memory_limit=self.parameter('memory_limit_mb') * 2**20)
        try:
            return self.synthesis_processes.call(WELL_SEPARATION, (spec, self._provenance(request), limits),
                                                 cancel=cancel, deadline=check_deadline + DIAGNOSIS_GRACE)
        except SynthesisError as error:
            if cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            self.get_logger().warning(f'well-separation not checked: {error}'[:300])
            return ''

    def _diagnosed(self, details: str, spec, request, robotics_semantics: bool, cancel: threading.Event,
                   deadline: float) -> str:
        """``details`` (the synthesizer's explanation), led by why the task cannot be done: in
        the task's terms when the request carries the specification's provenance, else by its
        formulas. The diagnosis runs in a synthesis child process, with the memory limit, and
        ends by diagnosis_timeout and before the request's time limit; without an answer by then
        the verdict stands with ``details``. A cancel raises SynthesisCancelledError."""
        provenance = self._provenance(request)
        limit = request.diagnosis_timeout or self.parameter('diagnosis_timeout')
        diagnosis_deadline = min(time.monotonic() + limit, deadline - DIAGNOSIS_GRACE)
        if diagnosis_deadline <= time.monotonic():
            return details
        limits = Limits(deadline=diagnosis_deadline, memory_limit=self.parameter('memory_limit_mb') * 2**20)
        try:
            # The diagnosis keeps its own deadline; the child is killed only if it overruns.
            return self.synthesis_processes.call(
                DIAGNOSIS, (details, spec, provenance, robotics_semantics, limits),
                cancel=cancel, deadline=diagnosis_deadline + DIAGNOSIS_GRACE)
        except SynthesisError:
            if cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            return details  # out of time, or its process died: the verdict stands without it

    def _provenance(self, request):
        """The request's provenance (None without one, or when it cannot be read: logged)."""
        if not request.provenance:
            return None
        try:
            return provenance_from_json(request.provenance)
        except ValueError as error:
            self.get_logger().warning(f'request.provenance ignored (no diagnosis): {error!r}'[:300])
            return None

    @staticmethod
    def _stopped(response, reason: str, timeout: float):
        code = ErrorCode.SYNTHESIS_TIMEOUT if reason == 'timeout' else ErrorCode.PREEMPTED
        response.error_code = error_code(code, f'synthesis stopped: {reason} (time limit {timeout:g} s)')


def main():
    node_main(LTLSynthesisNode, 'ltl_synthesis')
