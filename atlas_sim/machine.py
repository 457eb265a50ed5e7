"""A StateInstantiation list as the machine the executive runs: its tree, validated (ROS-free)."""

from __future__ import annotations

from dataclasses import dataclass, field

from atlas_sim.trace_check import Trace
from respec.errors import CodedError, ErrorCode
from sm_generation.generator import DECISION_CLASS, NOTHING_CLASS
from sm_generation.instantiation import StateInstantiation

ROOT_PATH = '/'
STATEMACHINE = StateInstantiation.CLASS_STATEMACHINE
CONCURRENCY = StateInstantiation.CLASS_CONCURRENCY
BEHAVIOR = StateInstantiation.CLASS_BEHAVIOR
OUTCOME = StateInstantiation.CLASS_OUTCOME
# The generator's helper states (flexbe_states) and how they return.
LOG_STATE = NOTHING_CLASS
DECISION_STATE = DECISION_CLASS



class ExecutionError(CodedError):
    """The run could not go on; ``item`` names the offending state, ``trace`` holds what ran."""

    code = ErrorCode.BEHAVIOR_SYNTHESIS_FAILED

    def __init__(self, message: str, item: str, trace: Trace | None = None):
        super().__init__(message, item)
        self.trace = trace


class MachineInvalidError(ExecutionError):
    """The StateInstantiation list is not a machine this executive can run."""

    code = ErrorCode.INVALID_REQUEST


class UndeclaredOutcomeError(ExecutionError):
    """A state returned an outcome that it does not declare (so it has no transition)."""

    code = ErrorCode.AUTOMATON_INVALID


@dataclass
class StateNode:
    """One entry of the StateInstantiation list, as the executive needs it."""

    path: str
    state_class: str
    behavior_class: str = ''
    parameter_values: tuple[str, ...] = ()
    outcomes: list[str] = field(default_factory=list)
    transitions: list[str] = field(default_factory=list)
    initial_state_name: str = ''
    conditions: list[tuple[str, list[tuple[str, str]]]] = field(default_factory=list)
    children: list[StateNode] = field(default_factory=list)

    @property
    def name(self) -> str:
        return self.path.rstrip('/').rsplit('/', 1)[-1]

    def next_target(self, outcome: str) -> str:
        if outcome not in self.outcomes:
            raise UndeclaredOutcomeError(f'state {self.path!r} returned {outcome!r}, which is not one of its '
                                         f'outcomes {self.outcomes}', item=self.path)
        return self.transitions[self.outcomes.index(outcome)]


def _as_dict(entry) -> dict:
    if isinstance(entry, dict):
        return entry
    if hasattr(entry, 'to_dict'):
        return entry.to_dict()
    raise MachineInvalidError(f'not a StateInstantiation: {entry!r}', item=repr(entry)[:60])


def load_machine(states) -> StateNode:
    """The root node with its top-level states (and their children), validated."""
    entries = [_as_dict(e) for e in states]
    nodes: dict[str, StateNode] = {}
    for entry in entries:
        path = str(entry.get('state_path', ''))
        if not path.startswith('/'):
            raise MachineInvalidError(f'state path {path!r} does not start with "/"', item=path)
        if path in nodes:
            raise MachineInvalidError(f'two entries have the state path {path!r}', item=path)
        outcomes, transitions = list(entry.get('outcomes', [])), list(entry.get('transitions', []))
        if len(outcomes) != len(transitions) and entry.get('state_class') != OUTCOME:
            raise MachineInvalidError(f'state {path!r} has {len(outcomes)} outcomes but '
                                      f'{len(transitions)} transitions', item=path)
        conditions = []
        for outcome, condition in zip(entry.get('cond_outcome', []), entry.get('cond_transition', [])):
            condition = condition if isinstance(condition, dict) else condition.to_dict()
            conditions.append((str(outcome), list(zip(condition['state_name'], condition['state_outcome']))))
        nodes[path] = StateNode(
            path=path, state_class=str(entry.get('state_class', '')),
            behavior_class=str(entry.get('behavior_class', '')),
            parameter_values=tuple(str(v) for v in entry.get('parameter_values', [])),
            outcomes=outcomes, transitions=transitions,
            initial_state_name=str(entry.get('initial_state_name', '')), conditions=conditions)
    root = nodes.get(ROOT_PATH)
    if root is None or root.state_class != STATEMACHINE:
        raise MachineInvalidError('no root entry (state_path "/", class :STATEMACHINE)', item=ROOT_PATH)
    for path, node in nodes.items():
        if path == ROOT_PATH or node.state_class == OUTCOME:
            continue
        parent = nodes.get(path.rsplit('/', 1)[0] or ROOT_PATH)
        if parent is None:
            raise MachineInvalidError(f'state {path!r} has no parent entry', item=path)
        if parent is not root and parent.state_class != CONCURRENCY:
            raise MachineInvalidError(f'state {path!r} is nested in {parent.path!r} ({parent.state_class}); '
                                      'only concurrency containers may hold states here', item=path)
        parent.children.append(node)
    _validate_targets(root)
    return root


def _validate_targets(root: StateNode) -> None:
    names = {child.name for child in root.children}
    if root.initial_state_name not in names:
        raise MachineInvalidError(f'initial state {root.initial_state_name!r} is not a state of the machine',
                                  item=root.initial_state_name)
    for state in root.children:
        for target in state.transitions:
            if target not in names and target not in root.outcomes:
                raise MachineInvalidError(f'state {state.path!r} leads to {target!r}, which is neither a state '
                                          'nor an outcome of the machine', item=state.path)
        if state.state_class == CONCURRENCY:
            if not state.children:
                raise MachineInvalidError(f'container {state.path!r} has no states', item=state.path)
            inner = {child.name for child in state.children}
            for outcome, condition in state.conditions:
                if outcome not in state.outcomes:
                    raise MachineInvalidError(f'container {state.path!r} has condition outcome {outcome!r} '
                                              'that it does not declare', item=state.path)
                for name, _ in condition:
                    if name not in inner:
                        raise MachineInvalidError(f'a condition of {state.path!r} names {name!r}, which is '
                                                  'not one of its states', item=state.path)
