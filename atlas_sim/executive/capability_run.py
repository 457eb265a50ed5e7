"""A simulated capability robot (CNU's format), in closed loop with its synthesized behavior (ROS-free).

No physics: each running state answers one of its capability's outcomes at once, the way a
robot's environment may answer. Which one: what the script says for that capability (``--fail
CAPABILITY[:OUTCOME]``), else its success outcome, else another one its environment allows
(a sensor set by the script, ``--sensor NAME[=false]``, decides a reading capability's outcome).

The run is checked against the specification step by step, in lockstep with the strategy the
machine was generated from: each answer is an environment move, which must be one the
specification's assumptions allow (else the script or the operator broke one, and the check
names it, with the step and who chose it); each next state is the machine's move, which must be
the strategy's (else the machine broke a guarantee). A run that reaches an outcome of the
machine without either is what the specification promises.
"""

from __future__ import annotations

import re
from dataclasses import asdict, dataclass, field

from respec.ltl import evaluate, to_infix
from respec.vocabulary.naming import FAILED, activation
from sm_generation.state_machine import State, StateMachine

#: States a run may enter before it is said not to finish (a failure retried forever).
MAX_STEPS = 200
CHOSEN_BY_ROBOT, CHOSEN_BY_SCRIPT, CHOSEN_BY_OPERATOR = 'the robot', 'the script', 'the operator'


@dataclass
class CapabilityScript:
    """What the simulated robot answers: ``outcomes`` (capability -> FlexBE outcome) instead of
    its success, and ``sensors`` (input -> value) for the environment's readings."""

    outcomes: dict[str, str] = field(default_factory=dict)
    sensors: dict[str, bool] = field(default_factory=dict)


@dataclass
class RunStep:
    state: str
    capability: str
    outcome: str
    chosen_by: str


@dataclass
class CapabilityRunResult:
    outcome: str | None                  # the machine's outcome, None when the run did not finish
    steps: list[RunStep]
    violations: list[str] = field(default_factory=list)
    not_finished: str = ''               # why the run stopped without an outcome

    def to_dict(self) -> dict:
        return {'outcome': self.outcome, 'steps': [asdict(step) for step in self.steps],
                'trace_check': {'ok': not self.violations, 'violations': self.violations},
                **({'not_finished': self.not_finished} if self.not_finished else {})}


class ScriptError(ValueError):
    """A script entry naming no capability, outcome or sensor of the robot."""


def parse_script(capabilities, outcomes: dict, fails: list[str], sensors: list[str]) -> CapabilityScript:
    """``--fail CAPABILITY[:OUTCOME]`` (default: the outcome the capability fails with) and
    ``--sensor NAME[=true|false]`` (default true) for the robot ``capabilities`` (a
    CapabilitySystem) whose capabilities have the FlexBE ``outcomes`` given
    (``respec.robot.state_library.capability_outcomes``); ScriptError naming the bad entry."""
    script = CapabilityScript()
    for entry in fails:
        name, _, outcome = entry.partition(':')
        capability = capabilities.capabilities.get(name)
        if capability is None:
            raise ScriptError(f'--fail {entry}: {name!r} is no capability of {capabilities.system} '
                              f'(capabilities: {", ".join(sorted(capabilities.capabilities))})')
        declared = list(outcomes[name])
        if not outcome:
            failure = capabilities.state_outcomes.get(FAILED)
            failing = [o for o in declared if capabilities.state_outcomes.get(o) == failure]
            if not failing:
                raise ScriptError(f'--fail {entry}: {name} has no outcome it fails with; name one of its outcomes '
                                  f'({", ".join(declared)}) as {name}:OUTCOME')
            outcome = failing[0]
        if outcome not in declared:
            raise ScriptError(f'--fail {entry}: {outcome!r} is no outcome of {name} ({", ".join(declared)})')
        script.outcomes[name] = outcome
    for entry in sensors:
        name, _, value = entry.partition('=')
        if name not in capabilities.spec_inputs:
            raise ScriptError(f'--sensor {entry}: {name!r} is no sensor (spec INPUT) of {capabilities.system} '
                              f'(sensors: {", ".join(capabilities.spec_inputs) or "none"})')
        if value.lower() not in ('', 'true', 'false', '1', '0'):
            raise ScriptError(f'--sensor {entry}: the value must be true or false')
        script.sensors[name] = value.lower() not in ('false', '0')
    return script


