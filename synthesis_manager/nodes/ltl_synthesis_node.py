"""The ``ltl_synthesis`` service node (SynthesizeAutomaton): a thin adapter around the synthesizer.

Like the original it writes the byproducts ``<spec_name>.structuredslugs``, ``.slugsin`` and
``.json`` to a directory; the spec name comes from users, so it must stay inside it.
"""

from __future__ import annotations

import re
import tempfile
import threading
import time
import uuid
from pathlib import Path

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from ltl_synthesizer import SynthesisCancelled, synthesize
from ltl_synthesizer.external import run_external_synthesizer
from ltl_synthesizer.strategy import strategy_to_json
from respec.automaton import automaton_from_strategy
from respec.errors import CodedError
from respec.parsing import ParseError, spec_from_text_sections
from synthesis_manager.ros.conversions import automaton_to_msg, error_code, msg_to_sections
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.node_main import node_main
from synthesis_msgs.srv import CancelSynthesis, SynthesizeAutomaton

SPEC_NAME = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]{0,99}$')
DEFAULT_SPEC_NAME = 'synthesized_spec'
BACKENDS = ('builtin', 'slugs')


class InvalidSpecName(CodedError):
    """A spec_name that would leave the byproducts directory."""

    code = 'INVALID_SPEC_NAME'


def byproduct_stem(directory: Path, spec_name: str) -> Path:
    """``directory/spec_name``, refusing names that could leave the directory."""
    name = spec_name or DEFAULT_SPEC_NAME
    if not SPEC_NAME.match(name) or '..' in name:
        raise InvalidSpecName(
            f'invalid spec_name {spec_name!r}: use letters, digits, "_", "-" and "." '
            '(no path separators or "..")')
    return directory / name


class LTLSynthesisNode(Node):
    """Synthesizes automata from GR(1) specifications.

    Parameters: ``byproducts_dir``; ``backend`` ('builtin' or 'slugs': an external
    slugs-compatible executable, ``slugs_executable``, called the original way);
    ``timeout`` (seconds, used when a request gives none); ``robotics_semantics``.
    """

    def __init__(self, **kwargs):
        super().__init__('ltl_synthesis', **kwargs)
        default_dir = str(Path(tempfile.gettempdir()) / 'behavior_synthesis_byproducts')
        self.declare_parameter('byproducts_dir', default_dir)
        self.declare_parameter('backend', 'builtin')
        self.declare_parameter('slugs_executable', 'slugs')
        self.declare_parameter('timeout', 60.0)
        self.declare_parameter('robotics_semantics', True)
        self._running: dict[str, threading.Event] = {}
        self._lock = threading.Lock()
        group = ReentrantCallbackGroup()
        self.create_service(SynthesizeAutomaton, 'ltl_synthesis', self.on_request, callback_group=group)
        self.create_service(CancelSynthesis, 'ltl_synthesis/cancel', self.on_cancel_request,
                            callback_group=group)

    def stop_work(self):
        """Stop every running synthesis (at shutdown, so the process exits promptly)."""
        with self._lock:
            for event in self._running.values():
                event.set()

    def active_requests(self) -> list[str]:
        """Ids of the requests whose synthesis is running now."""
        with self._lock:
            return sorted(self._running)

    def parameter(self, name):
        return self.get_parameter(name).value

    def on_cancel_request(self, request, response):
        with self._lock:
            event = self._running.get(request.request_id)
        response.cancelled = event is not None
        if event is not None:
            event.set()
        return response

    def on_request(self, request, response):
        cancel = threading.Event()
        # Anonymous requests are tracked too, so that stop_work() reaches them.
        request_id = request.request_id or f'anonymous-{uuid.uuid4().hex}'
        with self._lock:
            self._running[request_id] = cancel
        try:
            self._synthesize(request, response, cancel)
        except ParseError as error:  # the original's code for a malformed specification
            response.synthesizable = False
            response.error_code = error_code('SYNTHESIS_FAILED', f'malformed specification: {error}')
        except Exception as error:  # every failure becomes an error code; the node keeps serving
            response.synthesizable = False
            response.error_code = reported_error(error, self.get_logger(), 'synthesis failed')
        finally:
            with self._lock:
                self._running.pop(request_id, None)
        if response.error_code.message:
            self.get_logger().warning(response.error_code.message)
        return response

    def _synthesize(self, request, response, cancel):
        directory = Path(self.parameter('byproducts_dir'))
        stem = byproduct_stem(directory, request.spec_name)
        # Appended, not with_suffix: a dot inside the name ("a.b", "a.c") must not be replaced.
        byproduct = lambda suffix: stem.with_name(stem.name + suffix)  # noqa: E731
        spec = spec_from_text_sections(msg_to_sections(request.ltl_specification))
        directory.mkdir(parents=True, exist_ok=True)
        byproduct('.structuredslugs').write_text(spec.to_structuredslugs())
        slugsin_path = byproduct('.slugsin')
        slugsin_path.write_text(spec.to_slugsin())
        timeout = request.timeout or self.parameter('timeout')
        robotics = self.parameter('robotics_semantics')
        backend = self.parameter('backend')
        if backend == 'builtin':
            try:
                result = synthesize(spec, robotics_semantics=robotics, cancel=cancel,
                                    deadline=time.monotonic() + timeout)
            except SynthesisCancelled as stopped:
                reason = 'SYNTHESIS_TIMEOUT' if stopped.reason == 'timeout' else 'PREEMPTED'
                response.error_code = error_code(reason, f'synthesis stopped: {stopped.reason} '
                                                 f'(time limit {timeout:g} s)')
                return
            realizable, strategy, explanation = result.realizable, result.strategy, result.explanation
        elif backend == 'slugs':
            realizable, strategy, stderr = run_external_synthesizer(
                self.parameter('slugs_executable'), slugsin_path, byproduct('.json'),
                robotics_semantics=robotics, timeout=timeout, cancel=cancel)
            explanation = stderr.strip()
        else:
            response.error_code = error_code(
                'SYNTHESIS_FAILED', f'unknown backend {backend!r} (use one of {", ".join(BACKENDS)})')
            return
        response.synthesizable = realizable
        if not realizable:
            response.error_code = error_code(
                'SPEC_UNSYNTHESIZABLE',
                f'specification {stem.name!r} is unrealizable: {explanation}'.rstrip(': '))
            return
        byproduct('.json').write_text(strategy_to_json(strategy))
        response.automaton = automaton_to_msg(automaton_from_strategy(strategy, spec))
        response.error_code = error_code('SUCCESS')


def main():
    node_main(LTLSynthesisNode, 'ltl_synthesis')
