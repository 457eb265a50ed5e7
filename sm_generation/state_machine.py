"""The synthesized state machine as one tree, the form in which it travels (ROS-free).

FlexBE sends and stores a behavior as a flat list of StateInstantiations whose paths place
them (``/`` the machine, ``/name`` its states, ``/container/name`` a container's states);
its engine runs a tree (flexbe_core's ``StateMachine``: a container is a state that owns
its states). The generator builds this tree; the list is the wire format only, and this
module is the one place a list becomes the tree again:

    machine = StateMachine.from_instantiations(states)   # validated; SMGenerationError
    machine.to_instantiations() == states                # for every list the generator makes
    machine.to_dict()                                    # the tree as JSON for the GUI

Every node is a :class:`State` (a StateInstantiation placed in the tree); the root and the
concurrency containers are :class:`StateMachine` nodes owning their ``states`` and the
``:OUTCOME`` entries placing their outcomes. Validation, FlexBE code, the drawing, the
observable runs, the summary and the executive all read this tree.

Two kinds of problems are told apart. A problem that leaves no runnable tree (field types,
paths, parents, a transition of the machine to nowhere, initial states, concurrency
conditions) makes ``from_instantiations`` raise an ``SMGenerationError`` naming the offending
path. A problem only the FlexBE editor minds (autonomy levels, parameter and userdata pairs,
unreachable states, a machine without outcomes, an inner state's decorative transition) is
listed by :func:`validate_state_machine` alongside the others.
"""

from __future__ import annotations

import copy
from collections import deque
from dataclasses import dataclass
from typing import Any, Iterator, Mapping, Sequence

from sm_generation.errors import SMGenerationError
from sm_generation.instantiation import FIELD_NAMES, OutcomeCondition, StateInstantiation

ROOT_PATH = '/'
CONTAINER_CLASSES = (StateInstantiation.CLASS_STATEMACHINE, StateInstantiation.CLASS_CONCURRENCY,
                     StateInstantiation.CLASS_PRIORITY)
_STRING_LISTS = ('input_keys', 'output_keys', 'cond_outcome', 'parameter_names', 'parameter_values',
                 'outcomes', 'transitions', 'userdata_keys', 'userdata_remapping')


class State(StateInstantiation):
    """One StateInstantiation in its place in the tree (flexbe_core's ``State``).

    It reads as its StateInstantiation (the tree copies the entries it is built from, so
    treat the fields as read-only). A plain state owns no states.
    """

    states: tuple[State, ...] = ()
    outcome_entries: tuple[State, ...] = ()

    @property
    def children(self) -> tuple[State, ...]:
        """The nodes below this one in list order: its states, then its ``:OUTCOME`` entries."""
        return self.states + self.outcome_entries

    @property
    def is_outcome(self) -> bool:
        return self.state_class == StateInstantiation.CLASS_OUTCOME

    def next_target(self, outcome: str) -> str | None:
        """The state or container outcome that ``outcome`` leads to (None if not declared)."""
        if outcome not in self.outcomes:
            return None
        return self.transitions[self.outcomes.index(outcome)]

    def walk(self) -> Iterator[State]:
        """This node and every node below it, pre-order (the generator's list order)."""
        yield self
        for child in self.children:
            yield from child.walk()

    def to_instantiation(self) -> StateInstantiation:
        """A plain copy of this node's entry."""
        return StateInstantiation(**{name: copy.deepcopy(getattr(self, name)) for name in FIELD_NAMES})

    def to_dict(self) -> dict[str, Any]:
        """The entry's 16 fields, its ``name`` ('/' for the root) and its ``children`` (the GUI's tree)."""
        return {**super().to_dict(), 'name': self.name or ROOT_PATH,
                'children': [child.to_dict() for child in self.children]}


