"""Robots side by side: the ROS namespaces our nodes and clients are placed in.

Every name our nodes use (services, actions, topics) is relative, so a node placed in
``/robot1`` (``Node(namespace=...)`` or ``--ros-args -r __ns:=/robot1``) serves and asks
``/robot1/...``: each robot's server reads that robot's ``atlas_sim/state`` and FlexBE's
``flexbe/log``. Only the synthesis service may be shared between robots; a server reaches a
shared one through standard remapping (:func:`synthesis_service_remapping`).
"""

from __future__ import annotations


def absolute_namespace(namespace: str) -> str:
    """'robot1' and '/robot1/' -> '/robot1'; '' stays '' (no namespace given); '/' stays '/'."""
    return '/' + namespace.strip('/') if namespace else ''


def namespace_placement(namespace: str) -> dict:
    """Keyword arguments placing a node in ``namespace`` ({} for none: the node's default)."""
    namespace = absolute_namespace(namespace)
    return {'namespace': namespace} if namespace else {}


def synthesis_service_remapping(namespace: str) -> list[str]:
    """Node arguments pointing a server's ``ltl_synthesis`` clients at ``namespace``'s service.

    Standard ROS remapping (``-r from:=to``): the server's other names stay relative, so it
    still follows its own namespace for its other stages and for the robot's state topic.
    """
    target = absolute_namespace(namespace).rstrip('/')
    return ['--ros-args', '-r', f'ltl_synthesis:={target}/ltl_synthesis',
            '-r', f'ltl_synthesis/cancel:={target}/ltl_synthesis/cancel']
