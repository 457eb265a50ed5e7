"""The ``sm_generate`` service node (GenerateFlexBESM): a thin adapter around generate_state_machine."""

from __future__ import annotations

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from sm_generation import generate_state_machine
from synthesis_manager.ros.conversions import error_code, msg_to_automaton, state_to_msg
from synthesis_manager.limits import check_message
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_msgs.srv import GenerateFlexBESM


class SMGenerationNode(Node):
    """Turns synthesized automata into FlexBE state instantiations.

    Parameters: ``config_dir`` (directories of robot system files searched before the packaged config/),
    ``reduce`` (merge equivalent automaton states).
    """

    def __init__(self, **kwargs):
        super().__init__('sm_generation', **kwargs)
        self.declare_parameter('config_dir', '')
        self.declare_parameter('reduce', False)
        self.create_service(GenerateFlexBESM, 'sm_generate', self.on_request,
                            callback_group=ReentrantCallbackGroup(), qos_profile=service_qos())

    def on_request(self, request, response):
        try:
            # No list or whole-message bound: the automaton is a synthesis result, as large as the
            # specification makes it (its strings and names are still checked).
            check_message(request, max_list=None, max_total=None)
            states = generate_state_machine(
                msg_to_automaton(request.automaton), request.system,
                config_dir=self.get_parameter('config_dir').value or None,
                initial_conditions=list(request.initial_conditions) or None,
                reduce=self.get_parameter('reduce').value)
        except Exception as error:  # every failure becomes an error code; the node keeps serving
            response.error_code = reported_error(error, self.get_logger(), 'state machine generation failed')
            self.get_logger().warning(response.error_code.message)
            return response
        response.state_definition = [state_to_msg(state) for state in states]
        response.error_code = error_code()
        return response


def main():
    node_main(SMGenerationNode, 'sm_generation')
