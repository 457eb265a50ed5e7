"""The executive's errors, and where a state's outcome leads (ROS-free).

The executive runs the tree :class:`sm_generation.state_machine.StateMachine` as it is handed
over; a StateInstantiation list becomes that tree where it arrives (a message, a file).
"""

from __future__ import annotations

from atlas_sim.executive.trace_check import Trace
from respec.vocabulary.errors import CodedError, ErrorCode
from sm_generation.state_machine import State


class ExecutionError(CodedError):
    """The run could not go on; ``item`` names the offending state, ``trace`` holds what ran."""

    code = ErrorCode.BEHAVIOR_SYNTHESIS_FAILED

    def __init__(self, message: str, item: str, trace: Trace | None = None):
        super().__init__(message, item)
        self.trace = trace


class UndeclaredOutcomeError(ExecutionError):
    """A state returned an outcome that it does not declare (so it has no transition)."""

    code = ErrorCode.AUTOMATON_INVALID


def next_target(state: State, outcome: str, trace: Trace | None = None) -> str:
    """Where ``state`` goes on when it returns ``outcome``; an undeclared outcome stops the run."""
    target = state.next_target(outcome)
    if target is None:
        raise UndeclaredOutcomeError(f'state {state.state_path!r} returned {outcome!r}, which is not one of its '
                                     f'outcomes {state.outcomes}', item=state.state_path, trace=trace)
    return target
