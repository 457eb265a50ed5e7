"""Synthesis on the fly through ROS: initial conditions read from the atlas_sim node's state topic.

The suite's nodes, the simulator node and the clients run in one harness (or in the
``behavior-synthesis execute`` command, which starts them in-process the same way).
"""

from argparse import Namespace
import json
import threading
import time

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.trace_check import check_trace
from ltl_specification.initial_conditions import initial_conditions_in_status
from respec.parsing import spec_from_text_sections
from synthesis_manager.programs.cli import main as cli_main
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
from synthesis_manager.ros.atlas_sim_robot import RosRobot
from synthesis_manager.suite import suite_node_factories
from respec.robot import robot_system

pytestmark = pytest.mark.ros

TASK_1 = ['look_down', 'pickup_object']
AFTER_TASK_1 = ['manipulate', 'look_down', 'object_template', 'pickup_object']  # in any action order


def start_suite(ros, tmp_path, **settings):
    """The suite's nodes (with ``settings`` as the command line would give them) and a client."""
    args = Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='builtin',
                     slugs_executable='slugs', synthesis_timeout=60.0, service_timeout=2.0, **settings)
    for factory in suite_node_factories(args):
        ros.add_node(factory)
    client = SynthesisClient(ros.add_node(Node, 'on_the_fly_client'))
    assert client.wait_for_server(timeout=10.0)
    return client


def cnu_client(ros):
    """A client of CNU's FlexBESynthesis interface, served by the same server."""
    client = SynthesisClient(ros.add_node(Node, 'on_the_fly_cnu_client'), 'flexbe_synthesis')
    assert client.wait_for_server(timeout=10.0)
    return client


def synthesize(client, initial_conditions, goals):
    """Run a goal; returns the outcome and the initial conditions the server reported detecting."""
    statuses = []
    outcome = client.run(make_goal('atlas', initial_conditions, goals), timeout=120.0,
                         feedback=lambda status, _: statuses.append(status))
    detected = next(filter(None, map(initial_conditions_in_status, statuses)), None)
    return outcome, detected


def execute(outcome, robot, goals):
    run = execute_state_machine(outcome.machine, robot, robot_system('atlas'), max_wall_time=120.0)
    report = check_trace(run.trace, spec_from_text_sections(outcome.ltl_specification), goals=goals)
    assert report.ok, report.summary()
    return run


@pytest.mark.mujoco  # the robot is simulated in this process
def test_paper_second_demo_on_the_fly(ros, tmp_path):
    """Task 1, then footstep_execution with no initial conditions: it starts from manipulate."""
    client = start_suite(ros, tmp_path)
    ros.add_node(AtlasSimNode, parameter_overrides=[Parameter('speed', value=20.0),
                                                    Parameter('state_rate', value=50.0)])
    robot = RosRobot(ros.add_node(Node, 'executive'))
    robot.wait_until_ready()

    first, detected = synthesize(client, ['stand_prep'], TASK_1)
    assert first.succeeded and detected is None  # named initial conditions are used as they are
    assert execute(first, robot, TASK_1).outcome == 'finished'

    # CNU's interface with empty initial_conditions: the result's messages say what was used
    cnu = cnu_client(ros).run(make_flexbe_goal('atlas', [], ['footstep_execution']), timeout=120.0)
    assert cnu.succeeded, cnu.message
    source, initial_conditions = initial_conditions_in_status(cnu.message)
    assert source == 'atlas_sim/state' and sorted(initial_conditions) == sorted(AFTER_TASK_1)

    second, detected = synthesize(client, [], ['footstep_execution'])
    assert second.states == cnu.states  # the same robot state, the same behavior
    assert second.succeeded, second.message
    source, initial_conditions = detected
    assert source == 'atlas_sim/state'
    assert initial_conditions[0] == 'manipulate' and sorted(initial_conditions) == sorted(AFTER_TASK_1)
    assert 'manipulate_c' in second.ltl_specification['env_init']
    run = execute(second, robot, ['footstep_execution'])  # the trace check includes env_init
    assert run.outcome == 'finished'
    assert run.trace.steps[0].mode_at_entry == 'manipulate'
    assert 'pickup_object' not in [c for step in run.trace.steps for c in step.capabilities]