class StateMachine(State):
    """A container (flexbe_core's ``StateMachine``): the root or a concurrency container,
    owning its ``states`` and the ``:OUTCOME`` entries that place its outcomes."""

    @classmethod
    def from_instantiations(cls, states: Sequence[StateInstantiation | Mapping[str, Any]]) -> StateMachine:
        """The tree of ``states`` (StateInstantiations or their dicts), validated.

        Raises :class:`SMGenerationError` naming the offending path (``item``) for the
        first problem that leaves no runnable tree; problems only the editor minds are left
        to :func:`validate_state_machine`.
        """
        if not states:
            raise SMGenerationError('the state machine is empty', ROOT_PATH)
        nodes = []
        for index, entry in enumerate(states):
            node = _node(entry, index)
            problems = _field_problems(node)
            if problems:
                label = _label(node, index)
                raise SMGenerationError(f'{label}: {problems[0]}', label)
            nodes.append(node)
        root, found = _build(nodes)
        fatal = next((p for p in found if p.fatal), None)
        if fatal is not None:
            raise SMGenerationError(fatal.message, fatal.item)
        assert root is not None  # a machine without a root container has a fatal problem
        return root

    # --- the list and the GUI's JSON ------------------------------------------------------------

    def to_instantiations(self) -> list[StateInstantiation]:
        """The list back: every node pre-order (the root, each state followed by its inner
        states, then the ``:OUTCOME`` entries), as plain StateInstantiation copies."""
        return [node.to_instantiation() for node in self.walk()]

    # --- what the consumers read ------------------------------------------------------------------

    def descendants(self) -> list[State]:
        """Every node below this one except ``:OUTCOME`` entries, pre-order."""
        return [node for node in self.walk() if node is not self and not node.is_outcome]

    def containers(self) -> list[StateMachine]:
        """The containers inside this one, pre-order."""
        return [node for node in self.descendants() if isinstance(node, StateMachine)]

    def primitives(self) -> list[State]:
        """The states inside that are FlexBE state classes (neither containers nor behaviors)."""
        return [node for node in self.descendants()
                if node.state_class not in (*CONTAINER_CLASSES, StateInstantiation.CLASS_BEHAVIOR)]

    def behaviors(self) -> list[State]:
        """The ``:BEHAVIOR`` states inside, pre-order."""
        return [node for node in self.descendants() if node.state_class == StateInstantiation.CLASS_BEHAVIOR]

    def remapped_keys(self) -> list[str]:
        """Every userdata key some state inside remaps to, sorted (the root machine holds them all)."""
        return sorted({key for node in self.descendants() for key in node.userdata_remapping})

    def state(self, name: str) -> State | None:
        """The state of this container called ``name``."""
        return next((s for s in self.states if s.name == name), None)

    def initial_state(self) -> State | None:
        return self.state(self.initial_state_name)

    def ordered_states(self) -> list[State]:
        """This container's states as the FlexBE editor adds them: the initial state first, then by name."""
        by_name = sorted(self.states, key=lambda s: s.name)
        return ([s for s in by_name if s.name == self.initial_state_name]
                + [s for s in by_name if s.name != self.initial_state_name])

    @property
    def conditions(self) -> list[tuple[str, list[tuple[str, str]]]]:
        """A concurrency container's conditions in FlexBE's order: (its outcome, [(inner state, outcome)])."""
        return [(outcome, list(zip(condition.state_name, condition.state_outcome)))
                for outcome, condition in zip(self.cond_outcome, self.cond_transition)]

    def reachable_names(self) -> set[str]:
        """Names of the states reachable from the initial state along transitions."""
        by_name = {s.name: s for s in self.states}
        if self.initial_state_name not in by_name:
            return set()
        seen, queue = {self.initial_state_name}, deque([self.initial_state_name])
        while queue:
            for target in by_name[queue.popleft()].transitions:
                if target in by_name and target not in seen:
                    seen.add(target)
                    queue.append(target)
        return seen


def validate_state_machine(states: list[StateInstantiation]) -> list[str]:
    """Problems found in ``states`` (empty when consistent), each naming the entry.

    Checks field types, the path hierarchy (one root ``/`` first, parents are the root or
    concurrency containers, unique paths), equal lengths of outcomes/transitions/autonomy,
    parameters and userdata, that every transition names a sibling state or an outcome of
    the container, that initial states exist and every state is reachable from them, and
    that concurrency conditions name inner states and outcomes those states have: what
    ``StateMachine.from_instantiations`` refuses and what only the FlexBE editor minds.
    """
    if not states:
        return ['the state machine is empty']
    problems: list[str] = []
    for index, state in enumerate(states):
        if not isinstance(state, StateInstantiation):
            problems.append(f'{_label(state, index)}: not a StateInstantiation: {type(state).__name__}')
        else:
            problems.extend(f'{_label(state, index)}: {p}' for p in _field_problems(state))
    if problems:
        return problems  # structure checks below assume well-typed fields
    _, found = _build([_node(state, index) for index, state in enumerate(states)])
    return [problem.message for problem in found]


