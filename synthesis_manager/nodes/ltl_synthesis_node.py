"""The ``ltl_synthesis`` service node (SynthesizeAutomaton): a thin adapter around the synthesizer.

Like the original it writes the byproducts ``<spec_name>.structuredslugs``, ``.slugsin`` and
``.json`` to a directory (see synthesis_manager.byproducts for names and retention). An
unrealizable specification that comes with its provenance is diagnosed here, with this node's
settings, and the diagnosis leads the answer's message (ltl_specification.diagnosis).
"""

from __future__ import annotations

import importlib.metadata
import json
import threading
import time
import uuid

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node
from rclpy.serialization import deserialize_message, serialize_message

from ltl_specification.diagnosis import CORE_NOT_COMPUTED, explain_unsynthesizable, explain_well_separation
from ltl_specification.provenance import provenance_from_json
from ltl_synthesizer import Limits, SynthesisCancelledError, SynthesisError
from ltl_synthesizer.cache import DEFAULT_MAX_BYTES, CacheDirectoryError, StrategyCache, cache_key, source_digest
from ltl_synthesizer.external import run_external_synthesizer
from ltl_synthesizer.isolated import (SERVER_CHILD_NICENESS, WORKING_CHILDREN_MEMORY, SpecificationText,
                                      SynthesisProcesses, byproduct_texts)
from ltl_synthesizer.strategy import strategy_to_json
from respec.automaton import automaton_from_strategy, strategy_move_problems
from respec.errors import CodedError, ErrorCode
from respec.nesting import run_with_deep_stack
from respec.parsing import ParseError, spec_from_text_sections
from respec.spec import GR1Specification
from synthesis_manager.byproducts import DEFAULT_KEEP_LAST, EXTENSIONS, ByproductStore, default_directory
from synthesis_manager.limits import (DEFAULT_MAX_GOAL_TIMEOUT, capped_timeout, check_message, check_timeout,
                                      utf8_length)
from synthesis_manager.ros.conversions import automaton_to_msg, error_code, msg_to_automaton, msg_to_sections
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.stage_calls import LookTimer
from synthesis_manager.ros.worker_pool import Abandoned, WorkerPool, executor_waker
from synthesis_msgs.msg import FSAutomaton
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
#: The default bound of all working children's memory together (MiB; memory_sum_limit_mb): two
#: syntheses at their own limit (memory_limit_mb 2048).
DEFAULT_MEMORY_SUM_LIMIT_MB = 4096
#: The strategy cache's default bound (MiB; strategy_cache_mb).
DEFAULT_STRATEGY_CACHE_MB = DEFAULT_MAX_BYTES / 2**20
#: The code an answer comes from: part of every cache key, so that entries kept on disk by
#: other code miss (ltl_synthesizer.cache.source_digest).
ANSWERING_PACKAGES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'synthesis_manager')


