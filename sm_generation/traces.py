"""The observable runs of a generated machine, for comparing two machines.

A run starts at the root's initial state. In each step the running top-level state
reports one of its outcomes (a plain state) or one of its conditions (a concurrency
container); the step is recorded as (what runs, what was reported). A run ends when it
reaches an outcome of the machine or after ``depth`` steps. Two machines with the same
set of runs up to ``depth`` cannot be told apart by any sequence of that many outcomes.
"""

from __future__ import annotations

from typing import Any

from sm_generation.instantiation import StateInstantiation
from sm_generation.state_machine import State, StateMachine

Part = tuple[str, str, tuple[str, ...]]  # (state class, behavior class, parameter values)
Step = tuple[tuple[Part, ...], tuple[tuple[Part, str], ...]]
TRUNCATED = ('...',)


def _part(state: StateInstantiation) -> Part:
    return (state.state_class, state.behavior_class, tuple(state.parameter_values))


def _moves(state: State) -> tuple[tuple[Part, ...], list[tuple[tuple[tuple[Part, str], ...], str]]]:
    """What ``state`` runs, and its possible (report, target) moves."""
    if state.state_class != StateInstantiation.CLASS_CONCURRENCY:
        part = _part(state)
        return (part,), [(((part, outcome),), target) for outcome, target in zip(state.outcomes, state.transitions)]
    parts = {child.name: _part(child) for child in state.states}
    target_of = dict(zip(state.outcomes, state.transitions))
    moves = []
    for outcome, condition in zip(state.cond_outcome, state.cond_transition):
        report = tuple(sorted((parts[name], result) for name, result in zip(condition.state_name,
                                                                              condition.state_outcome)))
        moves.append((report, target_of[outcome]))
    return tuple(sorted(parts.values())), moves


def runs(root: StateMachine, depth: int) -> set[tuple[Any, ...]]:
    """All runs of ``root`` of at most ``depth`` steps: tuples of steps, then ('exit', outcome) or TRUNCATED."""
    top = {s.name: s for s in root.states}
    moves = {name: _moves(state) for name, state in top.items()}
    result: set[tuple[Any, ...]] = set()

    def walk(name: str, prefix: tuple[Any, ...]) -> None:
        if name in root.outcomes and name not in top:
            result.add(prefix + (('exit', name),))
            return
        if len(prefix) == depth:
            result.add(prefix + (TRUNCATED,))
            return
        running, options = moves[name]
        for report, target in options:
            walk(target, prefix + ((running, report),))

    walk(root.initial_state_name, ())
    return result
