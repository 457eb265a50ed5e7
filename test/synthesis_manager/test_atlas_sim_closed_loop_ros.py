"""Closed loop over ROS: /behavior_synthesis (suite in-process) -> atlas_sim node driven by RosRobot.

Also the ``behavior-synthesis execute`` command line, which runs the suite in-process too.
"""

import json

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.trace_check import check_trace
from respec.vocabulary.errors import ExitStatus
from respec.parsing import spec_from_text_sections
from synthesis_manager.programs.cli import main as cli_main
from synthesis_manager.client import SynthesisClient, make_goal
from lost_responses import GoalResponseLosingClient
from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
from synthesis_manager.ros.atlas_sim_robot import RosRobot
from synthesis_manager.suite import suite_node_factories
from respec.robot import robot_system

pytestmark = [pytest.mark.ros, pytest.mark.mujoco]


def synthesize_over_ros(ros, initial_conditions, goals, sm_outcomes=('finished', 'failed')):
    for factory in suite_node_factories():
        ros.add_node(factory)
    client = SynthesisClient(ros.add_node(Node, 'closed_loop_client'))
    assert client.wait_for_server(timeout=10.0)
    outcome = client.run(make_goal('atlas', initial_conditions, goals, sm_outcomes), timeout=60.0)
    assert outcome.succeeded, outcome.message
    return outcome


@pytest.mark.parametrize('fail, expected', [('', 'finished'), ('pickup_object', 'failed')])
def test_pickup_task_over_ros(ros, fail, expected):
    goals = ['look_down', 'pickup_object']
    outcome = synthesize_over_ros(ros, ['stand_prep'], goals)
    spec = spec_from_text_sections(outcome.ltl_specification)
    node = ros.add_node(AtlasSimNode, parameter_overrides=[
        Parameter('speed', value=20.0), Parameter('state_rate', value=50.0),
        Parameter('initial_conditions', value='stand_prep'), Parameter('fail', value=fail)])
    robot = RosRobot(ros.add_node(Node, 'executive'))
    robot.wait_until_ready()
    run = execute_state_machine(outcome.machine, robot, robot_system('atlas'), max_wall_time=60.0)
    assert run.outcome == expected
    report = check_trace(run.trace, spec, goals=goals)
    assert report.ok, report.summary()
    assert not run.fallen and not node.simulator.has_fallen()
    assert 0.6 < run.min_pelvis_height and 0.6 < node.simulator.snapshot()['pelvis_height'] < 1.1
    assert [s.state for s in run.trace.steps][-1] == '/pickup_object'
    assert node.simulator.snapshot()['holding_object'] == (expected == 'finished')


def test_the_robot_adapter_goes_on_when_its_goal_responses_are_lost(ros, monkeypatch):
    goals = ['look_down', 'pickup_object']
    outcome = synthesize_over_ros(ros, ['stand_prep'], goals)
    ros.add_node(AtlasSimNode, parameter_overrides=[
        Parameter('speed', value=20.0), Parameter('state_rate', value=50.0),
        Parameter('initial_conditions', value='stand_prep')])
    monkeypatch.setattr('synthesis_manager.ros.atlas_sim_robot.RaceFreeActionClient', GoalResponseLosingClient)
    robot = RosRobot(ros.add_node(Node, 'executive'))
    robot.wait_until_ready()
    run = execute_state_machine(outcome.machine, robot, robot_system('atlas'), max_wall_time=60.0)
    assert run.outcome == 'finished' and robot.client.lost >= len(goals)  # one goal per capability, or more
    assert check_trace(run.trace, spec_from_text_sections(outcome.ltl_specification), goals=goals).ok


def run_cli(capsys, *arguments):
    code = cli_main(['execute', '--json', *arguments])
    return code, json.loads(capsys.readouterr().out)


def test_cli_runs_a_task_and_prints_json(capsys):
    code, report = run_cli(capsys, '--goals', 'walk')
    assert code == 0, report
    assert report['outcome'] == 'finished' and report['fallen'] is False
    assert report['trace_check']['ok'] and report['trace_check']['goals_completed_at'] == {'walk': 1}
    assert [s['state'] for s in report['trace']['steps']] == ['/stand', '/walk']


def test_cli_exit_codes_follow_the_expected_outcome_and_records_frames(capsys, tmp_path):
    arguments = ['--goals', 'look_down,pickup_object', '--fail', 'pickup_object']
    code, report = run_cli(capsys, *arguments)
    assert code == ExitStatus.OTHER_OUTCOME and report['outcome'] == 'failed' and report['trace_check']['ok']
    code, report = run_cli(capsys, *arguments, '--expect', 'failed', '--record', str(tmp_path))
    assert code == 0
    frames = sorted((tmp_path / 'frames').glob('*.png'))
    assert len(frames) >= 10 and (tmp_path / 'timeline.png').stat().st_size > 5000
    assert report['timeline'] == str(tmp_path / 'timeline.png')


def test_cli_retries_with_finished_only_through_the_ros_simulator(capsys, tmp_path):
    code, report = run_cli(capsys, '--goals', 'pickup_object', '--sm-outcomes', 'finished',
                           '--fail-first', 'pickup_object:2', '--ros-sim', '--speed', '20',
                           '--record', str(tmp_path))
    assert code == 0, report
    pickups = [r['outcome'] for s in report['trace']['steps'] for r in s['results']
               if r['capability'] == 'pickup_object']
    assert pickups == ['failed', 'failed', 'completed']
    # frames rendered in this thread from events of the node's physics thread
    names = [path.name for path in sorted((tmp_path / 'frames').glob('*.png'))]
    assert sum('pickup_object_failed' in name for name in names) == 2 and names[-1].endswith('_end.png')


@pytest.mark.parametrize('arguments, item', [(['--fail-first', 'pickup_object'], 'pickup_object'),
                                             (['--fail', 'look_down,fly'], 'fly'),
                                             (['--initial-conditions', 'stand,walk'], 'walk')])
def test_cli_rejects_bad_faults_and_starts_before_synthesis(capsys, arguments, item):
    assert cli_main(['execute', *arguments]) == 2
    assert repr(item) in capsys.readouterr().err


def test_cli_reports_a_failed_synthesis(capsys):
    code, report = run_cli(capsys, '--goals', 'fly')
    assert code == ExitStatus.FAILED
    assert report['synthesis']['error_name'] != 'SUCCESS' and 'fly' in report['synthesis']['message']
    assert 'trace' not in report
