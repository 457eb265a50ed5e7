"""``atlas-sim-operator``: a headless FlexBE operator that answers InputState's requests.

FlexBE's ``InputState`` asks the operator through the action ``flexbe/behavior_input``
(flexbe_msgs/BehaviorInput). FlexBE's own server for it, flexbe_input's
``input_action_server``, opens a Qt window per request; WebUI 4.0.3 serves none. This node
answers the same way flexbe_input does (``result_code`` OK, ``data`` = ``str(pickle.dumps(value))``,
nothing else) without a screen, for unattended runs and CI:

* by default from the robot system's configuration: each InputState of ``flexbe.states`` has
  a request type, its input action (e.g. ``object_template``) the simulated operator's answer
  (``simulation.scenario.operator_answers``; ATLAS: template id 1, the box in front of it);
* ``--scenario FILE`` (YAML: request type -> answer) and ``--answer TYPE=VALUE`` replace those.

A request type without an answer is aborted with a message saying so, as flexbe_input
aborts types it cannot handle. It is never required: flexbe_input's own answer works too.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import yaml

from atlas_sim.simulator.config import SimulationConfigError, SystemConfig
from atlas_sim.simulator.operator_data import answers_by_request_type, flexbe_input_data, parse_answers, quoted
from respec.robot import RobotSystem, robot_system
from respec.robot.files import add_config_dir_argument
from sm_generation.config import flexbe_config, input_request_capabilities

NODE_NAME = 'atlas_sim_operator'
BEHAVIOR_INPUT_ACTION = 'flexbe/behavior_input'


def configured_answers(system: RobotSystem) -> dict:
    """Request type -> answer, from the system's InputStates and its simulated operator."""
    settings = SystemConfig.of(system).simulation
    return answers_by_request_type(settings, input_request_capabilities(flexbe_config(system)))


def make_operator_node(answers: dict):
    """A node factory (``run_nodes``) serving ``flexbe/behavior_input`` with ``answers``."""
    from flexbe_msgs.action import BehaviorInput
    from rclpy.action import ActionServer
    from rclpy.node import Node

    class OperatorNode(Node):
        def __init__(self, **kwargs):
            super().__init__(NODE_NAME, **kwargs)
            self.answers = dict(answers)
            self.requests = []  # (request type, message) of every request, in order
            self.server = ActionServer(self, BehaviorInput, BEHAVIOR_INPUT_ACTION, self.answer)

        def answer(self, goal_handle):
            request = goal_handle.request
            self.requests.append((request.request_type, request.msg))
            result = BehaviorInput.Result()
            if request.request_type not in self.answers:
                result.result_code = BehaviorInput.Result.RESULT_ABORTED
                result.data = f'no answer for request type {request.request_type} ({quoted(request.msg)})'
                self.get_logger().warning(result.data)
                goal_handle.abort()
                return result
            value = self.answers[request.request_type]
            result.result_code = BehaviorInput.Result.RESULT_OK
            result.data = flexbe_input_data(value)
            self.get_logger().info(f'{quoted(request.msg)}: answered {quoted(value)}')
            goal_handle.succeed()
            return result

        def destroy_node(self):
            self.server.destroy()
            super().destroy_node()

    return OperatorNode


def parse_arguments(argv):
    parser = argparse.ArgumentParser(
        prog='atlas-sim-operator',
        description="A headless FlexBE operator: answers InputState's flexbe/behavior_input requests "
                    'as flexbe_input does, from the system configuration or a scenario.',
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    parser.add_argument('--system', default='atlas', help='robot system (config/<system>.yaml)')
    add_config_dir_argument(parser)
    parser.add_argument('--scenario', type=Path, default=None,
                        help='YAML file: BehaviorInput request type -> answer, e.g. "0: 1"')
    parser.add_argument('--answer', action='append', default=[], metavar='TYPE=VALUE',
                        help='answer requests of TYPE with the YAML VALUE, e.g. 0=1 or "3=[0.6, 0, 0]"')
    return parser.parse_known_args(argv)


def answers_from_arguments(args) -> dict:
    answers = configured_answers(robot_system(args.system, args.config_dir))
    if args.scenario is not None:
        with open(args.scenario, encoding='utf-8') as stream:
            document = yaml.safe_load(stream) or {}
        if not isinstance(document, dict):
            raise SimulationConfigError(f'{args.scenario}: expected a mapping of request types to answers',
                                        item=str(args.scenario))
        answers.update(parse_answers(document, str(args.scenario)))
    answers.update(parse_answers(args.answer, '--answer'))
    return answers


def main(argv=None):
    from synthesis_manager.ros.node_main import run_nodes

    args, ros_arguments = parse_arguments(sys.argv[1:] if argv is None else argv)
    try:
        answers = answers_from_arguments(args)
    except (OSError, yaml.YAMLError, SimulationConfigError) as error:
        print(f'atlas-sim-operator: {error}', file=sys.stderr)
        return 2
    listed = ', '.join(f'{request_type}: {quoted(value)}' for request_type, value in sorted(answers.items()))
    return run_nodes(make_operator_node(answers), argv=[sys.argv[0], *ros_arguments],
                     ready_message=f'{NODE_NAME} ready (answers by request type: {listed or "none"})')


if __name__ == '__main__':
    sys.exit(main())
