"""``JobOutcome``: what a GUI job ended with, typed until the HTTP answer turns it into JSON.

The synthesis action's result arrives as ``SynthesisOutcome`` (synthesis_manager.client, ROS
side), its state machine already a tree (``SynthesisOutcome.machine``); the GUI's runner hands it
over as a JobOutcome, and the backend, the result summary, the drawing, the plays, the simulations
and the downloads read its fields and that tree. Only the routes (and ``result.json``) call
:meth:`to_dict`, where the tree becomes the StateInstantiation list again.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from respec.vocabulary.errors import ErrorCode
from sm_generation.state_machine import StateMachine


@dataclass(frozen=True)
class JobOutcome:
    """The action's result, or one the GUI made for a job that never got one.

    ``goal_status`` is the ROS goal's final status; None when no goal was sent (the job was
    cancelled while queued, or the runner failed), and then the JSON has no such key.
    """

    error_code: int
    error_name: str
    message: str
    machine: StateMachine | None = None  # the state machine, if the result has one
    ltl_specification: dict[str, list[str]] = field(default_factory=dict)  # text sections
    automaton: dict = field(default_factory=dict)                          # client.automaton_to_dict
    seconds: float = 0.0
    goal_status: str | None = None

    @classmethod
    def local(cls, error_name: ErrorCode, message: str, seconds: float) -> 'JobOutcome':
        """The outcome of a job that never got a result (``seconds`` since it was created)."""
        return cls(ErrorCode(error_name).number, error_name,  # type: ignore[call-arg]  # a lookup by value (mypy: a constructor)
                   message, seconds=round(seconds, 4))

    @classmethod
    def from_result(cls, data: dict, machine: StateMachine | None) -> 'JobOutcome':
        """The outcome of an action's result: ``data`` as ``SynthesisOutcome.to_dict()`` gives it
        (its ``states`` list left aside), ``machine`` the tree of that list."""
        return cls(error_code=data['error_code'], error_name=data['error_name'], message=data['message'],
                   machine=machine,
                   ltl_specification=data.get('ltl_specification') or {},
                   automaton=data.get('automaton') or {}, seconds=data.get('seconds', 0.0),
                   goal_status=data.get('goal_status'))

    @property
    def succeeded(self) -> bool:
        return self.error_name == ErrorCode.SUCCESS

    @property
    def cancelled(self) -> bool:
        return self.error_name == ErrorCode.PREEMPTED

    @property
    def automaton_states(self) -> list[dict]:
        return self.automaton.get('states') or []

    def to_dict(self) -> dict:
        """The JSON of ``outcome`` in a job (and of ``result.json``)."""
        result = {'error_code': self.error_code, 'error_name': self.error_name, 'message': self.message,
                  'states': [state.to_dict() for state in self.machine.to_instantiations()] if self.machine else [],
                  'ltl_specification': self.ltl_specification, 'automaton': self.automaton,
                  'seconds': round(self.seconds, 4)}
        if self.goal_status is not None:
            result['goal_status'] = self.goal_status
        return result
