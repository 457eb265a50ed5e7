"""The ``ltl_compilation`` service node (GenerateLTLSpecification): a thin adapter around compile_task."""

from __future__ import annotations

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from std_msgs.msg import String

from ltl_specification import compile_task
from ltl_specification.provenance import provenance_to_json
from respec.robot import SystemCatalog, catalog_to_json
from respec.robot.files import SystemConfigError
from respec.naming import DEFAULT_SM_OUTCOMES
from respec.nesting import run_with_deep_stack
from synthesis_manager.ros.conversions import error_code, msg_to_sections, spec_to_msg
from synthesis_manager.limits import check_message
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.robot_systems import create_systems_publisher
from synthesis_msgs.srv import GenerateLTLSpecification


class LTLCompilationNode(Node):
    """Compiles partial tasks into complete GR(1) specifications.

    Parameters: ``config_dir`` (directories of robot system files searched before the packaged
    config/, joined with os.pathsep; empty = config/ alone). Publishes those systems on ``robot_systems`` (latched; checked for edits
    every ``SYSTEMS_PERIOD`` seconds), so clients elsewhere see the systems it compiles for.
    """

    SYSTEMS_PERIOD = 2.0

    def __init__(self, **kwargs):
        super().__init__('ltl_compilation', **kwargs)
        self.declare_parameter('config_dir', '')
        self.create_service(GenerateLTLSpecification, 'ltl_compilation', self.on_request,
                            callback_group=ReentrantCallbackGroup(), qos_profile=service_qos())
        self._systems_publisher = create_systems_publisher(self)
        self._published_systems = None
        self.publish_systems()
        self.create_timer(self.SYSTEMS_PERIOD, self.publish_systems)

    def catalog(self) -> SystemCatalog:
        return SystemCatalog(self.get_parameter('config_dir').value or None)

    def publish_systems(self) -> None:
        """Publish the systems when they changed (a system file edited, added or removed)."""
        try:
            text = catalog_to_json(self.catalog())
        except (OSError, SystemConfigError) as error:  # e.g. a config directory vanished: keep the last list
            self.get_logger().warning(f'cannot read the robot systems: {error}')
            return
        if text != self._published_systems:
            self._systems_publisher.publish(String(data=text))
            self._published_systems = text

    def on_request(self, request, response):
        try:
            check_message(request)
            # Custom formulas may nest MAX_FORMULA_NESTING deep: compiled and printed on a deep stack.
            response.ltl_specification, response.provenance = run_with_deep_stack(self._compile, request)
        except Exception as error:  # every failure becomes an error code; the node keeps serving
            response.error_code = reported_error(error, self.get_logger(), 'LTL compilation failed')
            self.get_logger().warning(response.error_code.message)
            return response
        response.error_code = error_code()
        return response

    def _compile(self, request):
        """The request's specification message and its provenance (JSON)."""
        spec = compile_task(
            request.system, list(request.initial_conditions), list(request.goals),
            sm_outcomes=tuple(request.sm_outcomes) or DEFAULT_SM_OUTCOMES,
            strict_order=not request.unordered_goals,
            custom_ltl=msg_to_sections(request.custom_ltl) or None,
            config_dir=self.get_parameter('config_dir').value or None)
        # CNU capability systems record none: their unrealizable specifications are not diagnosed.
        provenance = provenance_to_json(spec.provenance) if spec.provenance is not None else ''
        return spec_to_msg(spec), provenance


def main():
    node_main(LTLCompilationNode, 'ltl_compilation')
