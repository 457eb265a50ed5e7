"""The atlas_sim node: ExecuteCapability goals (also overlapping), the state topic, parameters, process."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.parameter import Parameter

from respec.vocabulary.naming import parse_names
from synthesis_manager.nodes.atlas_sim_node import CAPABILITY_ACTION_PREFIX, AtlasSimNode
from synthesis_manager.ros.harness import RosHarness, wait_for
from synthesis_manager.ros.env import prepare_ros_environment
from synthesis_msgs.action import ExecuteCapability

from atlas_sim_client import Client

pytestmark = [pytest.mark.ros, pytest.mark.mujoco]


def sim_node(ros, **parameters):
    values = {'speed': 20.0, 'state_rate': 50.0, **parameters}
    return ros.add_node(AtlasSimNode, parameter_overrides=[Parameter(k, value=v) for k, v in values.items()])


def test_goals_run_capabilities_and_overlapping_goals_start_together(ros):
    node = sim_node(ros)
    client = Client(ros)
    (stand,) = client.execute('stand')
    assert (stand.outcome, stand.reason) == ('completed', 'stand completed') and stand.stamp > 1.5
    # look_down needs stand; sent together with manipulate, both are checked in the same instant
    look_down, manipulate = client.execute('look_down', 'manipulate')
    assert look_down.outcome == 'completed' and manipulate.outcome == 'completed', (look_down, manipulate)
    assert node.simulator.mode == 'manipulate' and not node.simulator.has_fallen()
    starts = {r.name: r.started_at for r in node.simulator.history}
    assert starts['look_down'] == starts['manipulate']
    latest = client.wait_for_state(lambda m: m.stamp > manipulate.stamp)
    assert latest.mode == 'manipulate' and 'look_down' not in latest.running and not latest.fallen
    assert 0.6 < latest.pelvis_height < 1.1


def test_refused_capabilities_fail_with_the_reason_and_unknown_ones_are_rejected(ros):
    sim_node(ros)
    client = Client(ros)
    (walk,) = client.execute('walk')
    assert walk.outcome == 'failed' and 'not allowed' in walk.reason
    (unknown,) = client.execute('fly')
    assert unknown is None  # goal rejected


def test_goals_carry_the_states_userdata_which_the_robot_checks(ros):
    """FlexBE's states send the template id the operator chose; no object_template runs here."""
    node = sim_node(ros, initial_conditions='manipulate')
    client = Client(ros)

    def pickup(value_text):
        goal = ExecuteCapability.Goal(capability='pickup_object', userdata_keys=['template_id'],
                                      userdata_values=[value_text])
        return client.results([client.action.send_goal_async(goal)])[0]

    wrong = pickup('7')
    assert wrong.outcome == 'failed'
    assert wrong.reason == 'pickup_object: template_id 7 names no object of the scene (known template ids: 1)'
    not_json = pickup('one')
    assert not_json.outcome == 'failed' and "template_id 'one' is not an object template id" in not_json.reason
    assert 'object_template' not in node.simulator.completed_actions()
    right = pickup('1')
    assert (right.outcome, right.reason) == ('completed', 'pickup_object completed')
    assert node.simulator.snapshot()['holding_object']


def test_parameters_set_initial_conditions_and_faults(ros):
    node = sim_node(ros, initial_conditions='stand,object_template', fail=['look_down'],
                    fail_first='manipulate:1', seed=3)
    assert node.simulator.mode == 'stand' and node.simulator.completed_actions() == ['object_template']
    client = Client(ros)
    look_down, = client.execute('look_down')
    assert look_down.outcome == 'failed' and look_down.reason.startswith('injected fault')
    first, = client.execute('manipulate')
    second, = client.execute('manipulate')
    assert (first.outcome, second.outcome) == ('failed', 'completed')
    pickup, = client.execute('pickup_object')
    assert pickup.outcome == 'completed'


def test_per_capability_servers_join_running_requests_and_wait_for_sensors(ros):
    node = sim_node(ros, speed=1.0, initial_conditions='stand')
    client_node = ros.add_node(Node, 'capability_client')
    clients = {name: ActionClient(client_node, ExecuteCapability, CAPABILITY_ACTION_PREFIX + name)
               for name in ('look_down', 'obj_detected')}
    assert all(c.wait_for_server(timeout_sec=10.0) for c in clients.values())
    goal = ExecuteCapability.Goal()  # the server names the capability
    first = wait_for(clients['look_down'].send_goal_async(goal))
    deadline = time.monotonic() + 5.0
    while 'look_down' not in node.simulator.snapshot()['running']:
        assert time.monotonic() < deadline
        time.sleep(0.01)
    second = wait_for(clients['look_down'].send_goal_async(goal))  # activated again while running
    results = [wait_for(h.get_result_async(), 30.0).result for h in (first, second)]
    assert [r.outcome for r in results] == ['completed', 'completed'] and results[0].stamp == results[1].stamp
    assert [r.name for r in node.simulator.history].count('look_down') == 1

    with node.lock:
        node.simulator.set_sensor('obj_detected', False)
    reading = wait_for(clients['obj_detected'].send_goal_async(goal)).get_result_async()
    time.sleep(0.3)  # the behaviour under test: the reading stays open while the sensor reads false
    assert not reading.done()
    with node.lock:
        node.simulator.set_sensor('obj_detected', True)
    assert wait_for(reading, 10.0).result.outcome == 'completed'
    wrong = wait_for(clients['look_down'].send_goal_async(ExecuteCapability.Goal(capability='stand')))
    assert not wrong.accepted


def test_list_parameters_accept_arrays_and_comma_separated_strings():
    assert parse_names('a, b,,c') == ['a', 'b', 'c']
    assert parse_names(['a', ' b ']) == ['a', 'b']
    assert parse_names('') == [] and parse_names(None) == []


def test_the_node_runs_as_its_own_process():
    from synthesis_manager.ros.harness import reserve_domain_id

    script = Path(sys.executable).parent / 'atlas-sim-node'
    if not script.exists():
        pytest.fail(f'{script} is not installed (pip install -e .)')
    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        process = subprocess.Popen([str(script), '--ros-args', '-p', 'speed:=20.0', '-p', 'fail:=look_down'],
                                   env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        try:
            with RosHarness(domain_id=domain) as ros:
                client = Client(ros, 'process_client')
                (stand,) = client.execute('stand')
                (look_down,) = client.execute('look_down')
                assert stand.outcome == 'completed'
                assert look_down.outcome == 'failed' and 'injected fault' in look_down.reason
                assert client.received.wait(5.0)
        finally:
            process.send_signal(signal.SIGTERM)
            output = process.communicate(timeout=20)[0]
        assert process.returncode == 0, output
        assert 'atlas_sim ready' in output
