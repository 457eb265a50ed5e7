"""The robot interface: what every surface asks of a robot, whatever format describes it.

Two formats describe a robot, and each is one implementation of ``RobotDescription``:

``RobotAbstraction`` (``respec.robot.abstraction``)  our own format: control modes and actions
``CapabilitySystem`` (``respec.robot.cnu``)          CNU's capability files

A ``RobotSystem`` holds one as ``system.description``. Questions whose answer is plain data
(what a task starts from, whether goals keep their order, the sensors) are this protocol's.
What a layer above respec does differently per format (compiling, the pre-check, repair
candidates, the FlexBE mapping, the GUI's view, the simulated robot) stays in that layer, in a
registry keyed by the implementation class and looked up with
``respec.robot.system.for_description``::

    _COMPILERS = {RobotAbstraction: _compiled_for_modes, CapabilitySystem: _compiled_for_capabilities}
    compile = for_description(_COMPILERS, system, missing=_compiled_for_modes)

so respec imports nothing above it, and the format is told apart in one place
(``respec.robot.system``, where the file is read).
"""

from __future__ import annotations

from typing import Protocol


class RobotDescription(Protocol):
    """A robot as one file format describes it (implemented by RobotAbstraction and CapabilitySystem)."""

    @property
    def system(self) -> str:
        """The robot system's name (read-only: the implementations are frozen)."""

    @property
    def default_initial_conditions(self) -> list[str]:
        """What a task starts from when it names nothing: an abstraction's ``initial_mode``; a
        capability robot's specification gives its own (nothing to name)."""

    @property
    def reads_robot_state_by_default(self) -> bool:
        """Whether a task naming no initial conditions starts from the robot's reported state
        (a mode robot), rather than from what the robot's files say (a capability robot)."""

    @property
    def orders_goals(self) -> bool:
        """Whether goals may be asked in a strict order (eq. (20)); CNU's goals hold together at the end."""

    @property
    def sensors(self) -> tuple[str, ...]:
        """The environment propositions the robot reads that are not outcomes of what it does."""