class CapabilityRun:
    """One run of ``machine`` (a StateMachine) on the simulated robot ``capabilities`` (a
    CapabilitySystem), in lockstep with ``automaton`` (the strategy it was generated from, as
    the synthesis answered it: a dict of variables and states) and checked against ``spec``."""

    def __init__(self, machine: StateMachine, automaton: dict, capabilities, spec, script: CapabilityScript,
                 choose=None, max_steps: int = MAX_STEPS):
        self.machine, self.capabilities, self.spec, self.script = machine, capabilities, spec, script
        self.inputs, self.outputs = list(automaton['input_variables']), list(automaton['output_variables'])
        self.nodes = {str(state['name']): state for state in automaton.get('states', automaton.get('automaton', ()))}
        self.initial = list(automaton['initial_states'])
        self.choose = choose  # (state path, outcomes) -> an outcome or None: the operator's choice
        self._asked: tuple[str, State, dict] | None = None    # (capability, state, node) ``choose`` is asked about
        self.result = CapabilityRunResult(None, [])  # the run so far (its steps), for a caller's progress
        self.sensors = dict(script.sensors)  # the sensors now: the script's, as the environment changes them
        self.max_steps = max_steps
        self.outcome_propositions = {capabilities.outcome_proposition(name, outcome)
                                     for name in capabilities.capabilities
                                     for outcome in capabilities.transition_outcomes}

    def run(self) -> CapabilityRunResult:
        states = {state.name: state for state in self.machine.states}
        result = self.result = CapabilityRunResult(None, [])
        node = self._initial_node()
        if node is None:
            result.violations.append('no initial state of the strategy has the sensors the script sets '
                                     f'({self._sensors_text()}): the task assumed otherwise')
            return result
        state = states[self.machine.initial_state_name]
        self._check_activation(result, state, node, 0)
        while not result.violations:
            if len(result.steps) >= self.max_steps:
                result.not_finished = self._not_finished(result.steps)
                return result
            capability = capability_of(state, self.capabilities)
            outcome, chosen_by, successor = self._answer(state, capability, node, result)
            result.steps.append(RunStep(state.state_path, capability, outcome, chosen_by))
            if successor is None:
                return result
            target = state.next_target(outcome)
            assert target is not None  # the outcome is one of the state's own
            if target in self.machine.outcomes:
                result.outcome = target
                if not self._output(successor, target):
                    result.violations.append(
                        f'the state machine broke a guarantee of the specification: it ended in {target!r} after '
                        f'{capability} returned {outcome!r} at step {len(result.steps)}, where the strategy goes on '
                        f'with {self._active(successor) or "nothing"}')
                return result
            state, node = states[target], successor
            self._check_activation(result, state, node, len(result.steps))
        return result

    # the environment's move -------------------------------------------------------------------

    def _answer(self, state: State, capability: str, node: dict, result: CapabilityRunResult):
        """The outcome answered for ``state``, who chose it and the strategy's next node (None
        when the choice breaks an assumption: the violation is added to ``result``)."""
        chosen = None
        if self.choose:
            self._asked = (capability, state, node)
            chosen = self.choose(state.state_path, list(state.outcomes))
        if chosen is not None:
            candidates, chosen_by = [chosen], CHOSEN_BY_OPERATOR
        elif capability in self.script.outcomes:
            candidates, chosen_by = [self.script.outcomes[capability]], CHOSEN_BY_SCRIPT
        else:
            candidates, chosen_by = self._preferred(capability, state), CHOSEN_BY_ROBOT
        # The sensors as they are first; a robot's own answer may then follow the environment's
        # change of a sensor (a script's or an operator's answer means the sensors it was given).
        for relax in (False, True) if chosen_by == CHOSEN_BY_ROBOT else (False,):
            for outcome in candidates:
                successor = self._successor(node, capability, outcome, relax)
                if successor is not None:
                    return outcome, chosen_by, successor
        outcome = candidates[0]
        result.violations.append(self._broken_assumption(node, capability, outcome, chosen_by, len(result.steps) + 1))
        return outcome, chosen_by, None

    @property
    def proposed(self) -> str:
        """What the robot (or the script) answers for the state ``choose`` is asked about, with
        the sensors as they are now (``choose`` may change ``sensors``: an operator's)."""
        return self._proposal(*self._asked) if self._asked else ''

    def _proposal(self, capability: str, state: State, node: dict) -> str:
        """The outcome the script gives ``capability``, else the robot's first one the sensors allow."""
        if capability in self.script.outcomes:
            return self.script.outcomes[capability]
        preferred = self._preferred(capability, state)
        return next((o for o in preferred if self._successor(node, capability, o, False) is not None), preferred[0])

    def _preferred(self, capability: str, state: State) -> list[str]:
        """The capability's outcomes, its success first and its failure last."""
        rank = {outcome: index for index, outcome in enumerate(self.capabilities.transition_outcomes)}
        outcomes = [o for o in state.outcomes]
        return sorted(outcomes, key=lambda o: (o == FAILED, rank.get(self._transition(capability, o), len(rank))))

    def _transition(self, capability: str, outcome: str) -> str:
        try:
            return self.capabilities.transition_outcome(capability, outcome)
        except Exception:  # noqa: BLE001 -- an outcome without a mapping: no proposition reports it
            return ''

    def _successor(self, node: dict, capability: str, outcome: str, relax: bool) -> dict | None:
        """The strategy's next node after ``capability`` answers ``outcome``: its outcome
        proposition true, no other capability's, the sensors as they are (the script's). Where
        the assumptions change a sensor (a completed charge: the battery is no longer low), the
        environment's next reading is taken and kept."""
        reported = self.capabilities.outcome_proposition(capability, self._transition(capability, outcome))
        answers = []
        for name in node['transitions']:
            successor = self.nodes[str(name)]
            inputs = dict(zip(self.inputs, successor['input_valuation']))
            if inputs.get(reported) and not any(inputs.get(p) for p in self.outcome_propositions if p != reported):
                answers.append((successor, inputs))
        for successor, inputs in answers:
            if all(inputs.get(sensor, value) == value for sensor, value in self.sensors.items()):
                return successor
        if answers and relax:
            successor, inputs = answers[0]
            self.sensors.update({sensor: bool(inputs[sensor]) for sensor in self.sensors if sensor in inputs})
            return successor
        return None

    def _broken_assumption(self, node: dict, capability: str, outcome: str, chosen_by: str, step: int) -> str:
        """The sentence for an answer no assumption of the specification allows, naming the
        first environment formula it breaks."""
        current = {**dict(zip(self.inputs, node['input_valuation'])), **dict(zip(self.outputs, node['output_valuation']))}
        reported = self.capabilities.outcome_proposition(capability, self._transition(capability, outcome))
        following = {**current, **{p: p == reported for p in self.outcome_propositions}, **self.sensors}
        broken = ''
        for index, formula in enumerate(self.spec.env_trans):
            try:
                if not evaluate(formula, current, following):
                    broken = f'env_trans[{index}]: {to_infix(formula)}'
                    break
            except KeyError:  # names a variable the strategy does not show (a memory): not this one
                continue
        verb = 'forced' if chosen_by == CHOSEN_BY_OPERATOR else 'answered'
        who = chosen_by[0].upper() + chosen_by[1:]
        assumed = f'the task assumed {broken}' if broken else 'no assumption of the task allows it'
        sensors = f' with {self._sensors_text()}' if self.sensors else ''
        return f'{who} {verb} {outcome!r} on {capability} at step {step}{sensors}; {assumed}'

    def _initial_node(self) -> dict | None:
        for name in self.initial:
            node = self.nodes[str(name)]
            inputs = dict(zip(self.inputs, node['input_valuation']))
            if all(inputs.get(sensor, value) == value for sensor, value in self.script.sensors.items()):
                return node
        return None

    # the machine's move -----------------------------------------------------------------------

    def _check_activation(self, result: CapabilityRunResult, state: State, node: dict, step: int) -> None:
        capability = capability_of(state, self.capabilities)
        active = self._active(node)
        if active != capability:
            result.violations.append(
                f'the state machine broke a guarantee of the specification: at step {step + 1} it runs '
                f'{capability or state.state_path}, where the strategy activates {active or "nothing"}')

    def _active(self, node: dict) -> str:
        outputs = dict(zip(self.outputs, node['output_valuation']))
        return next((name for name in self.capabilities.capabilities
                     if outputs.get(activation(name))), '')

    def _output(self, node: dict, proposition: str) -> bool:
        return bool(dict(zip(self.outputs, node['output_valuation'])).get(proposition))

    def _sensors_text(self) -> str:
        return ', '.join(f'{name}={"true" if value else "false"}' for name, value in self.sensors.items())

    def _not_finished(self, steps: list[RunStep]) -> str:
        last = steps[-1]
        repeated = sum(1 for step in steps if (step.capability, step.outcome) == (last.capability, last.outcome))
        scripted = f' ({last.chosen_by}: --fail {last.capability}:{last.outcome})' if last.chosen_by == CHOSEN_BY_SCRIPT \
            else ''
        return (f'no outcome of the machine after {len(steps)} states: {last.capability} answered {last.outcome!r} '
                f'{repeated} times{scripted}, and the machine tries again each time')


def capability_of(state: State, capabilities) -> str:
    """The capability a state of a capability robot's machine runs: its name, or its name
    without the ``_N`` the generator adds when a capability has several states."""
    if state.name in capabilities.capabilities:
        return state.name
    base = re.sub(r'_\d+$', '', state.name)
    return base if base in capabilities.capabilities else ''
