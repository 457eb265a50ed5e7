"""The operator's side of a run, as FlexBE's Runtime Control (ROS-free).

FlexBE lets the operator watch a behavior and step in: an autonomy level decides which
transitions wait for the operator's confirmation, any outcome of the active state can be
forced (FlexBE's "force outcome", fault injection anywhere at any time), an ``InputState``
asks the operator for data, and the behavior can be paused, resumed and stopped.
:class:`RuntimeControl` is that operator for the executive, fed with commands (plain dicts,
so a GUI in another process can send them):

    {'command': 'autonomy', 'level': 2}            # Off 0, Low 1, High 2, Full 3
    {'command': 'confirm', 'state': '/stand'}      # take the transition that waits
    {'command': 'force', 'state': '/stand', 'outcome': 'failed'}
    {'command': 'input', 'state': '/object_template', 'value': 1}   # None: the operator aborts
    {'command': 'pause'} / {'command': 'resume'} / {'command': 'stop'}
    {'command': 'sensor', 'name': 'battery_low', 'value': True}   # a capability robot's; None: free

While the executive waits for the operator (a confirmation, an answer, a pause) it does not
step the robot, so the robot's clock stands still: the run's robot time is the robot's work
alone, whatever the operator's reaction time (the simulated world is frozen meanwhile; a real
robot would hold its posture). A wait ends at the executive's wall-time limit like any run.

    control = RuntimeControl(receive=queue_reader, report=print, autonomy_level=HIGH)
    execute_state_machine(machine, robot, system, control=control)
"""

from __future__ import annotations

import time
from typing import Any, Callable

from atlas_sim.executive.errors import ExecutionError
from respec.vocabulary.errors import ErrorCode

#: FlexBE's autonomy levels (flexbe_core.Autonomy), the operator's names for them.
OFF, LOW, HIGH, FULL = 0, 1, 2, 3
AUTONOMY_LEVELS = {'Off': OFF, 'Low': LOW, 'High': HIGH, 'Full': FULL}
#: How long one wait for a command lasts before the executive looks at its limits again (s).
WAIT_POLL_SECONDS = 0.05
COMMANDS = ('autonomy', 'confirm', 'force', 'input', 'pause', 'resume', 'stop', 'sensor')


class OperatorStopError(ExecutionError):
    """The operator stopped the run (FlexBE's stop); the trace holds what ran until then."""

    code = ErrorCode.PREEMPTED


class OperatorWaitLimitError(ExecutionError):
    """The run reached its wall-time limit while it waited for the operator."""

    code = ErrorCode.TIMEOUT


class CommandError(ValueError):
    """A command the control does not understand (the sender is told why)."""


def needs_confirmation(required_autonomy: int, autonomy_level: int) -> bool:
    """Whether a transition waits for the operator: FlexBE takes an outcome on its own only
    when its required autonomy is below the current level
    (``OperatableStateMachine.is_transition_allowed``), so at level Off every one waits and one
    of Full autonomy always does (FlexBE runs unattended behaviors at level 255)."""
    return required_autonomy >= autonomy_level


def checked_command(command: Any) -> dict:
    """``command`` if it is one the control understands; CommandError saying why if not."""
    if not isinstance(command, dict) or command.get('command') not in COMMANDS:
        raise CommandError(f'a command is one of {", ".join(COMMANDS)}')
    kind = command['command']
    if kind == 'autonomy' and command.get('level') not in AUTONOMY_LEVELS.values():
        raise CommandError('autonomy: level is 0 (Off), 1 (Low), 2 (High) or 3 (Full)')
    if kind in ('confirm', 'force', 'input') and not isinstance(command.get('state'), str):
        raise CommandError(f'{kind}: state names the state (its path)')
    if kind == 'force' and not isinstance(command.get('outcome'), str):
        raise CommandError('force: outcome names one of the state\'s outcomes')
    value = command.get('value')
    if kind == 'sensor' and (not isinstance(command.get('name'), str) or not (value is None or isinstance(value, bool))):
        raise CommandError('sensor: name names the sensor, value is true, false or null (as the environment reads it)')
    return command


