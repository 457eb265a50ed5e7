"""The operator in the loop (RuntimeControl): autonomy, confirmation, forced outcomes, inputs,
pause and stop, on hand-made machines and a scripted robot; robot time stands still meanwhile."""

import collections

import pytest

from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.runtime_control import (FULL, HIGH, LOW, OFF, CommandError, OperatorStopError,
                                                 OperatorWaitLimitError, RuntimeControl, checked_command,
                                                 needs_confirmation)
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator.factory import make_simulator
from sm_generation import StateMachine
from respec.robot import robot_system

from hand_made_machines import ScriptedRobot, root, state

ATLAS = robot_system('atlas')

STAND_THEN_LOOK = [root('stand'),
                   {**state('/stand', 'stand_a', changed='look_down', failed='failed'), 'autonomy': [2, 0]},
                   {**state('/look_down', 'look_down_a', done='finished', failed='failed'), 'autonomy': [1, 0]}]


class Operator:
    """Commands the executive receives, each given once the executive waits for something
    (``script``: waiting kind -> commands), or at a robot tick (``at_tick``: tick -> commands)."""

    def __init__(self, robot, script=None, at_tick=None):
        self.robot, self.script = robot, collections.defaultdict(list, script or {})
        self.at_tick = at_tick or {}
        self.statuses, self.given = [], set()
        self.control = None

    def receive(self, timeout):
        waiting = self.control.waiting
        if waiting and self.script[waiting['kind']]:
            return [self.script[waiting['kind']].pop(0)]
        tick = self.robot.tick
        if tick in self.at_tick and tick not in self.given:
            self.given.add(tick)
            return list(self.at_tick[tick])
        if waiting:
            raise AssertionError(f'the executive waits for {waiting} and the operator has nothing to say')
        return []

    def make(self, level=FULL, **options):
        self.control = RuntimeControl(self.receive, self.statuses.append, autonomy_level=level, **options)
        return self.control


def test_flexbe_rule_a_transition_waits_unless_its_autonomy_is_below_the_level():
    assert needs_confirmation(2, HIGH) and not needs_confirmation(2, FULL)
    assert needs_confirmation(0, OFF) and not needs_confirmation(0, LOW)


def test_at_full_autonomy_nothing_waits_and_the_run_is_the_unattended_one():
    unattended = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), ScriptedRobot({'stand': (3, 'completed'),
                                                                       'look_down': (2, 'completed')}), ATLAS)
    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (2, 'completed')})
    operator = Operator(robot)
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(FULL))
    assert run.outcome == unattended.outcome == 'finished'
    assert run.trace.to_dict() == unattended.trace.to_dict()
    assert all(status['waiting'] is None for status in operator.statuses)


