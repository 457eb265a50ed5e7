"""The executive on hand-made state machines: FlexBE semantics, the robot protocol, errors."""

import pytest

from atlas_sim.executive.executor import ExecutionLimitError, UnmappedStateError, execute_state_machine
from atlas_sim.executive.errors import UndeclaredOutcomeError
from atlas_sim.executive.trace_check import check_trace
from atlas_sim.simulated_robot import SimulatedRobot
from atlas_sim.simulator.factory import FaultSpecError, InitialConditionError, make_simulator, parse_faults
from ltl_specification import compile_task
from sm_generation import SMGenerationError, StateInstantiation, StateMachine
from respec.robot import robot_system

from hand_made_machines import ScriptedRobot, root, state

ATLAS = robot_system('atlas')

pytestmark = pytest.mark.mujoco


def container(path, conditions, **transitions):
    """conditions: (container outcome, {child: outcome}) in FlexBE's order."""
    return {'state_path': path, 'state_class': ':CONCURRENCY', 'outcomes': list(transitions),
            'transitions': list(transitions.values()), 'cond_outcome': [o for o, _ in conditions],
            'cond_transition': [{'state_name': list(c), 'state_outcome': list(c.values())}
                                for _, c in conditions]}


PICKUP_TAIL = [state('/look_down', 'look_down_a', done='manipulate', failed='failed'),
               state('/manipulate', 'manipulate_a', changed='pickup_object', failed='failed'),
               state('/pickup_object', 'pickup_object_a', finished='finished', failed='failed')]


@pytest.fixture(scope='module')
def pickup_spec():
    return compile_task(ATLAS, ['stand_prep'], ['look_down', 'pickup_object'])


# --- FlexBE semantics on the simulator ---------------------------------------------------------------

def concurrent_start(conditions, **transitions):
    return [container('/object_template_and_stand', conditions, **transitions),
            state('/object_template_and_stand/object_template', 'object_template_a',
                  received='template_done', aborted='failed_inside'),
            state('/object_template_and_stand/stand', 'stand_a', changed='both_done', failed='failed_inside')]


def test_a_container_returns_on_its_first_holding_condition_and_running_states_carry_over(pickup_spec):
    machine = [root('object_template_and_stand'),
               *concurrent_start([('both_done', {'object_template': 'received', 'stand': 'changed'}),
                                  ('template_done', {'object_template': 'received'}),
                                  ('failed_inside', {'stand': 'failed'})],
                                 both_done='look_down', template_done='stand', failed_inside='failed'),
               state('/stand', 'stand_a', changed='look_down', failed='failed'), *PICKUP_TAIL]
    simulator = make_simulator(ATLAS, initial_conditions=['stand_prep'])
    run = execute_state_machine(StateMachine.from_instantiations(machine), SimulatedRobot(simulator), ATLAS)
    assert run.outcome == 'finished'
    first, second = run.trace.steps[:2]
    assert first.activated == ['object_template_a', 'stand_a'] and first.state_outcome == 'template_done'
    assert [r['capability'] for r in first.results] == ['object_template']
    # /stand keeps the stand transition started by the container instead of starting another
    assert second.state == '/stand' and second.results[0]['capability'] == 'stand'
    assert [r.name for r in simulator.history].count('stand') == 1
    assert [s.state for s in run.trace.steps] == ['/object_template_and_stand', '/stand', '/look_down',
                                                   '/manipulate', '/pickup_object']
    report = check_trace(run.trace, pickup_spec)
    assert report.ok, report.summary()


def test_a_container_waits_until_a_condition_holds(pickup_spec):
    machine = [root('object_template_and_stand'),
               *concurrent_start([('both_done', {'object_template': 'received', 'stand': 'changed'}),
                                  ('failed_inside', {'stand': 'failed'})],
                                 both_done='look_down', failed_inside='failed'),
               *PICKUP_TAIL]
    machine[1]['outcomes'], machine[1]['transitions'] = ['both_done', 'failed_inside'], ['look_down', 'failed']
    machine[2]['outcomes'], machine[2]['transitions'] = ['received'], ['both_done']
    run = execute_state_machine(StateMachine.from_instantiations(machine), SimulatedRobot(make_simulator(ATLAS)), ATLAS)
    first = run.trace.steps[0]
    assert first.state_outcome == 'both_done' and first.ended_at >= 1.5  # stand takes 1.5 s
    assert sorted(first.outcomes_at_exit) == ['obj_detected', 'object_template_c', 'stand_c']
    assert run.outcome == 'finished' and check_trace(run.trace, pickup_spec).ok