# --- building and checking ----------------------------------------------------------------------

@dataclass(frozen=True)
class _Problem:
    message: str
    item: str
    fatal: bool  # no runnable tree (from_instantiations raises); else only the editor minds


def _node(entry: object, index: int) -> State:
    """A fresh node (StateMachine for container classes) copied from ``entry`` or its dict."""
    if isinstance(entry, dict):
        try:
            data = StateInstantiation.from_dict(entry)
        except (TypeError, ValueError) as error:
            path = entry.get('state_path')
            label = path if isinstance(path, str) and path else f'entry #{index}'
            raise SMGenerationError(f'{label}: {error}', label) from error
    elif isinstance(entry, StateInstantiation):
        data = entry
    else:
        label = f'entry #{index}'
        raise SMGenerationError(f'{label}: not a StateInstantiation: {type(entry).__name__}', label)
    node_class = StateMachine if data.state_class in CONTAINER_CLASSES else State
    return node_class(**{name: copy.deepcopy(getattr(data, name)) for name in FIELD_NAMES})


def _label(state: object, index: int) -> str:
    """The entry's path, or its place in the list when it has none."""
    path = getattr(state, 'state_path', None)
    return path if isinstance(path, str) and path else f'entry #{index}'


def _build(nodes: list[State]) -> tuple[StateMachine | None, list[_Problem]]:
    """Attach every node to its container; the root and every problem found, in list order."""
    problems = []
    by_path: dict[str, State] = {}
    for node in nodes:
        if node.state_path in by_path:
            problems.append(_Problem(f'{node.state_path}: duplicate state_path', node.state_path, True))
        by_path[node.state_path] = node
    if nodes[0].state_path != ROOT_PATH or nodes[0].state_class != StateInstantiation.CLASS_STATEMACHINE:
        problems.append(_Problem('the first entry must be the root container with state_path "/" '
                                 f'and class {StateInstantiation.CLASS_STATEMACHINE}', ROOT_PATH, True))
    containers = {path: node for path, node in by_path.items() if isinstance(node, StateMachine)}
    members: dict[str, list[State]] = {path: [] for path in containers}
    for node in nodes:
        path = node.state_path
        if path == ROOT_PATH:
            continue
        if not path.startswith('/') or path.endswith('/') or not node.name:
            problems.append(_Problem(f'{path}: invalid state_path', path, True))
            continue
        if node.parent_path not in containers:
            problems.append(_Problem(f'{path}: parent {node.parent_path!r} is not a container', path, True))
            continue
        if node.state_class in (StateInstantiation.CLASS_STATEMACHINE, StateInstantiation.CLASS_PRIORITY):
            problems.append(_Problem(f'{path}: {node.state_class} containers inside the machine are not '
                                     f'supported (only {StateInstantiation.CLASS_CONCURRENCY})', path, True))
        members[node.parent_path].append(node)
    for path, container in containers.items():
        container.states = tuple(m for m in members[path] if not m.is_outcome)
        container.outcome_entries = tuple(m for m in members[path] if m.is_outcome)
    for container in containers.values():
        problems.extend(_container_problems(container))
    for node in nodes:
        problems.extend(_entry_problems(node))
    root = by_path.get(ROOT_PATH)
    return (root if isinstance(root, StateMachine) else None), problems


def _field_problems(state: StateInstantiation) -> list[str]:
    problems = []
    for name in ('state_path', 'state_class', 'initial_state_name', 'behavior_class'):
        if not isinstance(getattr(state, name), str):
            problems.append(f'{name} must be a string')
    for name in _STRING_LISTS:
        value = getattr(state, name)
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            problems.append(f'{name} must be a list of strings')
    if not isinstance(state.cond_transition, list) or not all(
            isinstance(c, OutcomeCondition) and isinstance(c.state_name, list) and isinstance(c.state_outcome, list)
            for c in state.cond_transition):
        problems.append('cond_transition must be a list of OutcomeCondition')
    if (not isinstance(state.position, list) or len(state.position) != 2
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in state.position)):
        problems.append('position must be two numbers')
    if not isinstance(state.autonomy, list) or not all(
            isinstance(v, int) and not isinstance(v, bool) and -128 <= v <= 127 for v in state.autonomy):
        problems.append('autonomy must be a list of int8')
    if len(FIELD_NAMES) != 16:  # guards the dataclass against drifting from the message
        problems.append('StateInstantiation must have the 16 fields of the message')
    return problems


