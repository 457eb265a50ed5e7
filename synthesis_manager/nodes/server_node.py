"""The ``/behavior_synthesis`` and ``/flexbe_synthesis`` action servers: compilation ->
synthesis -> state machine generation.

Both actions (the original BehaviorSynthesis and CNU's FlexBESynthesis, which FlexBE WebUI
revisions send) are read into one SynthesisTask and run the same pipeline with the same cancel;
synthesis_manager.ros.cnu_interface chooses FlexBESynthesis' type (CNU's own when importable).
Each stage is an asynchronous call to its service node (synthesis_manager.ros.pipeline), awaited by the goal's coroutine
(synthesis_manager.ros.stage_calls): a waiting goal holds no executor thread, so any number
of goals run side by side and the executor keeps serving. Cancel requests, the stage's time
limit, shutdown and the stage's node going away end the wait; a cancel is forwarded to the
synthesizer. Beyond ``max_active_goals`` goals at once, new goals are answered BUSY at once;
beyond twice that many accepted and unfinished (a flood), new goals are rejected on arrival.
A goal's ``timeout`` counts its whole pipeline from acceptance (synthesis_manager.limits).
"""

from __future__ import annotations

import contextlib
import threading
from dataclasses import replace

from rclpy.action import CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from respec.vocabulary.errors import INTERNAL_ERROR, CodedError, ErrorCode
from synthesis_manager.client_shares import ClientShares, goal_origin
from synthesis_manager.goals import GoalAdmission, PipelineOutcome, share_waiting_message
from synthesis_manager.limits import GoalDeadline, capped_timeout, check_message, check_timeout
from synthesis_manager.ros.action_goals import (ActionInterface, FeedbackChannel, HeapTrim, accepted_at,
                                                action_interfaces, flexbe_log_publisher, forget_goal_request)
from synthesis_manager.ros.action_server import BurstActionServer
from synthesis_manager.ros.cnu_interface import load_flexbe_synthesis_interface
from synthesis_manager.ros.errors import log_internal_error
from synthesis_manager.ros.logs import QuickLogger
from synthesis_manager.ros.node_main import node_main
from synthesis_manager.ros.pipeline import GoalPipeline
from synthesis_manager.ros.qos import action_server_qos
from synthesis_manager.ros.settings import declare_settings
from synthesis_manager.ros.stage_calls import WATCH_PERIOD, Preempted, ServerStoppingError, next_executor_turn
from synthesis_manager.settings import BEHAVIOR_SYNTHESIS_SERVER


