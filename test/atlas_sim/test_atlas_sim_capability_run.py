"""A simulated capability robot (issue 45, item 3): `execute --system <capability robot>` ran
nothing ("delivery_rover.yaml has no abstraction: section"). Each running state now answers one
of its capability's outcomes (its success, a scripted one, or what a scripted sensor implies),
and the run is checked in lockstep with the strategy: the script's or the operator's answers
against the assumptions, the machine's moves against the strategy."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from atlas_sim.executive.capability_run import (CHOSEN_BY_OPERATOR, CHOSEN_BY_ROBOT, CHOSEN_BY_SCRIPT, CapabilityRun,
                                                ScriptError, parse_script)
from ltl_specification import compile_task
from ltl_synthesizer import synthesize
from respec.automaton import automaton_from_strategy
from respec.robot import robot_system
from respec.robot.state_library import StateClass, capability_outcomes
from sm_generation import generate_state_machine
from sm_generation.automaton_io import automaton_to_dict

CLI = str(Path(sys.executable).parent / 'behavior-synthesis')
LIBRARY = {'LogState': StateClass('LogState', 'flexbe_states', ('text',), ('text',), outcomes=('done',)),
           'TryState': StateClass('TryState', 'test_states', ('text',), ('text',), outcomes=('done', 'failed')),
           'LookState': StateClass('LookState', 'test_states', ('text',), ('text',), outcomes=('done', 'low'))}
# A cart of our own: it checks its battery (a sensor decides), charges when low, then moves (which can fail).
CART = {
    'name': 'cart',
    'memory': {'sys_props': {'battery_ok': False}},
    'capabilities': {
        'check': {'interface': 'LookState', 'parameters': {'text': 'battery?'},
                  'postconditions': {'completed': ['battery_ok'], 'low': ['!battery_ok']},
                  'transition_relation': {'low': ['charge']}},
        'charge': {'interface': 'LogState', 'parameters': {'text': 'charging'}, 'preconditions': ['!battery_ok'],
                   'postconditions': {'completed': ['battery_ok']}},
        'move': {'interface': 'TryState', 'parameters': {'text': 'moving'}, 'preconditions': ['battery_ok'],
                 'postconditions': {'completed': ['move']}},
    },
}
SPEC = {'specs': {'INPUT': ['battery_low'], 'SYS_INIT': ['check_a'],
                  'ENV_TRANS': ["check_l' <-> (check_a & battery_low')", "check_c' <-> (check_a & !battery_low')",
                                "charge_c' -> !battery_low'"],
                  'ENV_LIVENESS': ['!battery_low']}}
MAPPINGS = {'state_outcome_mappings': {'done': 'completed', 'low': 'low', 'failed': 'failure'},
            'sm_outcome_mappings': {'finished': 'finished', 'failed': 'failed'},
            'transition_outcomes': ['completed', 'low', 'failure']}


@pytest.fixture
def cart(tmp_path):
    for name, document in (('capabilities', CART), ('spec', SPEC), ('mappings', MAPPINGS)):
        (tmp_path / f'cart_{name}.yaml').write_text(yaml.safe_dump(document))
    (tmp_path / 'cart.yaml').write_text('system: cart\ncnu_capabilities: cart_capabilities.yaml\n'
                                        'cnu_spec: cart_spec.yaml\ncnu_mappings: cart_mappings.yaml\n')
    return robot_system('cart', tmp_path)


def run(system, sm_outcomes=('finished', 'failed'), fails=(), sensors=(), choose=None):
    spec = compile_task(system, [], ['move'], sm_outcomes=list(sm_outcomes), state_library=LIBRARY)
    automaton = automaton_from_strategy(synthesize(spec).strategy, spec)
    machine = generate_state_machine(automaton, system, state_library=LIBRARY)
    script = parse_script(system.capabilities, capability_outcomes(system.capabilities, LIBRARY), list(fails),
                          list(sensors))
    return CapabilityRun(machine, automaton_to_dict(automaton), system.capabilities, spec, script, choose=choose).run()


def answers(result):
    return [(step.capability, step.outcome, step.chosen_by) for step in result.steps]


def test_each_state_answers_its_success_and_the_run_is_what_the_specification_promises(cart):
    result = run(cart)
    assert result.outcome == 'finished' and not result.violations
    assert answers(result) == [('check', 'done', CHOSEN_BY_ROBOT), ('move', 'done', CHOSEN_BY_ROBOT)]


def test_a_scripted_sensor_decides_what_reads_it_and_the_environment_changes_it(cart):
    result = run(cart, sensors=['battery_low'])
    assert result.outcome == 'finished' and not result.violations
    assert [a[:2] for a in answers(result)] == [('check', 'low'), ('charge', 'done'), ('move', 'done')]


def test_a_scripted_failure_ends_in_failed_or_is_retried_until_the_step_limit(cart):
    failed = run(cart, fails=['move'])
    assert failed.outcome == 'failed' and answers(failed)[-1] == ('move', 'failed', CHOSEN_BY_SCRIPT)
    retried = run(cart, sm_outcomes=['finished'], fails=['move:failed'])
    assert retried.outcome is None and not retried.violations
    assert "move answered 'failed'" in retried.not_finished and '--fail move:failed' in retried.not_finished


def test_an_answer_the_assumptions_forbid_is_named_with_its_step_and_who_chose_it(cart):
    result = run(cart, fails=['check:low'], sensors=['battery_low=false'])
    assert result.outcome is None and len(result.violations) == 1
    violation = result.violations[0]
    assert violation.startswith("The script answered 'low' on check at step 1 with battery_low=false")
    assert "the task assumed env_trans" in violation and "next(check_l) <-> check_a & next(battery_low)" in violation
    forced = run(cart, sensors=['battery_low=false'], choose=lambda path, outcomes: 'low' if path == '/check' else None)
    assert forced.violations[0].startswith("The operator forced 'low' on check at step 1")
    assert answers(forced) == [('check', 'low', CHOSEN_BY_OPERATOR)]


@pytest.mark.parametrize('fail, sensor, said', [
    ('fly', None, "'fly' is no capability of cart"), ('move:crash', None, "'crash' is no outcome of move (done, failed)"),
    ('check', None, 'check has no outcome it fails with'), (None, 'door', "'door' is no sensor (spec INPUT) of cart"),
    (None, 'battery_low=maybe', 'the value must be true or false')])
def test_a_bad_script_entry_is_named(cart, fail, sensor, said):
    with pytest.raises(ScriptError, match=said.replace('(', r'\(').replace(')', r'\)')):
        parse_script(cart.capabilities, capability_outcomes(cart.capabilities, LIBRARY), [fail] if fail else [],
                     [sensor] if sensor else [])


@pytest.mark.ros
@pytest.mark.flexbe
def test_execute_runs_the_delivery_rover_and_names_a_scripted_failure(flexbe):
    environment = dict(os.environ, AMENT_PREFIX_PATH=str(flexbe), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')

    def execute(*arguments):
        done = subprocess.run([CLI, 'execute', '--system', 'delivery_rover', '--goals', 'hand_over', '--json',
                               *arguments], capture_output=True, text=True, timeout=300, env=environment)
        return done.returncode, json.loads(done.stdout), done.stderr

    status, report, _ = execute()
    assert status == 0 and report['outcome'] == 'finished' and report['trace_check'] == {'ok': True, 'violations': []}
    status, report, stderr = execute('--sm-outcomes', 'finished', '--fail', 'drive:failed')
    assert status == 8 and report['outcome'] is None  # NOT_FINISHED, as --help says
    assert "drive answered 'failed'" in stderr and '--fail drive:failed' in stderr
    status, report, _ = execute('--fail', 'check_battery:low', '--sensor', 'battery_low=false')
    assert status == 7 and "The script answered 'low' on check_battery" in report['trace_check']['violations'][0]


@pytest.mark.ros
@pytest.mark.flexbe
def test_execute_runs_the_shelf_picker_the_second_shipped_capability_robot(flexbe):
    """config/shelf_picker (issue 45, item 6): its look reports a sensor and its grasp can fail."""
    environment = dict(os.environ, AMENT_PREFIX_PATH=str(flexbe), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')

    def execute(*arguments):
        done = subprocess.run([CLI, 'execute', '--system', 'shelf_picker', '--goals', 'place', '--json', *arguments],
                              capture_output=True, text=True, timeout=300, env=environment)
        return done.returncode, json.loads(done.stdout), done.stderr

    status, report, _ = execute()
    assert status == 0 and report['outcome'] == 'finished' and report['trace_check']['ok']
    assert [step['capability'] for step in report['steps']] == ['look', 'grasp', 'place']
    status, report, _ = execute('--fail', 'grasp')          # the grasp fails: the machine ends failed
    assert status == 6 and report['outcome'] == 'failed' and report['steps'][-1]['chosen_by'] == 'the script'
    status, report, stderr = execute('--sensor', 'item_on_shelf=false')   # never restocked: looks forever
    assert status == 8 and "look answered 'empty' 200 times" in stderr