def _entry_problems(state: State) -> list[_Problem]:
    path = state.state_path

    def problem(text: str, fatal: bool = False) -> _Problem:
        return _Problem(f'{path}: {text}', path, fatal)

    problems = []
    if not state.state_class:
        problems.append(problem('empty state_class'))
    if state.is_outcome:
        if state.outcomes or state.transitions:
            problems.append(problem(':OUTCOME entries have no outcomes or transitions'))
        return problems
    if len(state.outcomes) != len(state.transitions):
        problems.append(problem(f'{len(state.outcomes)} outcomes but {len(state.transitions)} transitions', True))
    if len(state.autonomy) != len(state.outcomes):
        problems.append(problem(f'{len(state.outcomes)} outcomes but {len(state.autonomy)} autonomy levels'))
    if len(set(state.outcomes)) != len(state.outcomes):
        problems.append(problem(f'an outcome is listed twice: {state.outcomes}'))
    if len(state.parameter_names) != len(state.parameter_values):
        problems.append(problem('parameter_names and parameter_values differ in length'))
    if len(state.userdata_keys) != len(state.userdata_remapping):
        problems.append(problem('userdata_keys and userdata_remapping differ in length'))
    if state.state_class == StateInstantiation.CLASS_BEHAVIOR and not state.behavior_class:
        problems.append(problem(':BEHAVIOR without behavior_class'))
    if isinstance(state, StateMachine) and not state.outcomes:
        problems.append(problem('a container needs outcomes'))
    return problems


def _container_problems(container: StateMachine) -> list[_Problem]:
    path = container.state_path
    states = {s.name: s for s in container.states}
    problems = [_Problem(f'{o.state_path}: not an outcome of {path}', o.state_path, False)
                for o in container.outcome_entries if o.name not in container.outcomes]
    problems.extend(_Problem(f'{path}: state {name!r} has the name of a container outcome', path, False)
                    for name in states if name in container.outcomes)
    if not states:
        return problems + [_Problem(f'{path}: container without states', path, True)]
    initial = container.initial_state_name
    if initial and initial not in states:
        problems.append(_Problem(f'{path}: initial_state_name {initial!r} is not one of its states', initial, True))
    concurrent = container.state_class == StateInstantiation.CLASS_CONCURRENCY
    if not concurrent and not initial:
        problems.append(_Problem(f'{path}: state machine without initial_state_name', path, True))
    allowed = set(container.outcomes) if concurrent else set(container.outcomes) | set(states)
    for member in states.values():  # a concurrency container's conditions, not its states' transitions, run
        problems.extend(_Problem(f'{member.state_path}: transition {t!r} names neither a sibling state nor an '
                                 f'outcome of {path}', member.state_path, not concurrent)
                        for t in member.transitions if t not in allowed)
    if concurrent:
        problems.extend(_condition_problems(container, states))
    elif initial in states:
        unreachable = set(states) - container.reachable_names()
        problems.extend(_Problem(f'{states[name].state_path}: unreachable from {initial!r}',
                                 states[name].state_path, False) for name in sorted(unreachable))
    return problems


def _condition_problems(container: StateMachine, states: dict[str, State]) -> list[_Problem]:
    path = container.state_path

    def problem(text: str, fatal: bool = True) -> _Problem:
        return _Problem(f'{path}: {text}', path, fatal)

    if len(container.cond_outcome) != len(container.cond_transition):
        return [problem('cond_outcome and cond_transition differ in length')]
    problems = []
    for outcome, condition in zip(container.cond_outcome, container.cond_transition):
        if outcome not in container.outcomes:
            problems.append(problem(f'condition outcome {outcome!r} is not a container outcome'))
        if not condition.state_name or len(condition.state_name) != len(condition.state_outcome):
            problems.append(problem(f'condition for {outcome!r} is empty or uneven'))
            continue
        for name, inner_outcome in zip(condition.state_name, condition.state_outcome):
            if name not in states:
                problems.append(problem(f'condition for {outcome!r} names unknown inner state {name!r}'))
            elif inner_outcome not in states[name].outcomes:
                problems.append(problem(f'condition for {outcome!r}: {name!r} has no outcome {inner_outcome!r}'))
    problems.extend(problem(f'container outcome {o!r} has no condition', fatal=False)
                    for o in container.outcomes if o not in container.cond_outcome)
    return problems