class BehaviorSynthesisServer(Node):
    """Action servers ``behavior_synthesis`` (synthesis_msgs/action/BehaviorSynthesis) and
    ``flexbe_synthesis`` (CNU's flexbe_synthesis_msgs/action/FlexBESynthesis when importable, else
    our look-alike synthesis_msgs/action/FlexBESynthesis; the log says why, once).

    Settings (ROS parameters): ``synthesis_manager.settings.BEHAVIOR_SYNTHESIS_SERVER``. A goal
    runs its stages through :class:`GoalPipeline` (synthesis_manager.ros.pipeline), within its
    client's share (ClientShares) and the server's admission (GoalAdmission).
    """

    def __init__(self, **kwargs):
        super().__init__('behavior_synthesis_server', **kwargs)
        self.settings = declare_settings(self, BEHAVIOR_SYNTHESIS_SERVER)
        self._stopping = threading.Event()
        self.admission = GoalAdmission(lambda: self.settings.max_active_goals)
        self.heap_trim = HeapTrim(self)
        self.shares = ClientShares(self.settings.max_client_goals, self.settings.max_client_goal_seconds,
                                   self.settings.max_client_waiting)
        self.log = QuickLogger(self.get_logger())  # a line per failed goal
        self.log_to_flexbe = flexbe_log_publisher(self, self.settings.flexbe_log_topic)
        group = ReentrantCallbackGroup()
        self.pipeline = GoalPipeline(self, self.log, self._stopping, group)
        flexbe_synthesis = load_flexbe_synthesis_interface()
        # Before `make flexbe` CNU's package is missing in every ordinary run: said at debug
        # here, and once plainly when a client uses /flexbe_synthesis (where it matters).
        self._fallback_note = flexbe_synthesis.fallback_reason
        if self._fallback_note:
            self.get_logger().debug(self._fallback_note)
        # rclpy keeps each result for result_timeout seconds (default 900: ~38 KB per goal).
        self.action_servers = [
            BurstActionServer(self, interface.action_type, interface.action_name,
                         self._executor_for(interface),
                         goal_callback=self.admit_goal,
                         cancel_callback=lambda _: CancelResponse.ACCEPT, callback_group=group,
                         result_timeout=max(1, round(self.settings.result_retention)),
                         **action_server_qos())
            for interface in action_interfaces(flexbe_synthesis)]

    def _executor_for(self, interface):
        """The execute callback of ``interface``'s action server (a coroutine function)."""
        async def execute(goal_handle):
            try:
                return await self.execute(goal_handle, interface)
            finally:
                self.admission.finished()
                forget_goal_request(goal_handle)
                self.heap_trim()
        return execute

    def stop_work(self):
        """Make goals that are waiting on a stage give up (at shutdown)."""
        self.pipeline.stop()

    def destroy_node(self):
        for action_server in self.action_servers:
            action_server.destroy()
        super().destroy_node()

    async def execute(self, goal_handle, interface: ActionInterface):
        if self._fallback_note and interface.action_name == 'flexbe_synthesis':
            self.get_logger().info(self._fallback_note)
            self._fallback_note = ''
        feedback = FeedbackChannel(goal_handle, interface.action_type.Feedback, listeners=lambda: self.count_subscribers(
            f'{interface.action_name}/_action/feedback'))
        outcome = PipelineOutcome()
        task = deadline = None
        try:
            check_message(goal_handle.request, 'goal')
            task = interface.read_goal(goal_handle.request, self.settings.default_system)
            requested = check_timeout(task.timeout)
            task = replace(task, timeout=capped_timeout(requested, self.settings.max_goal_timeout))
            deadline = GoalDeadline(task.timeout, started=accepted_at(self, goal_handle), requested=requested)
            if deadline.capped():
                feedback(deadline.capped())
            async with self.client_share(goal_handle, feedback, deadline):
                with self.admission.running():
                    await self.pipeline.run(goal_handle, task, outcome, feedback, deadline)
        except Preempted:
            outcome.fail(ErrorCode.PREEMPTED, 'cancelled by the client')
            goal_handle.canceled()
            return interface.make_result(outcome)
        except CodedError as error:
            outcome.fail(error.code, str(error))
        except Exception as error:  # noqa: BLE001 - a bug: logged with its traceback; the server keeps serving
            log_internal_error(self.get_logger(), 'behavior synthesis failed', error)
            outcome.fail(INTERNAL_ERROR, f'internal error: {error!r}')
        if not outcome.succeeded and task is not None:
            await self.pipeline.suggest_fixes(goal_handle, task, outcome, feedback, deadline)
        if outcome.succeeded:
            goal_handle.succeed()
        else:
            # Clients that drop the result of an aborted goal still see why: the last feedback
            # says it, and FlexBE WebUI 4.0.3 (which also drops feedback) shows FlexBE's log.
            failure = f'{outcome.code}: {outcome.message}'
            feedback(failure)
            self.log_to_flexbe(f'Behavior synthesis failed: {failure}')
            self.log.warning(failure)
            goal_handle.abort()
        return interface.make_result(outcome)

    def admit_goal(self, _goal_request) -> GoalResponse:
        """Accept a goal unless a flood is under way (GoalAdmission: beyond twice
        max_active_goals accepted, one response and no result for a client to lose; send-goal
        reports it as BUSY)."""
        return GoalResponse.ACCEPT if self.admission.accept() else GoalResponse.REJECT

    @contextlib.asynccontextmanager
    async def client_share(self, goal_handle, feedback, deadline: GoalDeadline):
        """Run a goal within its client's share (ClientShares): until it fits, it waits, told
        its place; its time limit (or, without one, its stages' limits) counts against the
        client's max_client_goal_seconds."""
        seconds = deadline.limit or sum(getattr(self.settings, f'{stage}_timeout')
                                        for stage in ('compilation', 'synthesis', 'generation'))
        ticket = self.shares.join(goal_origin(goal_handle.goal_id.uuid), seconds)
        try:
            told = 0
            while place := self.shares.admit(ticket):
                if goal_handle.is_cancel_requested:
                    raise Preempted()
                if self._stopping.is_set():
                    raise ServerStoppingError('the server is shutting down')
                if deadline.passed():
                    raise deadline.timed_out("waiting for its client's running goals to finish")
                if place != told:
                    told = place
                    feedback(share_waiting_message(self.shares, ticket, place))
                await next_executor_turn(look_every=WATCH_PERIOD)
            yield
        finally:
            self.shares.leave(ticket)


def main():
    node_main(BehaviorSynthesisServer, 'behavior_synthesis_server')
