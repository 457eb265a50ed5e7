"""The state machine as the executive runs it: the shared tree, and the executive's errors (ROS-free).

The tree is :class:`sm_generation.state_machine.StateMachine`; a list it refuses is refused here
as :class:`MachineInvalidError`, an error of the run (with the trace so far, none yet).
"""

from __future__ import annotations

from atlas_sim.executive.trace_check import Trace
from respec.errors import CodedError, ErrorCode
from sm_generation.errors import SMGenerationError
from sm_generation.state_machine import State, StateMachine


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


def load_machine(states) -> StateMachine:
    """The tree of ``states`` (StateInstantiations or their dicts), validated."""
    try:
        return StateMachine.from_instantiations(states)
    except SMGenerationError as error:
        raise MachineInvalidError(str(error), item=error.item) from error


def next_target(state: State, outcome: str, trace: Trace | None = None) -> str:
    """Where ``state`` goes on when it returns ``outcome``; an undeclared outcome stops the run."""
    target = state.next_target(outcome)
    if target is None:
        raise UndeclaredOutcomeError(f'state {state.state_path!r} returned {outcome!r}, which is not one of its '
                                     f'outcomes {state.outcomes}', item=state.state_path, trace=trace)
    return target
