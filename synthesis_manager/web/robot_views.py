"""What each GUI surface asks of a robot, answered by its format: ``robot_view(robot)``.

A robot of our own format (a mode abstraction: control modes and actions) and a robot of CNU's
capability format (capabilities, memories, a spec file's sensors) offer different things to the
same surfaces. Each kind answers, behind one small interface, what the form offers (initial
conditions, goals and whether each can come next, sensors), what the abstraction panel draws
(the control-mode graph, or the capability graph) and how a simulated robot answers a running
state (atlas_sim's MuJoCo ATLAS, or the capability robot of
``atlas_sim.executive.capability_run``). The shell asks the view, not the kind:

    view = robot_view(robot)
    view.choices()                      # GET /api/systems/{name}
    view.impossible_next(initial, goals, strict_order)
    view.simulation_support(can_simulate)
    view.simulator                      # the child's function in web/simulation_process.py
"""

from __future__ import annotations

import re

from ltl_specification.capability_precheck import clause_text
from ltl_specification.diagnosis import impossible_next_goals
from ltl_specification.systems import load_task_abstraction
from respec.vocabulary.naming import DEFAULT_SM_OUTCOMES, FINISHED
from respec.robot import RobotSystem, for_description
from respec.robot.abstraction import RobotAbstraction
from respec.robot.cnu import CapabilitySystem
from respec.robot.files import SystemConfigError
from synthesis_manager.web.jobs import JOB_OPTIONS

ATLAS_SIMULATOR, CAPABILITY_SIMULATOR = 'simulate', 'simulate_capability_robot'


class ModeRobotView:
    """A robot of our own format: control modes, actions with their preconditions, atlas_sim."""

    drawing = 'modes'
    simulator = ATLAS_SIMULATOR

    def __init__(self, robot: RobotSystem):
        self.robot = robot

    def choices(self) -> dict:
        abstraction = load_task_abstraction(self.robot)
        modes, actions = abstraction.control_modes, abstraction.actions
        predecessors = {mode: [other for other, after in modes.items() if other != mode and mode in after]
                        for mode in modes}
        needs = {action: f'needs: {", ".join(pre) or "nothing"}' for action, pre in actions.items()}
        return {
            'control_modes': [{'name': m, 'next': list(n)} for m, n in modes.items()],
            'actions': [{'name': a, 'preconditions': list(p)} for a, p in actions.items()],
            'initial_groups': [
                {'title': 'Control mode (one)', 'type': 'radio', 'items': [
                    {'name': m, 'hint': f'next: {", ".join(n) or "—"}'} for m, n in modes.items()]},
                {'title': 'Actions (already completed)', 'type': 'checkbox', 'items': [
                    {'name': a, 'hint': hint} for a, hint in needs.items()]}],
            'goal_groups': [
                {'label': 'Actions', 'items': [{'name': a, 'hint': hint} for a, hint in needs.items()]},
                {'label': 'Control modes', 'items': [
                    {'name': m, 'hint': f'reached from: {", ".join(predecessors[m]) or "no other mode"}'}
                    for m in modes]}],
            'default_initial_conditions': list(self.robot.default_initial_conditions),
            'sensors': [],
            'failure_names': [*actions, *modes],
        }

    def impossible_next(self, initial_conditions, goals, strict_order: bool) -> dict[str, str]:
        return impossible_next_goals(self.robot, initial_conditions, goals, strict_order)

    def simulation_support(self, can_simulate: bool) -> dict:
        if not can_simulate:
            return {'available': False, 'note': 'Simulation needs atlas_sim and MuJoCo, which are not installed.'}
        try:
            section = self.robot.section('simulation')
        except SystemConfigError:
            return {'available': False,
                    'note': f'{self.robot.name} has no simulation section: atlas_sim cannot run it.'}
        if section.get('stand_in'):
            return {'available': False,
                    'note': f'No simulation for {self.robot.name}: {" ".join(str(section["stand_in"]).split())}'}
        return {'available': True, 'note': '', 'frames': True, 'simulator': 'atlas_sim: MuJoCo humanoid',
                'faults': 'the first attempt of this capability fails (fault injection)'}


