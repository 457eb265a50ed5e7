"""Whether the robot can get to the control mode each goal needs, told in one sentence.

Eq. (9) only allows the mode changes that ``config/<system>.yaml`` lists. The compiler
refuses a goal whose mode no route from the initial mode reaches, and the pre-check of
``ltl_specification.diagnosis`` also follows the goals in order; both say it with the same
sentence, naming the missing transition and the modes the robot could change to instead.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from respec.robot.abstraction import RobotAbstraction

from ltl_specification.pertinence import mode_distances


@dataclass(frozen=True)
class Finding:
    """One impossible part of a request, found before synthesis."""

    sentence: str
    equation: str      # the paper equation whose formulas make it impossible
    config_item: str   # the configuration entry or request field to change
    item: str          # the goal, mode, action or custom formula concerned


def modes_needed_by(abstraction: RobotAbstraction, item: str) -> list[str]:
    """The control modes the robot must be in to achieve ``item``: the mode itself, or the
    action's mode preconditions (action preconditions persist once completed, modes do not)."""
    if abstraction.kind_of(item) == 'control_mode':
        return [item]
    return [p for p in abstraction.actions.get(item, ()) if abstraction.kind_of(p) == 'control_mode']


def unreachable_goal_modes(abstraction: RobotAbstraction, goals: Sequence[str], initial_mode: str, strict_order: bool,
                           where: str) -> list[Finding]:
    """Eq. (9) only allows the configured mode changes, so every goal's mode must be reachable
    from the initial mode; with eq. (20) goal i counts only after goal i-1, so it must be
    reachable from the mode the previous goal left the robot in."""
    findings = []
    mode, reason = initial_mode, f'the robot starts in {initial_mode}'
    for number, goal in enumerate(goals, start=1):
        for needed in modes_needed_by(abstraction, goal):
            if needed not in mode_distances(abstraction.control_modes, mode):
                findings.append(Finding(
                    _unreachable_sentence(abstraction, number, goal, needed, mode, reason, where),
                    '(9)', f'control_modes.{mode} in {where}', goal))
            if not strict_order:
                continue
            mode = needed
            reason = (f'after goal {number} ({goal}) the robot is in {needed}' if needed == goal else
                      f'goal {number} ({goal}) needs the robot in {needed}')
    return findings


def _unreachable_sentence(abstraction: RobotAbstraction, number: int, goal: str, needed: str, mode: str,
                          reason: str, where: str) -> str:
    what = f'goal {number} ({goal})' + ('' if needed == goal else f', which needs the robot in {needed},')
    adjacent = ', '.join(abstraction.control_modes[mode]) or 'no other mode'
    reachable = [m for m in mode_distances(abstraction.control_modes, mode) if m != mode]
    beyond = ('' if set(reachable) <= {*abstraction.control_modes[mode]} else
              f'; no mode reachable from {mode} ({", ".join(reachable)}) changes to {needed} either')
    return (f'{what[0].upper()}{what[1:]} can never be achieved: {reason}, and {mode} -> {needed} '
            f'is not a transition in {where} (from {mode} the robot can only change to {adjacent}{beyond}).')