class LTLSynthesisNode(Node):
    """Synthesizes automata from GR(1) specifications.

    Parameters: ``byproducts_dir``; ``keep_byproducts`` (how many spec names' byproduct
    files to keep, newest first; 0 keeps none) and ``byproducts_max_age`` (seconds, 0: no
    limit); ``backend`` ('builtin' or 'slugs': an external slugs-compatible executable,
    ``slugs_executable``, called the original way); ``timeout`` (seconds, used when a
    request gives none; time spent waiting for a worker counts); ``robotics_semantics``;
    ``memory_limit_mb`` (per synthesis; beyond it the synthesis ends with SYNTHESIS_FAILED
    naming the limit, not an OOM kill); ``memory_sum_limit_mb`` (this process and all its children
    together; beyond it the working child holding the most ends, SYNTHESIS_FAILED naming the
    sum limit; 0: none); ``diagnosis_timeout`` (seconds to find why an
    unrealizable specification cannot be met, used when a request gives none; never past the
    request's time limit); ``check_well_separation`` (a realizable specification's answer
    carries, as its SUCCESS message, a warning when the controller can win by forcing the
    environment to break its assumptions: ltl_synthesizer.well_separation; checked within the
    diagnosis time); ``max_strategy_edges`` (largest builtin strategy sent back, in
    transitions; larger ones are SYNTHESIS_FAILED naming their size; 0: no limit); ``max_timeout`` (seconds: the longest time limit a request gets,
    600; 0: no cap); ``parallel_syntheses`` (run at once) and ``queued_syntheses`` (waiting beyond those;
    further requests are answered BUSY); ``strategy_cache_mb`` (MiB of answers kept for identical
    requests, least recently used dropped first; 0: no cache) and ``strategy_cache_dir`` (a
    private directory where they are kept too, so that a restarted node finds them; '': memory
    only): see :meth:`_cache_key` for what an identical request is and which answers are kept.

    Syntheses run in the node's own worker threads, awaited by an async service callback,
    so the executor stays free for cancel requests and the other nodes of the process. Each
    builtin synthesis runs in a child process (ltl_synthesizer.isolated), which a cancel, the
    time limit or shutdown kills at once, even in the middle of a long CUDD operation.
    """

    def __init__(self, **kwargs):
        super().__init__('ltl_synthesis', **kwargs)
        self.log = QuickLogger(self.get_logger())  # a line per failed request
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
        self.declare_parameter('memory_sum_limit_mb', DEFAULT_MEMORY_SUM_LIMIT_MB)
        self.declare_parameter('diagnosis_timeout', 20.0)
        self.declare_parameter('check_well_separation', True)
        self.declare_parameter('parallel_syntheses', 8)
        self.declare_parameter('queued_syntheses', 200)
        self.declare_parameter('strategy_cache_mb', DEFAULT_STRATEGY_CACHE_MB)
        self.declare_parameter('strategy_cache_dir', '')
        self.declare_parameter('strategy_cache_key_file', '')
        self._running: dict[str, threading.Event] = {}
        self._lock = threading.Lock()
        self.workers = WorkerPool(self.parameter('parallel_syntheses'), self.parameter('queued_syntheses'),
                                  name='synthesis')
        self.synthesis_processes = SynthesisProcesses(niceness=SERVER_CHILD_NICENESS)
        # The bound of this process's whole tree (compilations, repairs and a GUI's simulations
        # too, when they run in the same process).
        WORKING_CHILDREN_MEMORY.limit = self.parameter('memory_sum_limit_mb') * 2**20 or None
        self.strategy_cache = self._strategy_cache()
        self._prune_leftovers()
        if self.parameter('backend') == 'builtin':
            self.synthesis_processes.prepare()
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

    def _strategy_cache(self) -> StrategyCache:
        """The cache of answers (strategy_cache_mb, strategy_cache_dir, strategy_cache_key_file).
        An unsafe or unusable directory or key file is logged and the cache kept in memory only: answers stay right, only a
        restart loses them."""
        max_bytes = int(self.parameter('strategy_cache_mb') * 2**20)
        directory = self.parameter('strategy_cache_dir')
        self._answering_code = (f"{source_digest(ANSWERING_PACKAGES)} dd {importlib.metadata.version('dd')}"
                                if max_bytes > 0 else '')
        try:
            return StrategyCache(max_bytes, directory or None, self.parameter('strategy_cache_key_file') or None)
        except (CacheDirectoryError, OSError) as error:
            self.get_logger().warning(f'strategy cache kept in memory only: {error}'[:300])
            return StrategyCache(max_bytes)

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
            # A large specification's key is computed in the worker: hashing megabytes here would
            # hold the executor thread (3.9 MB: 26 ms).
            key = None if _is_large(msg_to_sections(request.ltl_specification)) else self._cache_key(request)
            cached = self.strategy_cache.get(key, lambda entry: self._loaded_entry_problem(entry, request)) \
                if key else None
            if cached is not None:  # answered here: no worker, no synthesis process
                self._answer_from_cache(cached, request, response)
            else:
                try:
                    # Formulas are parsed, printed and pickled to the synthesis process on a deep stack.
                    with self.looks.waiting():
                        await self.workers.run(run_with_deep_stack, self._synthesize, request, response, cancel,
                                               timeout, deadline, key,
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
            self.log.warning(response.error_code.message)
        return response

    def _cache_key(self, request) -> str | None:
        """The strategy cache's key of ``request`` (None: not cached, with the cache off or the
        slugs backend, an external program that may change unseen).

        It digests everything the answer (the response and the byproduct files) depends on:
        the specification's text as sent, the provenance (the diagnosis and the well-separation
        warning tell it), the options that change the answer (robotics_semantics,
        check_well_separation, max_strategy_edges), and the code that computes it (the sources
        of ANSWERING_PACKAGES, the dd version). Both the specification and its provenance are
        compiled from the robot system's files, so a changed file that changes the answer
        changes the key; the request names no system beyond them. spec_name only names the
        byproduct files and appears in an unrealizable answer's message, so it is left out
        (the message is kept without it). Time and memory limits decide whether an answer
        comes, not which: a hit is the answer of a synthesis that had enough of both."""
        if not self.strategy_cache.enabled or self.parameter('backend') != 'builtin':
            return None
        return cache_key({
            'code': self._answering_code,
            'specification': msg_to_sections(request.ltl_specification), 'provenance': request.provenance,
            'robotics_semantics': self.parameter('robotics_semantics'),
            'check_well_separation': self.parameter('check_well_separation'),
            'max_strategy_edges': self.parameter('max_strategy_edges')})

    def _loaded_entry_problem(self, entry, request) -> str | None:
        """What is wrong with a realizable answer read back from the cache directory (None:
        nothing found): its strategy's moves against the request's specification
        (``respec.automaton.strategy_move_problems``), and its automaton against its strategy.
        An unrealizable verdict is signed but not re-checked (that would be a synthesis); nor
        is a specification over 64 KB, which this thread does not parse."""
        sections = msg_to_sections(request.ltl_specification)
        if entry.get('synthesizable') != b'1' or _is_large(sections):
            return None
        try:
            spec = spec_from_text_sections(sections)
            strategy = json.loads(entry['json'])
            problems = strategy_move_problems(strategy, spec)
            # Compared as automata: equal messages' CDR bytes may differ in their padding.
            if not problems and msg_to_automaton(deserialize_message(entry['automaton'], FSAutomaton)) \
                    != automaton_from_strategy(strategy, spec):
                problems = ['its automaton is not the one of its strategy']
        except (KeyError, ValueError, CodedError) as error:
            problems = [f'it cannot be read back ({error!r:.100})']
        if problems:
            self.get_logger().warning(f'strategy cache: an entry read from the directory is not served: '
                                      f'{problems[0]}')
        return problems[0] if problems else None

    def _answer_from_cache(self, entry, request, response):
        """Answer ``request`` with a kept answer: its byproduct files written again under this
        request's spec_name, the response byte-identical to the synthesis it was kept from."""
        with self.byproduct_store().open_set(request.spec_name) as files:
            for extension in EXTENSIONS:
                if extension in entry:
                    files.write(extension, entry[extension].decode())
        response.synthesizable = entry['synthesizable'] == b'1'
        if response.synthesizable:
            response.automaton = deserialize_message(entry['automaton'], FSAutomaton)
            message = entry['message'].decode()
        else:
            message = (entry['message_before'] + _unrealizable_head(files.name).encode()
                       + entry['message_after']).decode()
        response.error_code = error_code(ErrorCode[entry['code'].decode()], message)

    def _synthesize(self, request, response, cancel, timeout, deadline, key: str | None):
        """Synthesize (in a worker thread), once for concurrent identical requests: with a
        cache key, a request identical to one being synthesized waits for its answer. ``key``:
        the one on_request computed (None: computed here, e.g. a large specification's)."""
        if cancel.is_set() or time.monotonic() > deadline:  # stopped while waiting for a worker
            return self._stopped(response, 'cancelled' if cancel.is_set() else 'timeout', timeout)
        key = key or self._cache_key(request)
        if key is None:
            self._synthesize_fresh(request, response, cancel, timeout, deadline)
            return
        entry, how = self.strategy_cache.answer(
            key, lambda: self._synthesize_fresh(request, response, cancel, timeout, deadline, keep=True),
            give_up=lambda: cancel.is_set() or time.monotonic() > deadline,
            check=lambda entry: self._loaded_entry_problem(entry, request))
        if how == 'gave up':
            self._stopped(response, 'cancelled' if cancel.is_set() else 'timeout', timeout)
        elif how != 'computed':
            self._answer_from_cache(entry, request, response)

    def _synthesize_fresh(self, request, response, cancel, timeout, deadline, keep: bool = False) -> dict | None:
        """Synthesize ``request`` into ``response``; with ``keep``, return what the strategy
        cache keeps of the answer, or None when the answer must not be kept: a stop (time
        limit, cancel), a failure (memory limit, a strategy too large, the process died), or a
        diagnosis or well-separation check cut short by its time (a fresh synthesis with more
        time would say more). Realizable and unrealizable verdicts are deterministic: kept."""
        if cancel.is_set() or time.monotonic() > deadline:  # e.g. after waiting for an identical request
            return self._stopped(response, 'cancelled' if cancel.is_set() else 'timeout', timeout)
        sections = msg_to_sections(request.ltl_specification)
        backend = self.parameter('backend')
        if backend == 'builtin' and _is_large(sections):
            spec = SpecificationText(sections)  # parsed in the synthesis children
            try:
                structuredslugs, slugsin, inputs, outputs = self.synthesis_processes.call(
                    byproduct_texts, (spec,), cancel=cancel, deadline=deadline)
            except SynthesisCancelledError as stopped:
                return self._stopped(response, stopped.reason, timeout, getattr(stopped, 'during', ''))
            variables = GR1Specification(env_props=inputs, sys_props=outputs)  # what the automaton names
        else:
            spec = variables = spec_from_text_sections(sections)
            structuredslugs, slugsin = spec.to_structuredslugs(), spec.to_slugsin()
        entry = {'structuredslugs': structuredslugs.encode(), 'slugsin': slugsin.encode()} if keep else {}
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
                    return self._stopped(response, stopped.reason, timeout, getattr(stopped, 'during', ''))
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
                head = _unrealizable_head(files.name)
                details = f'{head}: {explanation}'.rstrip(': ')
                try:
                    message, diagnosed = self._diagnosed(details, spec, request, robotics, cancel, deadline)
                except SynthesisCancelledError as stopped:
                    return self._stopped(response, stopped.reason, timeout, getattr(stopped, 'during', ''))
                response.error_code = error_code(ErrorCode.SPEC_UNSYNTHESIZABLE, message)
                if not (keep and diagnosed):
                    return None
                before, found, after = message.rpartition(head)  # kept without the spec name
                if not found:
                    return None
                return {**entry, 'synthesizable': b'0', 'code': b'SPEC_UNSYNTHESIZABLE',
                        'message_before': before.encode(), 'message_after': after.encode()}
            strategy_json = strategy_to_json(strategy)
            files.write('json', strategy_json)
        try:
            warning, checked = self._well_separation_warning(spec, request, cancel, deadline)
        except SynthesisCancelledError as stopped:
            return self._stopped(response, stopped.reason, timeout, getattr(stopped, 'during', ''))
        response.automaton = automaton_to_msg(automaton_from_strategy(strategy, variables))
        response.error_code = error_code(ErrorCode.SUCCESS, warning)
        if not (keep and checked):
            return None
        return {**entry, 'json': strategy_json.encode(), 'synthesizable': b'1', 'code': b'SUCCESS',
                'message': warning.encode(), 'automaton': serialize_message(response.automaton)}

    def _well_separation_warning(self, spec, request, cancel: threading.Event, deadline: float) -> tuple[str, bool]:
        """The warning that the controller can win by forcing the environment to break its
        assumptions ('' when it cannot, when check_well_separation is off, or when the check
        does not end within the diagnosis time and the request's time limit: the automaton
        stands without it), and whether the check ended (or was off). The check runs in a
        synthesis child process, with the memory limit; a cancel raises SynthesisCancelledError."""
        if not self.parameter('check_well_separation'):
            return '', True
        limit = request.diagnosis_timeout or self.parameter('diagnosis_timeout')
        check_deadline = min(time.monotonic() + limit, deadline)
        if check_deadline <= time.monotonic():
            return '', False
        limits = Limits(deadline=check_deadline, memory_limit=self.parameter('memory_limit_mb') * 2**20)
        try:
            return self.synthesis_processes.call(WELL_SEPARATION, (spec, self._provenance(request), limits),
                                                 cancel=cancel, deadline=check_deadline + DIAGNOSIS_GRACE), True
        except SynthesisError as error:
            if cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            self.get_logger().warning(f'well-separation not checked: {error}'[:300])
            return '', False

    def _diagnosed(self, details: str, spec, request, robotics_semantics: bool, cancel: threading.Event,
                   deadline: float) -> tuple[str, bool]:
        """``details`` (the synthesizer's explanation), led by why the task cannot be done: in
        the task's terms when the request carries the specification's provenance, else by its
        formulas; and whether the diagnosis was whole (its core computed). The diagnosis runs in
        a synthesis child process, with the memory limit, and ends by diagnosis_timeout and
        before the request's time limit; without an answer by then the verdict stands with
        ``details``. A cancel raises SynthesisCancelledError."""
        provenance = self._provenance(request)
        limit = request.diagnosis_timeout or self.parameter('diagnosis_timeout')
        diagnosis_deadline = min(time.monotonic() + limit, deadline - DIAGNOSIS_GRACE)
        if diagnosis_deadline <= time.monotonic():
            return details, False
        limits = Limits(deadline=diagnosis_deadline, memory_limit=self.parameter('memory_limit_mb') * 2**20)
        try:
            # The diagnosis keeps its own deadline; the child is killed only if it overruns.
            message = self.synthesis_processes.call(
                DIAGNOSIS, (details, spec, provenance, robotics_semantics, limits),
                cancel=cancel, deadline=diagnosis_deadline + DIAGNOSIS_GRACE)
        except SynthesisError:
            if cancel.is_set():
                raise SynthesisCancelledError('cancelled') from None
            return details, False  # out of time, or its process died: the verdict stands without it
        # A diagnosis that failed says only the details; one whose time ran out says so.
        return message, message != details and CORE_NOT_COMPUTED not in message

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
    def _stopped(response, reason: str, timeout: float, during: str = ''):
        """``during``: the stage the synthesis was in and its size measure, when it said."""
        code = ErrorCode.SYNTHESIS_TIMEOUT if reason == 'timeout' else ErrorCode.PREEMPTED
        where = f' while {during}' if during else ''
        response.error_code = error_code(code, f'synthesis stopped: {reason}{where} (time limit {timeout:g} s)')


def _is_large(sections: dict) -> bool:
    """Whether a specification's text is over LARGE_SPEC_BYTES."""
    return sum(utf8_length(line) for lines in sections.values() for line in lines) > LARGE_SPEC_BYTES


def _unrealizable_head(spec_name: str) -> str:
    """How an unrealizable answer's synthesizer details start (the only part naming the spec)."""
    return f'specification {spec_name!r} is unrealizable'


def main():
    node_main(LTLSynthesisNode, 'ltl_synthesis')