class CapabilityRobotView:
    """A robot of CNU's capability format: what its capabilities make true, its memories and
    sensors, its capability graph; simulated without physics (each state answers an outcome)."""

    drawing = 'capabilities'
    simulator = CAPABILITY_SIMULATOR

    def __init__(self, robot: RobotSystem):
        self.robot = robot
        self.capabilities = robot.required_capabilities()

    def choices(self) -> dict:
        capabilities = self.capabilities
        starts = [{'name': name, 'hint': f'memory, {"true" if value else "false"} unless chosen'}
                  for name, value in capabilities.memory.items()]
        starts += [{'name': name, 'hint': f'sensor: {self._reporters_text(name)}'} for name in capabilities.spec_inputs]
        return {
            'control_modes': [],
            'actions': [{'name': name, 'preconditions': [clause_text(c) for c in capability.preconditions]}
                        for name, capability in capabilities.capabilities.items()],
            'initial_groups': [{'title': 'Holds at the start (memories and sensors)', 'type': 'checkbox',
                                'items': starts}],
            'initial_note': self._initial_note(),
            'goal_groups': [
                {'label': 'Made true by a capability', 'items': [
                    {'name': goal, 'hint': f'set by {", ".join(setters)}'} for goal, setters in self.goals().items()]},
                {'label': 'Must not hold at the end', 'items': [
                    {'name': goal, 'hint': f'{goal[1:]} is false at the end'} for goal in self.negated_goals()]}],
            'default_initial_conditions': list(self.robot.default_initial_conditions),
            'sensors': [{'name': name, 'reported_by': self.reporters(name)} for name in capabilities.spec_inputs],
            'capability_graph': self.graph(),
            'failure_names': list(capabilities.capabilities),
        }

    def goals(self) -> dict[str, list[str]]:
        """What the capabilities can make true (their postconditions' terms, in file order), each
        with who sets it ('check_battery on low')."""
        goals: dict[str, list[str]] = {}
        for name, capability in self.capabilities.capabilities.items():
            for outcome, literals in capability.postconditions.items():
                for literal in literals:
                    goals.setdefault(clause_text((literal,)), []).append(f'{name} on {outcome}')
        return goals

    def negated_goals(self) -> list[str]:
        """What may also be asked not to hold at the end (CNU's goals may be negated): the
        negation of each goal no capability makes false itself."""
        goals = self.goals()
        return [f'!{goal}' for goal in goals if not goal.startswith('!') and f'!{goal}' not in goals]

    def graph(self) -> dict:
        """The capability graph: each capability with the propositions its preconditions need
        and those its outcomes make true or false (the drawing's data)."""
        return {'capabilities': [
            {'name': name,
             'needs': [{'name': term.name, 'negated': term.negated, 'text': clause_text(clause)}
                       for clause in capability.preconditions for term in clause],
             'makes': [{'name': term.name, 'negated': term.negated, 'outcome': outcome, 'text': clause_text((term,))}
                       for outcome, literals in capability.postconditions.items() for term in literals]}
            for name, capability in self.capabilities.capabilities.items()],
            'initially': [name for name, value in self.capabilities.memory.items() if value],
            'sensors': [{'name': name, 'reported_by': self.reporters(name)} for name in self.capabilities.spec_inputs]}

    def reporters(self, sensor: str) -> list[str]:
        """The capabilities whose outcome the spec file binds to ``sensor`` (an ENV_TRANS
        'check_battery_l' <-> (check_battery_a & battery_low')')."""
        found = []
        for section, text in self.capabilities.spec_formulas:
            words = set(re.findall(r'[A-Za-z_][A-Za-z0-9_]*', text))
            if section != 'env_trans' or '<->' not in text or sensor not in words:
                continue
            for name in self.capabilities.capabilities:
                outcomes = {self.capabilities.outcome_proposition(name, outcome)
                            for outcome in self.capabilities.transition_outcomes}
                if words & outcomes and name not in found:
                    found.append(name)
        return found

    def _reporters_text(self, sensor: str) -> str:
        reporters = self.reporters(sensor)
        return f'reported by {", ".join(reporters)}' if reporters else 'reported by no capability'

    def _initial_note(self) -> str:
        spec = list(self.capabilities.spec_initial)
        return (f'Unchecked, the robot starts as its spec says ({", ".join(spec)}) with its memories at their '
                'initial values.' if spec else 'Unchecked, the robot starts with its memories at their initial values.')

    def impossible_next(self, initial_conditions, goals, strict_order: bool) -> dict[str, str]:
        return impossible_next_goals(self.robot, initial_conditions, goals, strict_order,
                                     candidates=[*self.goals(), *self.negated_goals()])

    def simulation_support(self, can_simulate: bool) -> dict:
        del can_simulate  # no physics: nothing to install
        return {'available': True, 'note': '', 'frames': False, 'sensors': list(self.capabilities.spec_inputs),
                'simulator': 'a simulated capability robot: each state answers one of its outcomes, no physics',
                'faults': 'this capability answers the outcome it fails with, every time (fault injection)'}


_VIEWS: dict[type, type[ModeRobotView] | type[CapabilityRobotView]] = {
    RobotAbstraction: ModeRobotView, CapabilitySystem: CapabilityRobotView}


def robot_view(robot: RobotSystem) -> ModeRobotView | CapabilityRobotView:
    """The view of ``robot`` for the GUI's surfaces, by the format that describes it (a file
    without a description gets the mode view, which names what is missing)."""
    return for_description(_VIEWS, robot, missing=ModeRobotView)(robot)


def common_choices(robot: RobotSystem, view) -> dict:
    """The form's choices of ``robot`` (GET /api/systems/{name}): its view's and the request's own."""
    return {'system': robot.name, 'drawing': view.drawing, **view.choices(),
            'sm_outcome_choices': [list(DEFAULT_SM_OUTCOMES), [FINISHED]], 'options': list(JOB_OPTIONS)}
