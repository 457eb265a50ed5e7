"""A robot's discrete abstraction: control modes, actions, outcomes and sensors.

It is read from the ``abstraction:`` section of ``config/<system>.yaml``::

    abstraction:
      outcomes: [completed, failed]      # optional; the first one is the success outcome
      initial_mode: stand_prep           # optional; used when no mode is an initial condition
      control_modes:                     # optional; mode -> modes it can change to
        stand_prep: [stand]              #   (self-loops are implied)
        stand: [manipulate, step, walk]
      actions:                           # action -> preconditions (actions or control modes)
        look_down: [stand]
        object_template: []
      sensors: [obj_detected]            # optional; environment propositions that are not outcomes

Every problem is reported by an ``AbstractionConfigError`` whose ``item`` names the offending
mode, action, outcome, sensor or key. Mappings keep the order of the file, which is the
order in which propositions appear in compiled specifications.
"""

from __future__ import annotations

import re
from typing import Mapping
from dataclasses import dataclass, field

from respec.vocabulary.errors import ErrorCode
from respec.vocabulary.naming import COMPLETED, DEFAULT_SM_OUTCOMES, FAILED, activation, memory, outcome_proposition
from respec.robot.files import SystemConfigError

_NAME = re.compile(r'^[A-Za-z][A-Za-z0-9_]*$')
DEFAULT_OUTCOMES = (COMPLETED, FAILED)
_SECTION_KEYS = ('outcomes', 'initial_mode', 'control_modes', 'actions', 'sensors')
# An outcome starting with 'a' or 'm' would name the same proposition as an activation
# (<p>_a) or a goal memory (<g>_m).
_RESERVED_OUTCOME_LETTERS = ('a', 'm')


class AbstractionConfigError(SystemConfigError):
    """The ``abstraction:`` section is invalid; ``item`` names the offending entry."""

    code = ErrorCode.ABSTRACTION_CONFIG_INVALID


@dataclass(frozen=True)
class RobotAbstraction:
    """A validated discrete abstraction (all mappings in file order, self-loops not listed)."""

    system: str
    control_modes: dict[str, tuple[str, ...]] = field(default_factory=dict)
    actions: dict[str, tuple[str, ...]] = field(default_factory=dict)
    outcomes: tuple[str, ...] = DEFAULT_OUTCOMES
    sensors: tuple[str, ...] = ()
    initial_mode: str | None = None

    # The robot interface (respec.robot.description.RobotDescription).
    reads_robot_state_by_default = True   # the robot reports its control mode and completed actions
    orders_goals = True

    @property
    def default_initial_conditions(self) -> list[str]:
        """The ``initial_mode``, when the section names one."""
        return [self.initial_mode] if self.initial_mode else []

    @property
    def success_outcome(self) -> str:
        """The outcome that means completion (the first one listed)."""
        return self.outcomes[0]

    @property
    def failure_outcomes(self) -> tuple[str, ...]:
        """Every outcome other than completion counts as a failure."""
        return self.outcomes[1:]

    def kind_of(self, item: str) -> str | None:
        """'action', 'control_mode' or None if the abstraction does not define ``item``."""
        if item in self.actions:
            return 'action'
        if item in self.control_modes:
            return 'control_mode'
        return None

    def items(self) -> list[str]:
        """All control modes, then all actions, in file order."""
        return [*self.control_modes, *self.actions]

    @property
    def capabilities(self) -> tuple[str, ...]:
        """What a robot can be asked to do: every control mode, then every action."""
        return tuple(self.items())

    def is_mode(self, name: str) -> bool:
        return name in self.control_modes

    def is_action(self, name: str) -> bool:
        return name in self.actions

    def is_capability(self, name: str) -> bool:
        return self.is_mode(name) or self.is_action(name)

    def transition_allowed(self, current: str, target: str) -> bool:
        """Self-loops are implied; otherwise the target must be listed under the current mode."""
        return target == current or target in self.control_modes.get(current, ())

    def dependents(self, action: str) -> set[str]:
        """Actions whose preconditions include ``action``, directly or transitively."""
        found: set[str] = set()
        frontier = [action]
        while frontier:
            needed = frontier.pop()
            for name, preconditions in self.actions.items():
                if needed in preconditions and name not in found:
                    found.add(name)
                    frontier.append(name)
        found.discard(action)
        return found


def abstraction_from_document(document: Mapping[str, object], system: str) -> RobotAbstraction:
    """The validated ``abstraction:`` section of a whole (parsed) system file."""
    if 'abstraction' not in document:
        raise AbstractionConfigError(f'{system}.yaml has no abstraction: section', item='abstraction')
    return abstraction_from_dict(document['abstraction'], system)