def test_dataclasses_and_dicts_run_the_same():
    machine = [root('stand'), state('/stand', 'stand_a', changed='walk', failed='failed'),
               state('/walk', 'walk_a', changed='finished', failed='failed')]
    from_dicts = execute_state_machine(StateMachine.from_instantiations(machine), SimulatedRobot(make_simulator(ATLAS)), ATLAS)
    objects = [StateInstantiation.from_dict(entry) for entry in machine]
    from_objects = execute_state_machine(StateMachine.from_instantiations(objects), SimulatedRobot(make_simulator(ATLAS)), ATLAS)
    assert from_dicts.trace.to_dict() == from_objects.trace.to_dict()
    assert from_dicts.outcome == 'finished' and from_dicts.trace.steps[-1].mode_at_exit == 'walk'


def test_a_failing_capability_takes_the_failure_transition():
    machine = [root('stand'), state('/stand', 'stand_a', changed='walk', failed='failed'),
               state('/walk', 'walk_a', changed='finished', failed='failed')]
    simulator = make_simulator(ATLAS, faults=parse_faults(fail=['walk']))
    run = execute_state_machine(StateMachine.from_instantiations(machine), SimulatedRobot(simulator), ATLAS)
    assert run.outcome == 'failed'
    assert run.trace.steps[-1].results[0]['reason'].startswith('injected fault')
    assert 'walk_f' in run.trace.steps[-1].outcomes_at_exit


# --- with a scripted robot --------------------------------------------------------------------------

def test_an_abandoned_request_is_recorded_and_the_check_blames_the_robot(pickup_spec):
    machine = [root('object_template_and_stand'),
               *concurrent_start([('template_done', {'object_template': 'received'})],
                                 template_done='object_template'),
               state('/object_template', 'object_template_a', received='failed', aborted='failed')]
    machine[2]['outcomes'], machine[2]['transitions'] = ['received'], ['template_done']
    robot = ScriptedRobot({'object_template': [(1, 'completed'), (5, 'completed')], 'stand': (3, 'completed')})
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS)
    second = run.trace.steps[1]
    assert second.results[0] == {'capability': 'stand', 'outcome': 'completed', 'reason': 'scripted',
                                 'time': 0.3, 'abandoned': True}
    assert 'stand_c' in second.outcomes_at_exit and 'stand_prep_c' not in second.outcomes_at_exit
    report = check_trace(run.trace, pickup_spec)
    # the mode changed while no state activated it: an assumption of the spec (eq. (12)) broke
    violation = next(v for v in report.violations if v.kind == 'env_trans')
    assert violation.step == 1
    assert 'stand_prep_c & !stand_prep_a & !stand_a & !manipulate_a -> next(stand_prep_c)' in violation.formulas


def test_sensor_states_return_when_the_sensor_turns_true():
    machine = [root('look_down_and_obj_detected'),
               container('/look_down_and_obj_detected', [('seen', {'obj_detected': 'found'}),
                                                         ('looked', {'look_down': 'done'})],
                         seen='finished', looked='failed'),
               state('/look_down_and_obj_detected/look_down', 'look_down_a', done='looked'),
               state('/look_down_and_obj_detected/obj_detected', 'obj_detected', found='seen')]
    robot = ScriptedRobot({'look_down': (10, 'completed')}, mode='stand', sensors_at={'obj_detected': 4})
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS)
    assert run.outcome == 'finished' and robot.tick == 4
    assert run.trace.steps[0].activated == ['look_down_a']  # sensors are not activated
    assert 'obj_detected' in run.trace.steps[0].outcomes_at_exit


def test_helper_states_take_no_robot_time_and_decisions_use_the_hook():
    machine = [root('choose_initial_state'),
               {'state_path': '/choose_initial_state', 'state_class': 'OperatorDecisionState',
                'outcomes': ['stand', 'nothing_to_do'], 'transitions': ['stand', 'nothing_to_do']},
               {'state_path': '/nothing_to_do', 'state_class': 'LogState', 'outcomes': ['done'],
                'transitions': ['finished']},
               state('/stand', 'stand_a', changed='finished', failed='failed')]
    robot = ScriptedRobot({'stand': (2, 'completed')})
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS)  # default: the first outcome
    assert run.outcome == 'finished' and robot.started == [(0, 'stand')]
    robot = ScriptedRobot({})
    asked = []
    run = execute_state_machine(StateMachine.from_instantiations(machine), robot, ATLAS, decide=lambda path, outcomes: asked.append(path) or outcomes[1])
    assert run.outcome == 'finished' and robot.tick == 0 and asked == ['/choose_initial_state']
    assert [s.state for s in run.trace.steps] == ['/choose_initial_state', '/nothing_to_do']


