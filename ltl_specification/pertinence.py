"""Which actions and control modes a task needs, and why.

Pertinence rule:

1. Actions: the goals that are actions, and, recursively, every action named as a
   precondition of a pertinent action (and actions that custom LTL mentions).
2. Needed modes: goals that are control modes, modes named as preconditions of pertinent
   actions (and modes that custom LTL mentions).
3. Control modes: the initial mode, plus every mode lying on some shortest path, in the
   system's full mode transition graph, from the initial mode or a needed mode to a needed
   mode. A needed mode that no route from the initial mode reaches is kept as well: the
   compiler refuses such a task, diagnosing the specification that shows why it is impossible.

Rule 3 keeps the specification small (a mode that is never on a shortest route is left
out), yet the modes kept always allow the robot to travel between any two modes the task
needs, in whatever order it needs them, along a shortest route. It is computed from the
configuration, so a goal such as ``walk`` or ``footstep_execution`` brings in ``stand``
and ``walk`` or ``step`` by itself.

Actions that are initial conditions but not needed by any goal are left out (they could
not affect the task); they are listed in ``Pertinence.left_out``. All results follow the
configuration file's order, so they do not depend on the order of goals.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass, field
from typing import Mapping, Sequence

from respec.robot.abstraction import RobotAbstraction


@dataclass(frozen=True)
class Pertinence:
    """The actions and modes a task needs (configuration order) and the reason for each."""

    initial_mode: str | None
    modes: tuple[str, ...]
    actions: tuple[str, ...]
    reasons: dict[str, str] = field(default_factory=dict)
    left_out: dict[str, str] = field(default_factory=dict)


def infer_pertinence(abstraction: RobotAbstraction, initial_mode: str | None,
                     initial_conditions: Sequence[str], goals: Sequence[str],
                     mentioned: Sequence[str] = ()) -> Pertinence:
    """Apply the pertinence rule of this module to a validated task."""
    reasons: dict[str, str] = {}
    needed_modes: list[str] = []
    needed_actions: list[str] = []

    def need(item: str, reason: str) -> None:
        """Mark ``item`` and, depth first, its preconditions (a stack, not recursion: a
        configuration may chain thousands of actions)."""
        pending = [(item, reason)]
        while pending:
            item, reason = pending.pop()
            if item in reasons:
                continue
            reasons[item] = reason
            if abstraction.kind_of(item) == 'control_mode':
                needed_modes.append(item)
                continue
            needed_actions.append(item)
            pending.extend((precondition, f'precondition of {item}')
                           for precondition in reversed(abstraction.actions[item]))

    if initial_mode is not None:
        reasons[initial_mode] = 'initial mode'
    for number, goal in enumerate(goals, start=1):
        need(goal, f'goal {number}')
    for item in mentioned:
        need(item, 'mentioned in custom LTL')

    modes = set()  # membership only; the result follows configuration order
    if initial_mode is not None:
        modes.add(initial_mode)
        # A needed mode no route reaches is pertinent all the same (the compiler refuses the
        # task, with the diagnosis of the specification that says why it is impossible).
        modes.update(needed_modes)
        for source in [initial_mode, *needed_modes]:
            for target in needed_modes:
                for mode in _on_shortest_paths(abstraction.control_modes, source, target):
                    if mode not in modes:
                        modes.add(mode)
                        reasons.setdefault(mode, f'on the way from {source} to {target}')

    left_out = {item: 'initial condition not needed by any goal'
                for item in initial_conditions if item not in reasons}
    return Pertinence(
        initial_mode=initial_mode,
        modes=tuple(m for m in abstraction.control_modes if m in modes),
        actions=tuple(a for a in abstraction.actions if a in reasons),
        reasons={item: reasons[item] for item in abstraction.items() if item in reasons},
        left_out=left_out)


def mode_distances(graph: Mapping[str, Sequence[str]], source: str) -> dict[str, int]:
    """Breadth-first distances from ``source``."""
    distance = {source: 0}
    queue = deque([source])
    while queue:
        node = queue.popleft()
        for successor in graph[node]:
            if successor not in distance:
                distance[successor] = distance[node] + 1
                queue.append(successor)
    return distance


def _on_shortest_paths(graph: Mapping[str, Sequence[str]], source: str, target: str) -> list[str]:
    """Nodes v on some shortest source->target path: d(source, v) + d(v, target) = d(source, target)."""
    from_source = mode_distances(graph, source)
    if target not in from_source:
        return []
    reverse = {node: [p for p in graph if node in graph[p]] for node in graph}
    to_target = mode_distances(reverse, target)
    length = from_source[target]
    return [v for v in graph
            if v in from_source and v in to_target and from_source[v] + to_target[v] == length]