def abstraction_from_dict(section: object, system: str = '<dict>') -> RobotAbstraction:
    """Validate an ``abstraction:`` mapping and build the RobotAbstraction it describes."""
    where = f'{system}.yaml abstraction'
    if not isinstance(section, dict):
        raise AbstractionConfigError(f'{where}: expected a mapping, got {_type(section)}',
                                     item='abstraction')
    for key in section:
        if key not in _SECTION_KEYS:
            raise AbstractionConfigError(
                f'{where}: unknown key {key!r} (expected one of {", ".join(_SECTION_KEYS)})', item=str(key))

    outcomes = _outcomes(section.get('outcomes', list(DEFAULT_OUTCOMES)), where)
    control_modes = _name_to_names(section.get('control_modes') or {}, 'control_modes', where)
    # Self-loops are implied, so a mode listing itself adds nothing.
    control_modes = {mode: tuple(m for m in adjacent if m != mode) for mode, adjacent in control_modes.items()}
    actions = _name_to_names(section.get('actions') or {}, 'actions', where)
    sensors = _names(section.get('sensors') or [], 'sensors', where)

    for mode, adjacent in control_modes.items():
        for other in adjacent:
            if other not in control_modes:
                raise AbstractionConfigError(
                    f'{where}: control mode {mode!r} can change to {other!r}, '
                    f'which is not a control mode', item=other)
    for action in actions:
        if action in control_modes:
            raise AbstractionConfigError(
                f'{where}: {action!r} is both an action and a control mode', item=action)
    for action, preconditions in actions.items():
        for precondition in preconditions:
            if precondition not in actions and precondition not in control_modes:
                raise AbstractionConfigError(
                    f'{where}: action {action!r} has unknown precondition {precondition!r} '
                    f'(not an action or control mode)', item=precondition)
    _reject_precondition_cycles(actions, where)

    initial_mode = section.get('initial_mode')
    if initial_mode is not None and initial_mode not in control_modes:
        raise AbstractionConfigError(
            f'{where}: initial_mode {initial_mode!r} is not a control mode', item=str(initial_mode))

    abstraction = RobotAbstraction(system, control_modes, actions, outcomes, sensors, initial_mode)
    _reject_proposition_clashes(abstraction, where)
    return abstraction


def _outcomes(value: object, where: str) -> tuple[str, ...]:
    outcomes = _names(value, 'outcomes', where)
    if not outcomes:
        raise AbstractionConfigError(f'{where}: outcomes must list at least one outcome', item='outcomes')
    first_letters: dict[str, str] = {}
    for outcome in outcomes:
        letter = outcome[0]
        if letter in _RESERVED_OUTCOME_LETTERS:
            raise AbstractionConfigError(
                f'{where}: outcome {outcome!r} starts with {letter!r}, which is reserved for '
                f'activation (_a) and memory (_m) propositions', item=outcome)
        if letter in first_letters:
            raise AbstractionConfigError(
                f'{where}: outcomes {first_letters[letter]!r} and {outcome!r} have the same '
                f'first letter, so their propositions would be equal', item=outcome)
        first_letters[letter] = outcome
    return outcomes


def _names(value: object, key: str, where: str) -> tuple[str, ...]:
    if not isinstance(value, list):
        raise AbstractionConfigError(f'{where}: {key} must be a list, got {_type(value)}', item=key)
    seen: list[str] = []
    for name in value:
        if not isinstance(name, str) or not _NAME.match(name):
            raise AbstractionConfigError(
                f'{where}: {key} entry {name!r} is not a valid name (letters, digits, _)', item=str(name))
        if name in seen:
            raise AbstractionConfigError(f'{where}: {key} lists {name!r} twice', item=name)
        seen.append(name)
    return tuple(seen)


def _name_to_names(value: object, key: str, where: str) -> dict[str, tuple[str, ...]]:
    if not isinstance(value, dict):
        raise AbstractionConfigError(
            f'{where}: {key} must be a mapping of name -> list of names, got {_type(value)}', item=key)
    result = {}
    for name, targets in value.items():
        if not isinstance(name, str) or not _NAME.match(name):
            raise AbstractionConfigError(f'{where}: {key} has invalid name {name!r}', item=str(name))
        result[name] = _names(targets or [], f'{key}.{name}', where)
    return result


def _reject_precondition_cycles(actions: dict[str, tuple[str, ...]], where: str) -> None:
    """Depth-first search; a precondition on the current path closes a cycle."""
    finished: set[str] = set()

    def visit(action: str, path: list[str]) -> None:
        if action in path:
            cycle = path[path.index(action):] + [action]
            raise AbstractionConfigError(
                f'{where}: preconditions form a cycle: {" -> ".join(cycle)}', item=action)
        if action in finished or action not in actions:
            return
        for precondition in actions[action]:
            visit(precondition, path + [action])
        finished.add(action)

    for action in actions:
        visit(action, [])


def _reject_proposition_clashes(abstraction: RobotAbstraction, where: str) -> None:
    """Two items must never generate the same proposition name (e.g. sensor 'x_c' vs action 'x')."""
    owners: dict[str, str] = {}

    def claim(proposition: str, owner: str) -> None:
        if proposition in owners and owners[proposition] != owner:
            raise AbstractionConfigError(
                f'{where}: proposition {proposition!r} would belong to both {owners[proposition]} '
                f'and {owner}', item=proposition)
        owners[proposition] = owner

    for outcome in DEFAULT_SM_OUTCOMES:
        claim(outcome, 'the state-machine outcomes')
    for item in abstraction.items():
        kind = abstraction.kind_of(item)
        assert kind is not None  # one of its own items
        owner = f'{kind.replace("_", " ")} {item!r}'
        claim(activation(item), owner)
        claim(memory(item), owner)
        for outcome in abstraction.outcomes:
            claim(outcome_proposition(item, outcome), owner)
    for sensor in abstraction.sensors:
        claim(sensor, f'sensor {sensor!r}')


def _type(value: object) -> str:
    return type(value).__name__
