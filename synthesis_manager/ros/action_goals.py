"""The action servers' goals as ROS sees them: the served action types and their results, a
goal's feedback, its acceptance time, what is forgotten or given back once it ends, and
FlexBE's operator log (synthesis_manager.goals holds what is not ROS)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any, Callable

from rclpy.node import Node
from rclpy.time import Time

from respec.child_processes.memory import released_memory
from synthesis_manager.goals import PipelineOutcome
from synthesis_manager.requests import task_from_behavior_synthesis, task_from_flexbe_synthesis
from synthesis_manager.ros.conversions import error_code
from synthesis_msgs.action import BehaviorSynthesis
from synthesis_msgs.msg import FSAutomaton, LTLSpecification


@dataclass(frozen=True)
class ActionInterface:
    """An action type served by this node: how its goals and results map to the pipeline's."""

    action_type: type[Any]      # a generated action class (its Goal, Result, Feedback)
    action_name: str
    read_goal: Callable        # (goal, default_system) -> SynthesisTask
    make_result: Callable      # (PipelineOutcome) -> action_type.Result


def behavior_synthesis_result(outcome: PipelineOutcome):
    return BehaviorSynthesis.Result(
        error_code=error_code(outcome.code, outcome.message_with_fixes()), states=outcome.states,
        ltl_specification=LTLSpecification() if outcome.ltl_specification is None else outcome.ltl_specification,
        automaton=FSAutomaton() if outcome.automaton is None else outcome.automaton)


def action_interfaces(flexbe_synthesis) -> tuple[ActionInterface, ...]:
    """The served actions; ``flexbe_synthesis``: the FlexBESynthesisInterface offered."""
    def flexbe_synthesis_result(outcome: PipelineOutcome):
        return flexbe_synthesis.result(outcome.code, outcome.message, outcome.states, outcome.notes, outcome.fixes)
    return (ActionInterface(BehaviorSynthesis, 'behavior_synthesis', task_from_behavior_synthesis,
                            behavior_synthesis_result),
            ActionInterface(flexbe_synthesis.action_type, 'flexbe_synthesis', task_from_flexbe_synthesis,
                            flexbe_synthesis_result))


#: How long a goal's first feedback waits for a feedback subscriber to be discovered (seconds).
FEEDBACK_LISTENER_WAIT = 0.5


class FeedbackChannel:
    """Publishes a goal's feedback and remembers the progress reached.

    ``listeners()`` counts the feedback topic's subscribers: a client that has just found the
    server (``ros2 action send_goal --feedback``) may not yet be matched to its feedback, which
    is not kept for late subscribers; a quick goal's first feedback waits FEEDBACK_LISTENER_WAIT
    at most for one, or it would be lost."""

    def __init__(self, goal_handle, feedback_type, listeners=None):
        self.goal_handle, self.feedback_type, self.progress = goal_handle, feedback_type, 0.0
        self._listeners = listeners

    def __call__(self, status: str, progress: float | None = None):
        if progress is not None:
            self.progress = float(progress)
        if self._listeners is not None:
            waited_until = time.monotonic() + FEEDBACK_LISTENER_WAIT
            while self._listeners() == 0 and time.monotonic() < waited_until:
                time.sleep(0.02)
            self._listeners = None  # once per goal
        self.goal_handle.publish_feedback(self.feedback_type(status=status, progress=self.progress))


def forget_goal_request(goal_handle) -> None:
    """Empty a finished goal's request: rclpy keeps its handle, the request included, until the
    result is gone (result_retention), so a refused 50 MB goal would hold its 50 MB that long."""
    request = goal_handle.request
    empty = type(request)()
    for name in request.get_fields_and_field_types():
        setattr(request, name, getattr(empty, name))


class HeapTrim:
    """Give freed heap pages back to the system after goals (what a big goal's strings left):
    PERIOD seconds after the last goal ended (a trim takes 1-9 ms; a burst gets one, after it).
    A node timer, idle between goals, not a thread: one started while the process shuts down
    would never run, and its starter would wait for it forever."""

    PERIOD = 1.0

    def __init__(self, node: Node):
        self.timer = node.create_timer(self.PERIOD, self._trim)
        self.timer.cancel()

    def __call__(self) -> None:
        self.timer.reset()

    def _trim(self) -> None:
        self.timer.cancel()
        released_memory(collect=False)


def flexbe_log_publisher(node: Node, topic: str) -> Callable[[str], None]:
    """A function logging an error on FlexBE's operator log (flexbe_msgs/BehaviorLog).

    FlexBE is not on the package registries, so this only logs where flexbe_msgs is installed
    (always so for FlexBE users); elsewhere, or with an empty topic, it does nothing.
    """
    try:
        from flexbe_msgs.msg import BehaviorLog
    except ImportError:
        BehaviorLog = None
    if BehaviorLog is None or not topic:
        return lambda text: None
    publisher = node.create_publisher(BehaviorLog, topic, 10)
    return lambda text: publisher.publish(BehaviorLog(text=text, status_code=BehaviorLog.ERROR))


def accepted_at(node: Node, goal_handle) -> float:
    """When the goal was accepted (time.monotonic()): its time limit counts from then."""
    # rclpy stamps GoalInfo with the server's clock on acceptance; ServerGoalHandle exposes
    # only its goal_id, so the stamp is read from the GoalInfo it keeps.
    stamp = getattr(goal_handle, '_goal_info', None)
    if stamp is None:
        return time.monotonic()
    waited = (node.get_clock().now() - Time.from_msg(stamp.stamp)).nanoseconds / 1e9
    return time.monotonic() - max(0.0, waited)
