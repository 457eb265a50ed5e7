"""FlexBE's StateInstantiation and OutcomeCondition as plain dataclasses (no ROS).

The fields are exactly those of ``flexbe_msgs/StateInstantiation`` and
``flexbe_msgs/OutcomeCondition`` of ROS 2 FlexBE 4.x (and of this project's
``synthesis_msgs``), so a ROS node can copy them field by field.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any, Iterable, Mapping

from respec.vocabulary.naming import (BEHAVIOR_CLASS, CONCURRENCY_CLASS, OUTCOME_CLASS, PRIORITY_CLASS,
                                      STATEMACHINE_CLASS)


@dataclass
class OutcomeCondition:
    """A conjunction: holds when every ``state_name[i]`` has returned ``state_outcome[i]``."""

    state_name: list[str] = field(default_factory=list)
    state_outcome: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {'state_name': list(self.state_name), 'state_outcome': list(self.state_outcome)}

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> OutcomeCondition:
        return cls(state_name=[str(n) for n in data.get('state_name', [])],
                   state_outcome=[str(o) for o in data.get('state_outcome', [])])


@dataclass
class StateInstantiation:
    """One entry of the list from which the FlexBE editor builds a behavior.

    ``state_path`` places the entry: ``/`` is the synthesized state machine itself,
    ``/name`` a state in it, ``/container/name`` a state inside a container.
    """

    CLASS_STATEMACHINE = STATEMACHINE_CLASS
    CLASS_CONCURRENCY = CONCURRENCY_CLASS
    CLASS_PRIORITY = PRIORITY_CLASS
    CLASS_BEHAVIOR = BEHAVIOR_CLASS
    CLASS_OUTCOME = OUTCOME_CLASS

    state_path: str = ''
    state_class: str = ''
    initial_state_name: str = ''
    input_keys: list[str] = field(default_factory=list)
    output_keys: list[str] = field(default_factory=list)
    cond_outcome: list[str] = field(default_factory=list)
    cond_transition: list[OutcomeCondition] = field(default_factory=list)
    behavior_class: str = ''
    parameter_names: list[str] = field(default_factory=list)
    parameter_values: list[str] = field(default_factory=list)
    position: list[float] = field(default_factory=lambda: [0.0, 0.0])
    outcomes: list[str] = field(default_factory=list)
    transitions: list[str] = field(default_factory=list)
    autonomy: list[int] = field(default_factory=list)
    userdata_keys: list[str] = field(default_factory=list)
    userdata_remapping: list[str] = field(default_factory=list)

    @property
    def name(self) -> str:
        """The last segment of the path ('' for the root state machine)."""
        return self.state_path.rstrip('/').rsplit('/', 1)[-1] if self.state_path != '/' else ''

    @property
    def parent_path(self) -> str:
        """Path of the container holding this entry ('' for the root itself)."""
        if self.state_path == '/':
            return ''
        parent = self.state_path.rsplit('/', 1)[0]
        return parent or '/'

    def to_dict(self) -> dict[str, Any]:
        """All 16 fields, in message order; ``cond_transition`` as a list of dicts."""
        result = {}
        for f in fields(self):
            value = getattr(self, f.name)
            if f.name == 'cond_transition':
                value = [c.to_dict() for c in value]
            elif f.name == 'position':
                value = [float(v) for v in value]
            elif f.name == 'autonomy':
                value = [int(v) for v in value]
            elif isinstance(value, list):
                value = list(value)
            result[f.name] = value
        return result

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> StateInstantiation:
        """Inverse of ``to_dict``; unknown keys are rejected so typos do not pass silently."""
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise ValueError(f'unknown StateInstantiation field {unknown[0]!r}')
        kwargs = dict(data)
        if 'cond_transition' in kwargs:
            kwargs['cond_transition'] = [
                c if isinstance(c, OutcomeCondition) else OutcomeCondition.from_dict(c)
                for c in kwargs['cond_transition']]
        if 'position' in kwargs:
            kwargs['position'] = [float(v) for v in kwargs['position']]
        if 'autonomy' in kwargs:
            kwargs['autonomy'] = [int(v) for v in kwargs['autonomy']]
        return cls(**kwargs)


FIELD_NAMES = tuple(f.name for f in fields(StateInstantiation))

# The helper states the generator adds where the automaton itself has no state (flexbe_states'
# classes): an operator decision between several starts, and a state that only logs that there
# is nothing to do. The FlexBE code generation and the executive recognise them by class.
DECISION_CLASS = 'OperatorDecisionState'
NOTHING_CLASS = 'LogState'
HELPER_STATE_CLASSES = (DECISION_CLASS, NOTHING_CLASS)


def count_states(entries: Iterable[object]) -> int:
    """How many states a machine has: every entry but the machine itself ('/') and its outcomes.

    States inside containers count, and so do the containers. ``entries`` are
    StateInstantiations, their dicts or messages. Every report of a machine's size (progress,
    result summary, command line) uses this one count.
    """
    def field(entry: object, name: str) -> object:
        return entry[name] if isinstance(entry, dict) else getattr(entry, name)

    return sum(1 for entry in entries
               if field(entry, 'state_path') != '/' and field(entry, 'state_class') != StateInstantiation.CLASS_OUTCOME)
