"""Consistency checks of a StateInstantiation list (what the FlexBE editor relies on)."""

from __future__ import annotations

from collections import deque

from sm_generation.instantiation import FIELD_NAMES, OutcomeCondition, StateInstantiation

CONTAINER_CLASSES = (StateInstantiation.CLASS_STATEMACHINE, StateInstantiation.CLASS_CONCURRENCY,
                     StateInstantiation.CLASS_PRIORITY)
_STRING_LISTS = ('input_keys', 'output_keys', 'cond_outcome', 'parameter_names', 'parameter_values',
                 'outcomes', 'transitions', 'userdata_keys', 'userdata_remapping')


def validate_state_machine(states: list[StateInstantiation]) -> list[str]:
    """Problems found in ``states`` (empty when consistent), each naming the entry.

    Checks field types, the path hierarchy (one root ``/`` first, parents are containers,
    unique paths), equal lengths of outcomes/transitions/autonomy, parameters and userdata,
    that every transition names a sibling state or an outcome of the container, that
    initial states exist and every state is reachable from them, and that concurrency
    conditions name inner states and outcomes those states have.
    """
    if not states:
        return ['the state machine is empty']
    problems = []
    for index, state in enumerate(states):
        problems.extend(f'{_label(state, index)}: {p}' for p in _field_problems(state))
    if problems:
        return problems  # structure checks below assume well-typed fields

    by_path: dict[str, StateInstantiation] = {}
    for state in states:
        if state.state_path in by_path:
            problems.append(f'{state.state_path}: duplicate state_path')
        by_path[state.state_path] = state
    if states[0].state_path != '/' or states[0].state_class not in CONTAINER_CLASSES:
        problems.append('the first entry must be the root container with state_path "/"')
    children: dict[str, list[StateInstantiation]] = {path: [] for path, s in by_path.items()
                                                      if s.state_class in CONTAINER_CLASSES}
    for state in states:
        if state.state_path == '/':
            continue
        if not state.state_path.startswith('/') or state.state_path.endswith('/') or not state.name:
            problems.append(f'{state.state_path}: invalid state_path')
            continue
        if state.parent_path not in children:
            problems.append(f'{state.state_path}: parent {state.parent_path!r} is not a container')
            continue
        children[state.parent_path].append(state)
    for path, members in children.items():
        problems.extend(_container_problems(by_path[path], members))
    for state in states:
        problems.extend(f'{state.state_path}: {p}' for p in _entry_problems(state))
    return problems


def _label(state, index: int) -> str:
    return getattr(state, 'state_path', None) or f'entry #{index}'


def _field_problems(state) -> list[str]:
    if not isinstance(state, StateInstantiation):
        return [f'not a StateInstantiation: {type(state).__name__}']
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


def _entry_problems(state: StateInstantiation) -> list[str]:
    problems = []
    if not state.state_class:
        problems.append('empty state_class')
    if state.state_class == StateInstantiation.CLASS_OUTCOME:
        if state.outcomes or state.transitions:
            problems.append(':OUTCOME entries have no outcomes or transitions')
        return problems
    if len(state.outcomes) != len(state.transitions):
        problems.append(f'{len(state.outcomes)} outcomes but {len(state.transitions)} transitions')
    if len(state.autonomy) != len(state.outcomes):
        problems.append(f'{len(state.outcomes)} outcomes but {len(state.autonomy)} autonomy levels')
    if len(set(state.outcomes)) != len(state.outcomes):
        problems.append(f'an outcome is listed twice: {state.outcomes}')
    if len(state.parameter_names) != len(state.parameter_values):
        problems.append('parameter_names and parameter_values differ in length')
    if len(state.userdata_keys) != len(state.userdata_remapping):
        problems.append('userdata_keys and userdata_remapping differ in length')
    if state.state_class == StateInstantiation.CLASS_BEHAVIOR and not state.behavior_class:
        problems.append(':BEHAVIOR without behavior_class')
    if state.state_class in CONTAINER_CLASSES and not state.outcomes:
        problems.append('a container needs outcomes')
    return problems


def _container_problems(container: StateInstantiation, members: list[StateInstantiation]) -> list[str]:
    path = container.state_path
    states = {m.name: m for m in members if m.state_class != StateInstantiation.CLASS_OUTCOME}
    problems = [f'{m.state_path}: not an outcome of {path}' for m in members
                if m.state_class == StateInstantiation.CLASS_OUTCOME and m.name not in container.outcomes]
    problems.extend(f'{path}: state {name!r} has the name of a container outcome'
                    for name in states if name in container.outcomes)
    if not states:
        return problems + [f'{path}: container without states']
    if container.initial_state_name and container.initial_state_name not in states:
        problems.append(f'{path}: initial_state_name {container.initial_state_name!r} is not one of its states')
    concurrent = container.state_class == StateInstantiation.CLASS_CONCURRENCY
    if not concurrent and not container.initial_state_name:
        problems.append(f'{path}: state machine without initial_state_name')
    allowed = set(container.outcomes) if concurrent else set(container.outcomes) | set(states)
    for member in states.values():
        problems.extend(f'{member.state_path}: transition {t!r} names neither a sibling state nor an '
                        f'outcome of {path}' for t in member.transitions if t not in allowed)
    if concurrent:
        problems.extend(_condition_problems(container, states))
    elif container.initial_state_name in states:
        unreachable = set(states) - _reachable(container.initial_state_name, states)
        problems.extend(f'{states[name].state_path}: unreachable from {container.initial_state_name!r}'
                        for name in sorted(unreachable))
    return problems


def _condition_problems(container: StateInstantiation, states: dict[str, StateInstantiation]) -> list[str]:
    path = container.state_path
    if len(container.cond_outcome) != len(container.cond_transition):
        return [f'{path}: cond_outcome and cond_transition differ in length']
    problems = []
    for outcome, condition in zip(container.cond_outcome, container.cond_transition):
        if outcome not in container.outcomes:
            problems.append(f'{path}: condition outcome {outcome!r} is not a container outcome')
        if not condition.state_name or len(condition.state_name) != len(condition.state_outcome):
            problems.append(f'{path}: condition for {outcome!r} is empty or uneven')
            continue
        for name, inner_outcome in zip(condition.state_name, condition.state_outcome):
            if name not in states:
                problems.append(f'{path}: condition for {outcome!r} names unknown inner state {name!r}')
            elif inner_outcome not in states[name].outcomes:
                problems.append(f'{path}: condition for {outcome!r}: {name!r} has no outcome {inner_outcome!r}')
    problems.extend(f'{path}: container outcome {o!r} has no condition'
                    for o in container.outcomes if o not in container.cond_outcome)
    return problems


def _reachable(initial: str, states: dict[str, StateInstantiation]) -> set[str]:
    seen, queue = {initial}, deque([initial])
    while queue:
        for target in states[queue.popleft()].transitions:
            if target in states and target not in seen:
                seen.add(target)
                queue.append(target)
    return seen
