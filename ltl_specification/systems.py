"""The robot system of a task, loaded with the compiler's error codes.

Shared by the compiler and the diagnosis (which the compiler calls to explain a refusal), so
neither imports the other for it.
"""

from __future__ import annotations

from respec.robot import RobotSystem, robot_system
from respec.robot.abstraction import AbstractionConfigError, RobotAbstraction
from respec.robot.files import SystemNotFoundError

from ltl_specification.errors import InvalidAbstractionError, UnknownSystemError


def load_task_system(system: RobotSystem | str, config_dir=None) -> RobotSystem:
    """The task's robot system, with the compiler's codes for an unknown or invalid one. A file
    that cannot be read as a robot file keeps its own CONFIG_FILE_INVALID, as every command and
    both actions report it (ConfigFileInvalidError)."""
    try:
        return robot_system(system, config_dir)
    except SystemNotFoundError as error:
        raise UnknownSystemError(str(error), item=error.item) from error
    except AbstractionConfigError as error:
        raise InvalidAbstractionError(str(error), item=error.item) from error


def load_task_abstraction(system: RobotSystem | str, config_dir=None) -> RobotAbstraction:
    """The abstraction of an abstraction-kind system (as ``load_task_system``)."""
    system = load_task_system(system, config_dir)
    try:
        return system.required_abstraction()
    except AbstractionConfigError as error:
        raise InvalidAbstractionError(str(error), item=error.item) from error
