"""``JobOutcome``: what a GUI job ended with, typed until the HTTP answer turns it into JSON.

The synthesis action's result arrives as ``SynthesisOutcome`` (synthesis_manager.client, ROS
side); the GUI's runner hands it over as a JobOutcome, and the backend, the result summary and
the downloads read its fields. Only the routes (and ``result.json``) call :meth:`to_dict`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from respec.errors import ErrorCode
from sm_generation.instantiation import StateInstantiation


@dataclass(frozen=True)
class JobOutcome:
    """The action's result, or one the GUI made for a job that never got one.

    ``goal_status`` is the ROS goal's final status; None when no goal was sent (the job was
    cancelled while queued, or the runner failed), and then the JSON has no such key.
    """

    error_code: int
    error_name: str
    message: str
    states: tuple[StateInstantiation, ...] = ()
    ltl_specification: dict[str, list[str]] = field(default_factory=dict)  # text sections
    automaton: dict = field(default_factory=dict)                          # client.automaton_to_dict
    seconds: float = 0.0
    goal_status: str | None = None

    @classmethod
    def local(cls, error_name: ErrorCode, message: str, seconds: float) -> 'JobOutcome':
        """The outcome of a job that never got a result (``seconds`` since it was created)."""
        return cls(ErrorCode(error_name).number, error_name, message, seconds=round(seconds, 4))

    @classmethod
    def from_dict(cls, data: dict) -> 'JobOutcome':
        """Inverse of :meth:`to_dict` (also reads ``SynthesisOutcome.to_dict()``)."""
        return cls(error_code=data['error_code'], error_name=data['error_name'], message=data['message'],
                   states=tuple(StateInstantiation.from_dict(state) for state in data.get('states') or ()),
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
                  'states': [state.to_dict() for state in self.states],
                  'ltl_specification': self.ltl_specification, 'automaton': self.automaton,
                  'seconds': round(self.seconds, 4)}
        if self.goal_status is not None:
            result['goal_status'] = self.goal_status
        return result
