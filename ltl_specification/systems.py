"""The robot system of a task, with the compiler's error codes.

Shared by the compiler and the diagnosis (which the compiler calls to explain a refusal), so
neither imports the other for it. The edges that turn a task's system name into a RobotSystem
(the ``compile`` command, the compilation node) read it inside ``task_system_errors``.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

from respec.robot import RobotSystem
from respec.robot.abstraction import AbstractionConfigError, RobotAbstraction
from respec.robot.files import SystemNotFoundError

from ltl_specification.errors import InvalidAbstractionError, UnknownSystemError


@contextmanager
def task_system_errors() -> Iterator[None]:
    """The compiler's codes for an unknown or invalid robot system read in this block, e.g.
    ``with task_system_errors(): system = robot_system(name, config_dir)``. A file that cannot
    be read as a robot file keeps its own CONFIG_FILE_INVALID, as every command and both
    actions report it (ConfigFileInvalidError)."""
    try:
        yield
    except SystemNotFoundError as error:
        raise UnknownSystemError(str(error), item=error.item) from error
    except AbstractionConfigError as error:
        raise InvalidAbstractionError(str(error), item=error.item) from error


def load_task_abstraction(system: RobotSystem) -> RobotAbstraction:
    """The abstraction of an abstraction-kind system, with the compiler's code when it has none."""
    try:
        return system.required_abstraction()
    except AbstractionConfigError as error:
        raise InvalidAbstractionError(str(error), item=error.item) from error
