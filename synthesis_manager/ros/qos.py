"""QoS of the suite's services and actions: queues deep enough for bursts of up to QUEUE_DEPTH.

rclpy's defaults keep the last 10 requests (and responses) per endpoint, so the 11th of a
burst of goals silently overwrote an earlier one and its client waited forever. Every
service, service client, action server and action client of the suite uses these instead.
A burst deeper than a queue still loses its excess in DDS, unseen by either side (10,000
goals at once from a client with these queues: about 1,100 reached the server).
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

#: Requests (and responses) an endpoint holds before the oldest would be dropped.
QUEUE_DEPTH = 1000
#: Feedback is progress only: a shorter queue is enough.
FEEDBACK_DEPTH = 100


def service_qos() -> QoSProfile:
    """For services and their clients: reliable, volatile, QUEUE_DEPTH deep."""
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH,
                      reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)


def action_server_qos() -> dict:
    """Keyword arguments for rclpy's ActionServer."""
    return dict(goal_service_qos_profile=service_qos(), result_service_qos_profile=service_qos(),
                cancel_service_qos_profile=service_qos(),
                feedback_pub_qos_profile=QoSProfile(depth=FEEDBACK_DEPTH))


def action_client_qos() -> dict:
    """Keyword arguments for rclpy's ActionClient."""
    return dict(goal_service_qos_profile=service_qos(), result_service_qos_profile=service_qos(),
                cancel_service_qos_profile=service_qos(),
                feedback_sub_qos_profile=QoSProfile(depth=FEEDBACK_DEPTH))


def latched_qos() -> QoSProfile:
    """For a topic whose last message a late subscriber still gets (transient local, depth 1)."""
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL)
