"""The ``sm_generate`` service node (GenerateFlexBESM): a thin adapter around generate_state_machine.

Small automata (the tasks' own, a few dozen states) are turned into state machines at once, in
this process. A large one (a synthesized strategy may have up to the synthesis node's
``max_strategy_edges``; 100,000 states took 5.5 s here) is generated in a child process
(``synthesis_manager.ros.child_stage``), within the node's time and memory limits and killed at
shutdown, so one request can neither hold this process's interpreter for seconds nor grow it
without bound.
"""

from __future__ import annotations

import time
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from respec.vocabulary.errors import ErrorCode
from respec.robot import SystemCatalog
from sm_generation import generate_state_machine
from sm_generation.config import generation_system_errors
from sm_generation.state_machine import StateMachine
from synthesis_manager.limits import check_message, check_timeout
from synthesis_manager.ros.child_stage import ChildStage, StageStopped
from synthesis_manager.ros.conversions import error_code, msg_to_automaton, state_to_msg
from synthesis_manager.ros.errors import reported_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.qos import service_qos
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.settings import SM_GENERATION
from synthesis_msgs.srv import CancelSynthesis, GenerateFlexBESM

#: Automata with more states than this are generated in a child process (2,000 chain states
#: took 76 ms in-process; starting the work in a child costs a few milliseconds more).
SMALL_AUTOMATON_STATES = 2000
#: How often requests waiting for a generation child look at their deadline.


def generated_states(automaton, system: str, catalog: SystemCatalog, initial_conditions: list[str] | None,
                     reduce: bool) -> StateMachine:
    """The machine of ``automaton`` on ``catalog``'s system of that name (the node's edge: in a
    child process too, so it takes the name)."""
    with generation_system_errors():
        robot = catalog.load(system)
    return generate_state_machine(automaton, robot, initial_conditions=initial_conditions, reduce=reduce)


class SMGenerationNode(Node):
    """Turns synthesized automata into FlexBE state instantiations.

    Settings (ROS parameters): ``synthesis_manager.settings.SM_GENERATION``; ``timeout``,
    ``memory_limit_mb`` and the parallel and queued generations bound automata over
    SMALL_AUTOMATON_STATES states, generated in child processes.
    """

    def __init__(self, **kwargs):
        super().__init__('sm_generation', **kwargs)
        self.log = QuickLogger(self.get_logger())  # a line per failed request
        self.settings = declare_settings(self, SM_GENERATION)
        self.children = ChildStage(self, 'sm_generation', self.settings.parallel_generations,
                                   self.settings.queued_generations, name='generation',
                                   what='state machine generation', failed=ErrorCode.SM_GENERATION_FAILED)
        group = ReentrantCallbackGroup()
        self.create_service(GenerateFlexBESM, 'sm_generate', self.on_request,
                            callback_group=group, qos_profile=service_qos())
        self.create_service(CancelSynthesis, 'sm_generate/cancel', self.on_cancel_request,
                            callback_group=group, qos_profile=service_qos())

    def stop_work(self):
        """Stop every generation in a child process (at shutdown, so the process exits promptly)."""
        self.children.stop()

    def destroy_node(self):
        self.children.stop()
        return super().destroy_node()

    def on_cancel_request(self, request, response):
        """``sm_generate/cancel``: stop a large generation by its request id (PREEMPTED)."""
        response.cancelled = self.children.cancel(request.request_id)
        return response

    async def on_request(self, request, response):
        try:
            # No list or whole-message bound: the automaton is a synthesis result, as large as the
            # specification makes it (its strings and names are still checked).
            arrival = time.monotonic()
            check_message(request, max_list=None, max_total=None)
            requested = check_timeout(request.timeout, 'request.timeout')  # 0: the node's own limit
            arguments = (msg_to_automaton(request.automaton), request.system)
            options = {'catalog': SystemCatalog(self.settings.config_dir or None),
                       'initial_conditions': list(request.initial_conditions) or None,
                       'reduce': self.settings.reduce}
            if len(request.automaton.automaton) <= SMALL_AUTOMATON_STATES:
                states = generated_states(*arguments, **options)
            else:
                try:
                    states = await self.children.run(generated_states, arguments, options,
                                                     size=f'{len(request.automaton.automaton):,} automaton states',
                                                     arrival=arrival, requested=requested,
                                                     request_id=request.request_id)
                except StageStopped as stopped:
                    response.error_code = stopped.error_code
                    self.log.warning(response.error_code.message)
                    return response
        except Exception as error:  # noqa: BLE001 - every failure becomes an error code; the node keeps serving
            response.error_code = reported_error(error, self.get_logger(), 'state machine generation failed')
            self.log.warning(response.error_code.message)
            return response
        response.state_definition = [state_to_msg(state) for state in states.to_instantiations()]
        response.error_code = error_code()
        return response


def main():
    node_main(SMGenerationNode, 'sm_generation')