def test_a_high_transition_at_high_autonomy_waits_for_confirmation_and_robot_time_stands_still():
    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (2, 'completed')})
    operator = Operator(robot, script={'confirm': [{'command': 'confirm', 'state': '/stand'}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(HIGH))
    waits = [s['waiting'] for s in operator.statuses if s['waiting']]
    assert waits == [{'kind': 'confirm', 'state': '/stand', 'outcome': 'changed', 'required': 2,
                      'outcomes': ['changed', 'failed']}]  # look_down's done (Low) did not wait
    assert run.outcome == 'finished' and robot.tick == 5  # 3 + 2 ticks: no tick while waiting
    assert [s.entered_at for s in run.trace.steps] == [0.0, 0.3]
    assert run.operator_events == [{'command': 'confirm', 'state': '/stand'}]


def test_raising_the_level_lets_the_waiting_transition_go():
    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (2, 'completed')})
    operator = Operator(robot, script={'confirm': [{'command': 'autonomy', 'level': FULL}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(OFF))
    assert run.outcome == 'finished' and operator.control.autonomy_level == FULL


def test_forcing_another_outcome_at_a_waiting_transition_takes_it():
    robot = ScriptedRobot({'stand': (3, 'completed')})
    operator = Operator(robot, script={'confirm': [{'command': 'force', 'state': '/stand', 'outcome': 'failed'}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(HIGH))
    assert run.outcome == 'failed' and run.trace.steps[0].state_outcome == 'failed'
    # The trace says who chose it, and what the choice stands for (the trace check reads it so).
    assert (run.trace.steps[0].forced, run.trace.steps[0].forced_propositions) == ('failed', ['stand_f'])


def test_an_outcome_forced_while_the_state_runs_ends_it_at_once():
    robot = ScriptedRobot({'stand': (30, 'completed')})
    operator = Operator(robot, at_tick={4: [{'command': 'force', 'state': '/stand', 'outcome': 'failed'}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(FULL))
    assert run.outcome == 'failed' and robot.tick == 4
    assert run.trace.steps[0].ended_at == pytest.approx(0.4)
    assert (run.trace.steps[0].forced, run.trace.steps[0].forced_propositions) == ('failed', ['stand_f'])


def test_an_outcome_the_state_does_not_have_is_refused_and_the_run_goes_on():
    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (2, 'completed')})
    operator = Operator(robot, at_tick={1: [{'command': 'force', 'state': '/stand', 'outcome': 'nonsense'}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(FULL))
    assert run.outcome == 'finished'
    assert run.operator_events[-1]['command'] == 'refused' and 'nonsense' in run.operator_events[-1]['reason']


def test_pause_holds_the_robot_until_resume_and_stop_ends_the_run_with_its_trace():
    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (2, 'completed')})
    operator = Operator(robot, at_tick={2: [{'command': 'pause'}]}, script={'resume': [{'command': 'resume'}]})
    run = execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(FULL))
    assert run.outcome == 'finished' and robot.tick == 5
    assert {'kind': 'resume', 'state': '/stand'} in [s['waiting'] for s in operator.statuses]

    robot = ScriptedRobot({'stand': (3, 'completed'), 'look_down': (20, 'completed')})
    operator = Operator(robot, at_tick={2: [{'command': 'pause'}]}, script={'resume': [{'command': 'stop'}]})
    with pytest.raises(OperatorStopError) as stopped:
        execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=operator.make(FULL))
    assert stopped.value.item == '/stand' and [s.state for s in stopped.value.trace.steps] == ['/stand']
    assert robot.tick == 2


def test_a_wait_ends_at_the_wall_time_limit():
    robot = ScriptedRobot({'stand': (3, 'completed')})
    control = RuntimeControl(lambda timeout: [], autonomy_level=OFF)
    with pytest.raises(OperatorWaitLimitError) as limit:
        execute_state_machine(StateMachine.from_instantiations(STAND_THEN_LOOK), robot, ATLAS, control=control, max_wall_time=0.2)
    assert limit.value.item == '/stand' and 'waited for the operator: confirm' in str(limit.value)


def test_a_sensor_set_while_a_confirmation_waits_ends_the_wait_to_ask_again():
    """A capability robot's run: the operator's sensor changes the robot's answer, so the wait
    for the old one ends (None) and the caller asks again; a confirmation then goes on."""
    commands = [[{'command': 'sensor', 'name': 'battery_low', 'value': True}],
                [{'command': 'confirm', 'state': '/check'}]]
    control = RuntimeControl(lambda timeout: commands.pop(0) if commands else [], autonomy_level=OFF)
    assert control.confirm('/check', 'ok', 0, ['ok', 'low'], None, until=lambda: bool(control.sensors)) is None
    assert control.sensors == {'battery_low': True}
    control.sensors.clear()
    assert control.confirm('/check', 'low', 0, ['ok', 'low'], None, until=lambda: bool(control.sensors)) == 'low'
    assert control.waiting is None


def test_commands_are_checked():
    assert checked_command({'command': 'pause'}) == {'command': 'pause'}
    sensor = {'command': 'sensor', 'name': 'battery_low', 'value': None}   # a capability robot's, freed
    assert checked_command(sensor) == sensor
    for bad in [{'command': 'dance'}, {'command': 'autonomy', 'level': 7}, {'command': 'force', 'state': '/a'},
                {'command': 'confirm'}, 'pause', {'command': 'sensor', 'name': 'battery_low', 'value': 1},
                {'command': 'sensor', 'value': True}]:
        with pytest.raises(CommandError):
            checked_command(bad)


# --- InputState on the simulator: the user's answer reaches the actions that need it ---------------

PICK = [root('object_template'),
        state('/object_template', 'object_template_a', received='finished', aborted='failed')]


@pytest.mark.mujoco
def test_input_state_asks_the_operator_with_the_simulators_answer_offered():
    simulator = make_simulator(ATLAS, initial_conditions=['stand_prep'])
    asked = []

    def receive(timeout):
        waiting = control.waiting
        if waiting and waiting['kind'] == 'input' and not asked:
            asked.append(waiting)
            return [{'command': 'input', 'state': '/object_template', 'value': waiting['default']}]
        return []

    control = RuntimeControl(receive, autonomy_level=HIGH)
    run = execute_state_machine(StateMachine.from_instantiations(PICK), SimulatedRobot(simulator), ATLAS, control=control)
    assert asked == [{'kind': 'input', 'state': '/object_template', 'prompt': 'Specify desired object template',
                      'default': 1}]
    assert run.outcome == 'finished' and simulator.answers == {'template_id': 1}


@pytest.mark.mujoco
@pytest.mark.parametrize('answer', [None, 7, 'box'])
def test_an_aborted_or_invalid_input_fails_the_input_state(answer):
    simulator = make_simulator(ATLAS, initial_conditions=['stand_prep'])
    control = RuntimeControl(lambda timeout: [{'command': 'input', 'state': '/object_template', 'value': answer}]
                             if control.waiting else [], autonomy_level=LOW)
    run = execute_state_machine(StateMachine.from_instantiations(PICK), SimulatedRobot(simulator), ATLAS, control=control)
    assert run.outcome == 'failed'
    assert run.trace.steps[0].results[0]['reason'] == 'operator did not provide object_template'


@pytest.mark.mujoco
def test_at_full_autonomy_the_input_takes_the_robots_default_without_asking():
    simulator = make_simulator(ATLAS, initial_conditions=['stand_prep'])
    run = execute_state_machine(StateMachine.from_instantiations(PICK), SimulatedRobot(simulator), ATLAS, control=RuntimeControl(lambda timeout: []))
    assert run.outcome == 'finished' and simulator.answers == {'template_id': 1} and run.operator_events == []


def test_an_operator_decision_waits_with_its_suggestion_even_at_full_autonomy():
    """The generator's decision has Full autonomy, FlexBE's "always needs an operator input"."""
    from sm_generation.generator import DECISION_AUTONOMY
    assert DECISION_AUTONOMY == FULL
    machine = [root('choose_initial_state'),
               {'state_path': '/choose_initial_state', 'state_class': 'OperatorDecisionState',
                'outcomes': ['stand', 'nothing_to_do'], 'transitions': ['stand', 'nothing_to_do'],
                'autonomy': [DECISION_AUTONOMY] * 2},
               {'state_path': '/nothing_to_do', 'state_class': 'LogState', 'outcomes': ['done'],
                'transitions': ['finished'], 'autonomy': [0]},
               state('/stand', 'stand_a', changed='finished', failed='failed')]
    robot = ScriptedRobot({'stand': (2, 'completed')})
    operator = Operator(robot, script={'confirm': [{'command': 'confirm', 'state': '/choose_initial_state'}]})
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS, control=operator.make(FULL))
    assert [s['waiting']['outcome'] for s in operator.statuses if s['waiting']] == ['stand']  # the suggestion
    assert [s.state for s in run.trace.steps] == ['/choose_initial_state', '/stand']
    robot = ScriptedRobot({'stand': (2, 'completed')})
    operator = Operator(robot, script={'confirm': [{'command': 'force', 'state': '/choose_initial_state',
                                                    'outcome': 'nothing_to_do'}]})
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS, control=operator.make(FULL))
    assert [s.state for s in run.trace.steps] == ['/choose_initial_state', '/nothing_to_do'] and robot.tick == 0
