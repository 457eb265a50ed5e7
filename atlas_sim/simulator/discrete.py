"""Discrete semantics of control modes and actions (no physics).

The rules, taken from the ``abstraction:`` section of the robot config:

* **Control modes.**  Requesting mode ``m`` while in mode ``c`` is allowed when
  ``m == c`` (self-loops are implied) or ``m`` is listed under
  ``control_modes[c]``.  A disallowed request fails and the robot stays in
  ``c``.  While a transition runs, ``pending_mode`` names its target and the
  robot still reports ``mode == c``; the mode changes only when the motion
  settles with outcome ``completed``.
* **Action preconditions.**  Each entry of ``actions[a]`` must hold when ``a``
  starts: a *control mode* entry holds when it is the current mode and no
  transition is pending; an *action* entry holds when that action has a valid
  completion.  Only direct preconditions are checked: indirect ones were
  checked when the prerequisite itself started, and invalidation cascades (see
  below) keep the chain consistent.
* **Validity of completions.**  A completed action stays valid until
  (a) a later attempt of the same action fails, or
  (b) a capability listed as its invalidator in ``simulation.invalidations``
  completes (e.g. executing a footstep plan consumes it).
  Invalidating an action also invalidates every action whose preconditions
  (transitively) include it.  Mode changes do not invalidate actions unless
  configured.
* **Busy.**  A capability that is already running cannot be started again, and
  a mode transition cannot start while another one is pending.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, Iterable, List, Mapping, Optional, Set

from .config import SimulationConfigError
from respec.robot.abstraction import RobotAbstraction
from respec.vocabulary.naming import COMPLETED, FAILED



@dataclass
class DiscreteState:
    """What the simulator believes about the robot's discrete situation."""

    mode: str
    pending_mode: Optional[str] = None
    #: valid completions: action -> sequence number of its latest completion
    completed: Dict[str, int] = field(default_factory=dict)
    running: Set[str] = field(default_factory=set)
    completion_counter: int = 0

    def completed_actions(self) -> List[str]:
        """Validly completed actions, oldest completion first."""
        return sorted(self.completed, key=self.completed.__getitem__)


class DiscreteSemantics:
    """Decides whether a request may start and updates the state on outcomes."""

    def __init__(
        self,
        abstraction: RobotAbstraction,
        invalidations: Optional[Mapping[str, Iterable[str]]] = None,
    ) -> None:
        self.abstraction = abstraction
        self.invalidations = {k: tuple(v) for k, v in (invalidations or {}).items()}
        for trigger, victims in self.invalidations.items():
            unknown = [n for n in (trigger, *victims) if not abstraction.is_capability(n)]
            if unknown:
                raise SimulationConfigError(f"invalidations mention unknown capabilities {unknown}", item=unknown[0])

    def initial_state(self, mode: Optional[str] = None) -> DiscreteState:
        mode = mode or next(iter(self.abstraction.control_modes))
        if not self.abstraction.is_mode(mode):
            raise SimulationConfigError(f"unknown initial mode {mode!r}", item=str(mode))
        return DiscreteState(mode=mode)

    # ----------------------------------------------------------------- checks
    def refusal(self, state: DiscreteState, name: str, exempt: Iterable[str] = ()) -> Optional[str]:
        """Why ``name`` cannot start now, or ``None`` if it may start.

        ``exempt`` names preconditions not to check (the request carries the data they stand for).
        """
        if not self.abstraction.is_capability(name):
            return f"unknown capability {name!r}"
        if name in state.running:
            return f"{name} is already running"
        if self.abstraction.is_mode(name):
            return self._mode_refusal(state, name)
        return self._precondition_refusal(state, name, set(exempt))

    def _mode_refusal(self, state: DiscreteState, target: str) -> Optional[str]:
        if state.pending_mode is not None:
            return f"transition to {state.pending_mode} in progress"
        if not self.abstraction.transition_allowed(state.mode, target):
            return f"transition {state.mode} -> {target} is not allowed"
        return None

    def _precondition_refusal(self, state: DiscreteState, action: str, exempt: Set[str]) -> Optional[str]:
        unmet = [p for p in self.abstraction.actions[action] if p not in exempt and not self._holds(state, p)]
        if unmet:
            return f"preconditions of {action} not met: {', '.join(unmet)}"
        return None

    def _holds(self, state: DiscreteState, precondition: str) -> bool:
        if self.abstraction.is_mode(precondition):
            return state.mode == precondition and state.pending_mode is None
        return precondition in state.completed

    # ---------------------------------------------------------------- updates
    def begin(self, state: DiscreteState, name: str) -> None:
        """Record that ``name`` started (call only after ``refusal`` returned None)."""
        state.running.add(name)
        if self.abstraction.is_mode(name):
            state.pending_mode = name

    def finish(self, state: DiscreteState, name: str, outcome: str) -> Set[str]:
        """Apply the outcome of a started request; returns invalidated actions."""
        state.running.discard(name)
        invalidated: Set[str] = set()
        if self.abstraction.is_mode(name):
            if state.pending_mode == name:
                state.pending_mode = None
            if outcome == COMPLETED:
                state.mode = name
        elif outcome == FAILED:
            invalidated |= self._invalidate(state, [name])
        if outcome == COMPLETED:
            invalidated |= self._invalidate(state, self.invalidations.get(name, ()))
            if self.abstraction.is_action(name):
                state.completion_counter += 1
                state.completed[name] = state.completion_counter
        return invalidated

    def _invalidate(self, state: DiscreteState, actions: Iterable[str]) -> Set[str]:
        removed: Set[str] = set()
        for action in actions:
            for victim in {action, *self.abstraction.dependents(action)}:
                if state.completed.pop(victim, None) is not None:
                    removed.add(victim)
        return removed