@pytest.mark.parametrize('initial_conditions', ['', 'current'])
def test_no_robot_state_is_a_clear_error_naming_the_topic(ros, tmp_path, initial_conditions):
    client = start_suite(ros, tmp_path, robot_state_topic='robot/state', robot_state_timeout=0.3)
    outcome, _ = synthesize(client, initial_conditions, ['look_down'])
    assert outcome.error_name == 'INVALID_INITIAL_CONDITIONS'
    assert "'robot/state'" in outcome.message
    cnu = cnu_client(ros).run(make_flexbe_goal('atlas', initial_conditions, ['look_down']), timeout=30.0)
    assert not cnu.succeeded
    assert 'INVALID_INITIAL_CONDITIONS' in cnu.message and "'robot/state'" in cnu.message
    # the server keeps serving, and named initial conditions need no robot
    assert synthesize(client, ['stand_prep'], ['look_down'])[0].succeeded


def test_cancel_while_waiting_for_the_robot_state(ros, tmp_path):
    client = start_suite(ros, tmp_path, robot_state_timeout=60.0)
    cancel = threading.Event()

    def on_feedback(status, _):
        if status.startswith('Reading the initial conditions from atlas_sim/state'):
            cancel.set()

    started = time.monotonic()
    outcome = client.run(make_goal('atlas', 'current', ['look_down']), feedback=on_feedback,
                         cancel=cancel, timeout=30.0)
    assert outcome.error_name == 'PREEMPTED' and time.monotonic() - started < 10.0


def test_current_beside_named_initial_conditions_is_rejected(ros, tmp_path):
    client = start_suite(ros, tmp_path)
    outcome, _ = synthesize(client, ['stand', 'current'], ['look_down'])
    assert outcome.error_name == 'INVALID_INITIAL_CONDITIONS' and "'stand'" in outcome.message


def run_mission(capsys, *arguments):
    code = cli_main(['execute', '--json', '--ros-sim', '--speed', '20', *arguments])
    return code, json.loads(capsys.readouterr().out)


@pytest.mark.mujoco  # the robot is simulated in this process
def test_mission_runs_the_second_demo_on_the_fly(capsys):
    code, report = run_mission(capsys, '--goals', ','.join(TASK_1), '--then', 'footstep_execution')
    assert code == 0, report
    first, second = report['batches']
    assert first['initial_conditions'] == ['stand_prep'] and first['initial_conditions_source'] == 'request'
    assert second['initial_conditions_source'] == 'atlas_sim/state'
    assert second['initial_conditions'][0] == 'manipulate'
    assert sorted(second['initial_conditions']) == sorted(AFTER_TASK_1)
    for batch in report['batches']:
        assert batch['outcome'] == 'finished' and batch['trace_check']['ok'] and not batch['fallen']
        assert batch['synthesis']['seconds'] > 0 and batch['exit_code'] == 0
    assert second['trace']['steps'][0]['mode_at_entry'] == 'manipulate'


@pytest.mark.mujoco  # the robot is simulated in this process
def test_mission_recovers_after_a_failed_batch(capsys):
    code, report = run_mission(capsys, '--goals', ','.join(TASK_1), '--fail-first', 'pickup_object:1',
                               '--then', 'pickup_object')
    assert code == 0, report
    failed, recovered = report['batches']
    assert failed['outcome'] == 'failed' and failed['trace_check']['ok'] and failed['exit_code'] == 6  # ExitStatus.OTHER_OUTCOME
    # the next batch starts from the failed state: in manipulate, the pickup not completed
    assert recovered['initial_conditions'][0] == 'manipulate'
    assert 'pickup_object' not in recovered['initial_conditions']
    assert {'look_down', 'object_template'} <= set(recovered['initial_conditions'])
    assert recovered['outcome'] == 'finished' and recovered['trace_check']['ok']
    steps = [step['state'] for step in recovered['trace']['steps']]
    assert steps == ['/pickup_object']  # nothing already done is redone


@pytest.mark.mujoco  # the robot is simulated in this process
def test_mission_without_ros_sim_reads_the_in_process_simulator(capsys):
    code = cli_main(['execute', '--json', '--goals', 'walk', '--then', 'look_down'])
    report = json.loads(capsys.readouterr().out)
    assert code == 0, report
    walked, looked = report['batches']
    assert walked['outcome'] == 'finished'
    assert looked['initial_conditions'] == ['walk'] and looked['initial_conditions_source'] == 'simulator'
    assert [step['state'] for step in looked['trace']['steps']] == ['/stand', '/look_down']
