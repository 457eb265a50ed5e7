"""STAND-IN, to be deleted: the JSON of the StateMachine tree that ``sm_generation.state_machine``
(written in parallel, issue 31 point 2) will build with
``StateMachine.from_instantiations(states).to_dict()``. Until that module is on main, the GUI
serves this function's answer, which has exactly the same shape:

every node is its StateInstantiation's ``to_dict()`` fields plus ``name`` (the last path
segment, ``/`` for the root) and ``children`` (in list order: the root's top-level states, then
its ``:OUTCOME`` entries; a container's inner states; ``[]`` for a leaf).
"""

from __future__ import annotations

from typing import Sequence

from sm_generation.instantiation import StateInstantiation


def state_machine_tree(states: Sequence[StateInstantiation]) -> dict:
    """The root node of the machine that ``states`` (a generator's flat list) describes."""
    nodes = {state.state_path: {**state.to_dict(), 'name': state.name or '/', 'children': []} for state in states}
    inner = {path: [] for path in nodes}
    for state in states:
        if state.state_path != '/':
            inner[state.parent_path].append(state)
    for path, node in nodes.items():
        in_order = sorted(inner[path], key=lambda s: s.state_class == StateInstantiation.CLASS_OUTCOME)  # stable
        node['children'] = [nodes[s.state_path] for s in in_order]
    return nodes['/']