# --- errors ---------------------------------------------------------------------------------------

def test_a_run_without_outcome_hits_the_robot_time_limit():
    machine = [root('stand'), state('/stand', 'stand_a', changed='finished', failed='failed')]
    with pytest.raises(ExecutionLimitError) as error:
        execute_state_machine(StateMachine.from_instantiations(machine), ScriptedRobot({}), ATLAS, max_robot_time=2.0)
    assert error.value.item == '/stand' and error.value.code == 'TIMEOUT'
    assert len(error.value.trace.steps) == 1 and 'robot time' in str(error.value)


def test_an_undeclared_outcome_names_the_state():
    machine = [root('stand'), state('/stand', 'stand_a', changed='finished')]  # no 'failed' outcome
    with pytest.raises(UndeclaredOutcomeError) as error:
        execute_state_machine(StateMachine.from_instantiations(machine), ScriptedRobot({'stand': (1, 'failed')}), ATLAS)
    assert error.value.item == '/stand' and "'failed'" in str(error.value)


def test_an_unmapped_state_names_the_state():
    machine = [root('dance'), {'state_path': '/dance', 'state_class': 'DanceState', 'outcomes': ['done'],
                               'transitions': ['finished']}]
    with pytest.raises(UnmappedStateError) as error:
        execute_state_machine(StateMachine.from_instantiations(machine), ScriptedRobot({}), ATLAS)
    assert error.value.item == '/dance' and 'DanceState' in str(error.value)
    wrong_parameter = state('/stand', 'stand_a', changed='finished', failed='failed')
    wrong_parameter['parameter_values'] = ['ChangeControlModeActionState.FLY']
    with pytest.raises(UnmappedStateError) as error:
        execute_state_machine(StateMachine.from_instantiations([root('stand'), wrong_parameter]), ScriptedRobot({}), ATLAS)
    assert error.value.item == '/stand'


@pytest.mark.parametrize('machine, item', [
    ([state('/stand', 'stand_a', changed='finished')], '/'),
    ([root('walk'), state('/stand', 'stand_a', changed='finished')], 'walk'),
    ([root('stand'), state('/stand', 'stand_a', changed='nowhere')], '/stand'),
    ([root('stand'), state('/stand/inner', 'stand_a', changed='x'),
      state('/stand', 'stand_a', changed='finished')],
     '/stand/inner'),
    ([root('c'), container('/c', [('x', {'ghost': 'done'})], x='finished'),
      state('/c/stand', 'stand_a', changed='x')], '/c'),
])
def test_invalid_machines_name_the_offending_entry(machine, item):
    """A list the executive could not run is refused where it becomes the tree."""
    with pytest.raises(SMGenerationError) as error:
        StateMachine.from_instantiations(machine)
    assert error.value.item == item


# --- simulator set-up -------------------------------------------------------------------------------

def test_make_simulator_starts_in_the_initial_conditions():
    simulator = make_simulator(ATLAS, initial_conditions=['manipulate', 'object_template'])
    assert simulator.mode == 'manipulate' and simulator.completed_actions() == ['object_template']
    assert simulator.execute('pickup_object').completed  # its preconditions hold from the start
    assert not simulator.has_fallen()


@pytest.mark.parametrize('conditions, item', [(['fly'], 'fly'), (['stand', 'walk'], 'walk')])
def test_make_simulator_rejects_bad_initial_conditions(conditions, item):
    with pytest.raises(InitialConditionError) as error:
        make_simulator(ATLAS, initial_conditions=conditions)
    assert error.value.item == item


def test_parse_faults():
    assert parse_faults(['walk'], ['pickup_object:2'], ['stand:0.5']) == {
        'walk': {'always': True}, 'pickup_object': {'fail_first': 2}, 'stand': {'probability': 0.5}}
    with pytest.raises(FaultSpecError) as error:
        parse_faults(fail_first=['pickup_object'])
    assert error.value.item == 'pickup_object'
    with pytest.raises(FaultSpecError) as error:
        make_simulator(ATLAS, faults=parse_faults(fail=['fly']))
    assert error.value.item == 'fly'
