"""Initial conditions detected at runtime (paper Sec. V-A and VIII-B, "Synthesis on-the-fly").

"The initial conditions are either specified by the user or detected at runtime": a request
that names none, or just the word ``current``, is synthesized from where the robot is now.
A robot reports its discrete state as its current control mode and the actions whose
latest outcome was ``completed`` (and whose completion still holds); these are exactly the
task's initial conditions 𝓘, since eq. (14) makes their completion propositions true
initially and every other outcome proposition false, as the robot would report them.

ROS-free: the server node reads the robot state topic and calls these functions; the
status line it publishes is written and read here, so clients can tell which initial
conditions a behavior was synthesized from.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

from ltl_specification.errors import InvalidInitialConditionsError

if TYPE_CHECKING:
    from respec.robot import RobotSystem

#: The initial condition that stands for "wherever the robot is now".
CURRENT = 'current'

_STATUS = re.compile(r'^Initial conditions from (?P<source>\S+): (?P<names>.*)$')


def asks_for_robot_state(initial_conditions: Sequence[str]) -> bool:
    """Whether a request leaves its initial conditions to the robot: none given, or ``current``.

    ``current`` already means all of the robot's initial conditions, so naming others
    beside it is an error (naming the first of them).
    """
    names = list(initial_conditions)
    if CURRENT not in names:
        return not names
    others = [name for name in names if name != CURRENT]
    if others:
        raise InvalidInitialConditionsError(
            f"initial condition {CURRENT!r} stands for the robot's whole state and cannot be combined "
            f"with {', '.join(map(repr, others))}", item=others[0])
    return True


def reads_robot_state(initial_conditions: Sequence[str], system: RobotSystem | None) -> bool:
    """Whether the server must read the robot's state for this request (``asks_for_robot_state``).

    ``system`` is None when it cannot be read (compiling the task reports why). A robot
    described by CNU's capability files keeps CNU's meaning of no initial conditions: its
    specification already gives them (``current`` still asks the robot).
    """
    if not asks_for_robot_state(initial_conditions):
        return False
    if CURRENT in initial_conditions:
        return True
    return system is None or system.reads_robot_state_by_default


def initial_conditions_from_robot_state(mode: str, completed_actions: Iterable[str],
                                        source: str = 'the robot state') -> list[str]:
    """𝓘 of a robot: its control ``mode`` first, then its ``completed_actions`` in their order.

    ``source`` (e.g. the state topic) names where the state came from in errors: every
    robot system has control modes, so a state without one is not a usable state.
    """
    if not mode:
        raise InvalidInitialConditionsError(f'the robot state from {source} names no control mode',
                                            item=source)
    return list(dict.fromkeys([mode, *(action for action in completed_actions if action)]))


def detected_status(initial_conditions: Sequence[str], source: str) -> str:
    """The status line reporting the initial conditions detected from ``source``."""
    return f'Initial conditions from {source}: {", ".join(initial_conditions)}'


def initial_conditions_in_status(status: str) -> tuple[str, list[str]] | None:
    """``(source, initial conditions)`` from a :func:`detected_status` line, else None."""
    match = _STATUS.match(status or '')
    if match is None:
        return None
    return match['source'], [name for name in match['names'].split(', ') if name]
