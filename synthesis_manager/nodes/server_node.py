"""The ``/behavior_synthesis`` action server: compilation -> synthesis -> state machine generation.

Each stage is an asynchronous call to its service node. Waiting happens in the goal's own
executor thread (MultiThreadedExecutor), so goals run side by side and the executor keeps
serving; cancel requests are checked while waiting and forwarded to the synthesizer, which
stops within about a second.
"""

from __future__ import annotations

import threading
import time

from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from respec.naming import DEFAULT_SM_OUTCOMES, parse_names
from synthesis_manager.requests import InvalidRequest, selected_option
from synthesis_manager.ros.conversions import error_code, error_name, is_empty_spec
from synthesis_manager.ros.node_main import node_main
from synthesis_msgs.action import BehaviorSynthesis
from synthesis_msgs.srv import (CancelSynthesis, GenerateFlexBESM, GenerateLTLSpecification,
                                SynthesizeAutomaton)


class StageFailed(Exception):
    """A pipeline stage ended the goal; carries the error code name and message."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code

    @classmethod
    def from_error_code(cls, error_code_msg) -> 'StageFailed':
        name = error_name(error_code_msg.value)
        return cls(name, error_code_msg.message or name)


class Preempted(Exception):
    """The client cancelled the goal."""


class BehaviorSynthesisServer(Node):
    """Action server ``behavior_synthesis`` (synthesis_msgs/action/BehaviorSynthesis).

    Parameters: ``service_timeout`` (seconds to wait for a service to appear),
    ``compilation_timeout``, ``synthesis_timeout`` and ``generation_timeout`` (seconds per stage).
    """

    def __init__(self, **kwargs):
        super().__init__('behavior_synthesis_server', **kwargs)
        self.declare_parameter('service_timeout', 5.0)
        self.declare_parameter('compilation_timeout', 30.0)
        self.declare_parameter('synthesis_timeout', 120.0)
        self.declare_parameter('generation_timeout', 30.0)
        self._stopping = threading.Event()
        group = ReentrantCallbackGroup()
        self.compiler = self.create_client(GenerateLTLSpecification, 'ltl_compilation', callback_group=group)
        self.synthesizer = self.create_client(SynthesizeAutomaton, 'ltl_synthesis', callback_group=group)
        self.synthesis_cancel = self.create_client(CancelSynthesis, 'ltl_synthesis/cancel', callback_group=group)
        self.generator = self.create_client(GenerateFlexBESM, 'sm_generate', callback_group=group)
        self.action_server = ActionServer(
            self, BehaviorSynthesis, 'behavior_synthesis', self.execute,
            goal_callback=lambda _: GoalResponse.ACCEPT,
            cancel_callback=lambda _: CancelResponse.ACCEPT, callback_group=group)

    def stop_work(self):
        """Make goals that are waiting on a stage give up (at shutdown)."""
        self._stopping.set()

    def destroy_node(self):
        self.action_server.destroy()
        super().destroy_node()

    def parameter(self, name):
        return self.get_parameter(name).value

    # --- goal execution -----------------------------------------------------------------

    def execute(self, goal_handle):
        result = BehaviorSynthesis.Result()
        try:
            self.run_pipeline(goal_handle, result)
        except Preempted:
            goal_handle.canceled()
            result.error_code = error_code('PREEMPTED', 'cancelled by the client')
            return result
        except StageFailed as failure:
            result.error_code = error_code(failure.code, str(failure))
        except InvalidRequest as invalid:
            result.error_code = error_code(invalid.code, str(invalid))
        except Exception as error:  # the server keeps serving whatever happens
            self.get_logger().error(f'behavior synthesis failed: {error!r}')
            result.error_code = error_code('BEHAVIOR_SYNTHESIS_FAILED', f'internal error: {error}')
        if result.error_code.value == result.error_code.SUCCESS:
            goal_handle.succeed()
        else:
            self.get_logger().warning(result.error_code.message)
            goal_handle.abort()
        return result

    def run_pipeline(self, goal_handle, result):
        goal = goal_handle.request
        request = goal.request
        option = selected_option(goal.synthesis_options)
        goal_id = bytes(goal_handle.goal_id.uuid).hex()
        spec_name = request.name or f'{request.system or "behavior"}_{goal_id[:8]}'
        feedback = lambda status, progress: goal_handle.publish_feedback(  # noqa: E731
            BehaviorSynthesis.Feedback(status=status, progress=float(progress)))

        if option == 'ltl_synthesis_only':
            if is_empty_spec(request.ltl_specification):
                raise InvalidRequest('ltl_synthesis_only needs the complete LTL specification '
                                     'in request.ltl_specification')
            result.ltl_specification = request.ltl_specification
        else:
            feedback('Compiling the LTL specification', 0.05)
            compiled = self.call(goal_handle, self.compiler, GenerateLTLSpecification.Request(
                system=request.system, goals=parse_names(request.goal),
                initial_conditions=parse_names(request.initial_condition),
                sm_outcomes=list(request.sm_outcomes) or list(DEFAULT_SM_OUTCOMES),
                custom_ltl=request.ltl_specification, unordered_goals=request.unordered_goals),
                'LTL compilation', self.parameter('compilation_timeout'))
            self.check(compiled.error_code)
            result.ltl_specification = compiled.ltl_specification
            feedback('Compiled the LTL specification', 1 / 3)
            if option == 'ltl_compilation_only':
                result.error_code = error_code('SUCCESS')
                return

        feedback('Synthesizing an automaton', 0.4)
        timeout = request.timeout or self.parameter('synthesis_timeout')
        synthesized = self.call(goal_handle, self.synthesizer, SynthesizeAutomaton.Request(
            ltl_specification=result.ltl_specification, spec_name=spec_name,
            timeout=float(timeout), request_id=goal_id),
            'LTL synthesis', timeout + 5.0, on_cancel=lambda: self.cancel_synthesis(goal_id))
        self.check(synthesized.error_code)
        result.automaton = synthesized.automaton
        feedback(f'Synthesized an automaton with {len(result.automaton.automaton)} states', 2 / 3)
        if option in ('ltl_synthesis_only', 'ltl_steps_only'):
            result.error_code = error_code('SUCCESS')
            return

        feedback('Generating the state machine', 0.7)
        generated = self.call(goal_handle, self.generator, GenerateFlexBESM.Request(
            automaton=result.automaton, system=request.system,
            initial_conditions=parse_names(request.initial_condition)),
            'state machine generation', self.parameter('generation_timeout'))
        self.check(generated.error_code)
        result.states = generated.state_definition
        states = [s for s in result.states if s.state_path != '/' and s.state_class != s.CLASS_OUTCOME]
        feedback(f'Generated a state machine with {len(states)} states', 1.0)
        result.error_code = error_code('SUCCESS')

    @staticmethod
    def check(code):
        if code.value != code.SUCCESS:
            raise StageFailed.from_error_code(code)

    def call(self, goal_handle, client, request, stage: str, timeout: float, on_cancel=None):
        """Call a service asynchronously; wait while watching for cancel and the time limit."""
        if not client.wait_for_service(timeout_sec=self.parameter('service_timeout')):
            raise StageFailed('SERVICE_UNAVAILABLE',
                              f'{stage}: service {client.srv_name!r} is not available')
        future = client.call_async(request)
        done = threading.Event()
        future.add_done_callback(lambda _: done.set())
        deadline = time.monotonic() + timeout
        while not done.wait(0.02):
            if self._stopping.is_set():
                raise StageFailed('BEHAVIOR_SYNTHESIS_FAILED', f'{stage}: the server is shutting down')
            if goal_handle.is_cancel_requested:
                if on_cancel:
                    on_cancel()
                client.remove_pending_request(future)
                raise Preempted()
            if time.monotonic() > deadline:
                if on_cancel:
                    on_cancel()
                client.remove_pending_request(future)
                raise StageFailed('TIMEOUT', f'{stage}: no answer from {client.srv_name!r} '
                                  f'within {timeout:g} s')
        return future.result()

    def cancel_synthesis(self, goal_id: str):
        """Tell the synthesizer to stop this goal's synthesis (fire and forget)."""
        if self.synthesis_cancel.service_is_ready():
            self.synthesis_cancel.call_async(CancelSynthesis.Request(request_id=goal_id))


def main():
    node_main(BehaviorSynthesisServer, 'behavior_synthesis_server')