class RuntimeControl:
    """The operator of one run: commands in through ``receive(timeout) -> [command, ...]``
    (waits up to ``timeout`` seconds for one), what it waits for out through
    ``report(status)`` whenever that changes (see :meth:`status`)."""

    def __init__(self, receive: Callable[[float], list], report: Callable[[dict], None] | None = None,
                 autonomy_level: int = FULL, clock: Callable[[], float] = time.monotonic):
        self.receive, self.report_to = receive, report or (lambda status: None)
        self.autonomy_level = autonomy_level
        self.clock = clock
        self.paused = self.stopped = False
        self.forced: dict[str, str] = {}       # state path -> outcome the operator forced
        self.confirmed: set[str] = set()       # states whose waiting transition was confirmed
        self.answers: dict[str, Any] = {}      # state path -> the operator's input
        self.sensors: dict[str, bool | None] = {}  # a capability robot's sensors the operator set (None: freed)
        self.waiting: dict | None = None       # what the run waits for, as the GUI shows it
        self.events: list[dict] = []           # what the operator did, in order

    def status(self) -> dict:
        return {'autonomy': self.autonomy_level, 'paused': self.paused, 'waiting': self.waiting}

    def report(self) -> None:
        self.report_to(self.status())

    # commands ------------------------------------------------------------------------------

    def apply(self, command: dict) -> None:
        """Take one command (checked: CommandError for one it does not understand)."""
        command = checked_command(command)
        kind = command['command']
        if kind == 'autonomy':
            self.autonomy_level = command['level']
        elif kind == 'pause':
            self.paused = True
        elif kind == 'resume':
            self.paused = False
        elif kind == 'stop':
            self.stopped = True
        elif kind == 'force':
            self.forced[command['state']] = command['outcome']
        elif kind == 'confirm':
            self.confirmed.add(command['state'])
        elif kind == 'sensor':
            self.sensors[command['name']] = command['value']
        else:
            self.answers[command['state']] = command.get('value')
        self.events.append(dict(command))

    def poll(self, timeout: float = 0.0) -> None:
        """Take the commands that arrived (waiting up to ``timeout`` for one); report changes."""
        before = self.status()
        for command in self.receive(timeout):
            try:
                self.apply(command)
            except CommandError as error:  # the GUI checks commands; a bad one must not end the run
                self.events.append({'command': 'refused', 'reason': str(error)})
        if self.status() != before:
            self.report()

    # what the executive asks ----------------------------------------------------------------

    def between_ticks(self, state_path: str, deadline: float | None) -> None:
        """Before each robot step: take commands; stop, or hold while paused (no step)."""
        self.poll()
        self._check_stop(state_path)
        if self.paused:
            self._wait(state_path, {'kind': 'resume', 'state': state_path}, lambda: not self.paused, deadline)

    def take_forced(self, paths) -> tuple[str, str] | None:
        """(path, outcome) the operator forced for one of ``paths`` (the active state and its
        children), taken once."""
        for path in paths:
            if path in self.forced:
                return path, self.forced.pop(path)
        return None

    def confirm(self, state_path: str, outcome: str, required: int, outcomes: list[str],
                deadline: float | None, until: Callable[[], bool] | None = None) -> str | None:
        """The outcome ``state_path`` goes on with once its transition on ``outcome`` (of
        ``required`` autonomy) may be taken: at once when the level allows it, else when the
        operator confirms it, raises the level, or forces another outcome instead. None when
        ``until()`` ended the wait first (a capability robot's sensor changed: the caller asks again)."""
        if not needs_confirmation(required, self.autonomy_level) and state_path not in self.forced:
            return outcome
        self.confirmed.discard(state_path)
        interrupted = []

        def done() -> bool:
            if (state_path in self.confirmed or state_path in self.forced
                    or not needs_confirmation(required, self.autonomy_level)):
                return True
            if until is not None and until():
                interrupted.append(True)
                return True
            return False
        self._wait(state_path, {'kind': 'confirm', 'state': state_path, 'outcome': outcome, 'required': required,
                                'outcomes': list(outcomes)}, done, deadline)
        if interrupted:
            return None
        self.confirmed.discard(state_path)
        forced = self.forced.pop(state_path, None)
        return forced if forced in outcomes else outcome

    def ask_input(self, state_path: str, prompt: str, default: Any, deadline: float | None) -> Any:
        """The operator's answer to the ``InputState`` at ``state_path`` (None: aborted). At Full
        autonomy nobody is asked: the robot's ``default`` answers (the unattended run)."""
        if self.autonomy_level >= FULL:
            return default
        self.answers.pop(state_path, None)
        self._wait(state_path, {'kind': 'input', 'state': state_path, 'prompt': prompt, 'default': default},
                   lambda: state_path in self.answers, deadline)
        return self.answers.pop(state_path)

    def _wait(self, state_path: str, waiting: dict, done: Callable[[], bool], deadline: float | None) -> None:
        """Take commands until ``done()``; the robot is not stepped meanwhile."""
        self.waiting = waiting
        self.report()
        try:
            while True:
                self._check_stop(state_path)
                if done():
                    return
                if deadline is not None and self.clock() > deadline:
                    raise OperatorWaitLimitError(f'no SM outcome within the wall-clock limit (state {state_path!r} '
                                                 f'waited for the operator: {waiting["kind"]})', item=state_path)
                self.poll(WAIT_POLL_SECONDS)
        finally:
            self.waiting = None
            self.report()

    def _check_stop(self, state_path: str) -> None:
        if self.stopped:
            raise OperatorStopError(f'the operator stopped the run in state {state_path!r}', item=state_path)


__all__ = ['RuntimeControl', 'AUTONOMY_LEVELS', 'OFF', 'LOW', 'HIGH', 'FULL', 'needs_confirmation',
           'checked_command', 'CommandError', 'OperatorStopError', 'OperatorWaitLimitError']
