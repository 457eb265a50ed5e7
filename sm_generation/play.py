"""Play the environment against a synthesized state machine, one outcome at a time (ROS-free).

In FlexBE's Runtime Control an operator may force any outcome of the active state. Playing
the environment is the same game without a robot: at each step the user reports one outcome of
the active state, and the machine follows its transitions until it ends in one of its own
outcomes. A concurrency container is played as one state: its outcomes are what its
conditions give (the generator nests no other containers).

A play is the list of outcomes reported so far, so the HTTP API above it is stateless:
``play_machine(machine, ['done', 'failed'])``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any, Sequence

from sm_generation.state_machine import StateMachine

MAX_PLAY_STEPS = 500


class MachinePlayError(ValueError):
    """An outcome the active state does not have, or a play too long."""


@dataclass
class MachineTurn:
    """Where the machine is after the outcomes reported so far."""

    step: int
    active: str | None                 # the active state's path ('/look_down'); None once ended
    outcomes: list[str] = field(default_factory=list)   # what may be reported at it
    ended: str | None = None           # the machine's own outcome once it ended
    history: list[tuple[str, str]] = field(default_factory=list)   # (state path, outcome)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def play_machine(machine: StateMachine, outcomes: Sequence[str]) -> MachineTurn:
    """The turn after reporting ``outcomes`` one by one from the machine's initial state."""
    if len(outcomes) > MAX_PLAY_STEPS:
        raise MachinePlayError(f'a play of {len(outcomes)} steps is longer than {MAX_PLAY_STEPS}')
    active, ended, history = machine.initial_state(), None, []
    for step, outcome in enumerate(outcomes):
        if active is None:
            raise MachinePlayError(f'the machine already ended in {ended!r} before step {step}')
        if outcome not in active.outcomes:
            raise MachinePlayError(f'{active.name} has no outcome {outcome!r} (its outcomes: '
                                   f'{", ".join(active.outcomes)}): move {outcome!r} at step {step} does not exist')
        history.append((active.state_path, outcome))
        target = active.next_target(outcome)
        assert target is not None  # the outcome is one of the active state's
        active = machine.state(target)
        if active is None:               # the machine's own outcome: the behavior ended
            ended = target
    turn = MachineTurn(len(outcomes), None if active is None else active.state_path, history=history, ended=ended)
    if active is not None:
        turn.outcomes = list(active.outcomes)
    return turn
