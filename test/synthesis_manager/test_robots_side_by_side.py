"""Two robots side by side: each robot's nodes in its own namespace, one synthesis service.

Two simulated ATLAS (``/robot1`` from stand_prep, ``/robot2`` from stand) ask for behaviors
at the same time with the initial condition ``current``: each robot's server must read its
own robot's state topic, and each behavior is run on its own robot and checked.
"""

from argparse import Namespace
import threading

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from atlas_sim.executive.executor import execute_state_machine
from atlas_sim.executive.trace_check import check_trace
from ltl_specification.initial_conditions import initial_conditions_in_status
from respec.parsing import spec_from_text_sections
from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
from synthesis_manager.ros.atlas_sim_robot import RosRobot
from synthesis_manager.ros.namespaces import synthesis_service_remapping
from synthesis_manager.suite import suite_node_factories
from respec.robot import robot_system

pytestmark = pytest.mark.ros

ROBOTS = {  # namespace -> (where its simulated ATLAS starts, what it is asked to do)
    '/robot1': ('stand_prep', ['look_down', 'pickup_object']),
    '/robot2': ('stand', ['footstep_execution']),
}


def fleet_args(tmp_path, **settings):
    return Namespace(config_dir='', byproducts_dir=str(tmp_path), backend='builtin', slugs_executable='slugs',
                     synthesis_timeout=60.0, service_timeout=3.0, **settings)


@pytest.mark.mujoco  # each robot is an atlas_sim node: a simulator in this process
def test_two_robots_synthesize_and_run_at_once_with_one_synthesis_service(ros, tmp_path):
    factories = suite_node_factories(fleet_args(tmp_path, namespaces=list(ROBOTS)))
    nodes = [ros.add_node(factory) for factory in factories]
    synthesizers = [node for node in nodes if node.get_name() == 'ltl_synthesis']
    assert [node.get_namespace() for node in synthesizers] == ['/']  # one, shared
    assert sorted(node.get_namespace() for node in nodes if node.get_name() == 'behavior_synthesis_server') \
        == sorted(ROBOTS)
    robots, clients = {}, {}
    for namespace, (start, _) in ROBOTS.items():
        ros.add_node(AtlasSimNode, namespace=namespace,
                     parameter_overrides=[Parameter('initial_conditions', value=start),
                                          Parameter('speed', value=20.0), Parameter('state_rate', value=50.0)])
        robots[namespace] = RosRobot(ros.add_node(Node, 'executive', namespace=namespace))
        clients[namespace] = SynthesisClient(ros.add_node(Node, 'operator', namespace=namespace))
    for namespace in ROBOTS:
        robots[namespace].wait_until_ready()
        assert clients[namespace].wait_for_server(timeout=10.0)

    results = {}

    def synthesize_and_run(namespace):
        statuses = []
        goals = ROBOTS[namespace][1]
        outcome = clients[namespace].run(make_goal('atlas', 'current', goals), timeout=120.0,
                                         feedback=lambda status, _: statuses.append(status))
        detected = next(filter(None, map(initial_conditions_in_status, statuses)), None)
        run = execute_state_machine(outcome.machine, robots[namespace], robot_system('atlas'), max_wall_time=120.0) \
            if outcome.succeeded else None
        results[namespace] = outcome, detected, run

    threads = [threading.Thread(target=synthesize_and_run, args=(namespace,)) for namespace in ROBOTS]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=240.0)
    assert sorted(results) == sorted(ROBOTS)
    for namespace, (start, goals) in ROBOTS.items():
        outcome, detected, run = results[namespace]
        assert outcome.succeeded, (namespace, outcome.message)
        source, initial_conditions = detected
        assert source == 'atlas_sim/state' and initial_conditions == [start], (namespace, detected)
        assert run.outcome == 'finished'
        assert run.trace.steps[0].mode_at_entry == start
        report = check_trace(run.trace, spec_from_text_sections(outcome.ltl_specification), goals=goals)
        assert report.ok, report.summary()
        ran = {capability for step in run.trace.steps for capability in step.capabilities}
        assert set(goals) <= ran
    # each robot's simulator ran its own behavior only
    assert 'footstep_execution' not in {c for step in results['/robot1'][2].trace.steps for c in step.capabilities}
    assert 'pickup_object' not in {c for step in results['/robot2'][2].trace.steps for c in step.capabilities}


def test_a_server_reaches_a_shared_synthesis_service_by_standard_remapping():
    assert synthesis_service_remapping('/') == [
        '--ros-args', '-r', 'ltl_synthesis:=/ltl_synthesis', '-r', 'ltl_synthesis/cancel:=/ltl_synthesis/cancel']
    assert synthesis_service_remapping('fleet/') == [
        '--ros-args', '-r', 'ltl_synthesis:=/fleet/ltl_synthesis',
        '-r', 'ltl_synthesis/cancel:=/fleet/ltl_synthesis/cancel']


def test_without_namespaces_the_suite_is_placed_as_before(tmp_path):
    factories = suite_node_factories(fleet_args(tmp_path))
    assert all('namespace' not in factory.keywords and 'cli_args' not in factory.keywords
               for factory in factories)
    one = suite_node_factories(fleet_args(tmp_path, namespaces=['robot1']))
    assert {factory.keywords['namespace'] for factory in one} == {'/robot1'}  # synthesis too
    assert all('cli_args' not in factory.keywords for factory in one)


# Not 2x faster (issue 50): the documented commands start two serve processes, two robots and the clients (3.5 s).
def test_the_documented_commands_serve_two_robots_and_the_clients_pick_one(tmp_path):
    """docs/deployment.md: one synthesis service in /fleet (``serve --ros-args -r __ns:=/fleet``),
    both robots' other nodes in one ``serve --namespace /robot1 --namespace /robot2
    --synthesis-namespace /fleet``, each robot's ``atlas-sim-node --ros-args -r __ns:=...``;
    ``send-goal --namespace`` and ``gui --connect --namespace`` pick the robot, whose server reads
    its own robot's state."""
    import json
    import subprocess
    import time

    import httpx

    from suite_processes import BIN, GUI_URL, loopback_domain, started

    serve = [BIN / 'behavior-synthesis', 'serve', '--byproducts-dir', tmp_path]
    with loopback_domain() as (_, environment):
        with started([*serve, '--nodes', 'ltl_synthesis', '--ros-args', '-r', '__ns:=/fleet'],
                     environment) as (_, synthesis_output), \
                started([*serve, '--namespace', '/robot1', '--namespace', '/robot2', '--synthesis-namespace', '/fleet',
                         '--nodes', 'behavior_synthesis_server,ltl_compilation,sm_generation'],
                        environment) as (_, server_output), \
                started([BIN / 'atlas-sim-node', '--ros-args', '-r', '__ns:=/robot1',
                         '-p', 'initial_conditions:=stand_prep'], environment), \
                started([BIN / 'atlas-sim-node', '--ros-args', '-r', '__ns:=/robot2',
                         '-p', 'initial_conditions:=stand'], environment), \
                started([BIN / 'behavior-synthesis', 'gui', '--port', '0', '--connect', '--namespace', '/robot2'],
                        environment) as (_, gui_output):
            synthesis_output.wait_for('suite up')
            assert 'in /robot1, /robot2' in server_output.wait_for('suite up').string
            for namespace, start in (('/robot2', 'stand'), ('/robot1', 'stand_prep')):
                sent = subprocess.run(
                    [BIN / 'behavior-synthesis', 'send-goal', '--namespace', namespace, '--action',
                     'flexbe_synthesis', '--initial-conditions', 'current', '--goals', 'look_down', '--json'],
                    env=environment, capture_output=True, text=True, timeout=120)
                assert sent.returncode == 0, sent.stderr
                assert f'waiting for {namespace}/flexbe_synthesis' in sent.stderr
                result = json.loads(sent.stdout)  # CNU's result says where its initial conditions came from
                assert initial_conditions_in_status(result['message']) == ('atlas_sim/state', [start])

            url = gui_output.wait_for(GUI_URL).group(1)
            assert 'the suite of /robot2' in httpx.get(f'{url}api/info').json()['description']
            assert 'atlas' in json.dumps(httpx.get(f'{url}api/systems').json())  # from /robot2/robot_systems
            answer = httpx.post(f'{url}api/jobs', json={'system': 'atlas', 'initial_conditions': ['current'],
                                                        'goals': ['look_down']})
            assert answer.status_code == 202, answer.text
            deadline = time.monotonic() + 120
            while (job := httpx.get(f"{url}api/jobs/{answer.json()['id']}").json())['state'] != 'finished':
                assert time.monotonic() < deadline, job
                time.sleep(0.1)
            assert job['outcome']['error_name'] == 'SUCCESS', job['outcome']
            detected = next(filter(None, (initial_conditions_in_status(note['status']) for note in job['timeline'])))
            assert detected == ('atlas_sim/state', ['stand'])  # robot 2's state, read by robot 2's server


def test_a_client_names_its_robots_action_when_the_server_is_gone(ros):
    client = SynthesisClient(ros.add_node(Node, 'operator', namespace='/robot9'))
    assert 'the /robot9/behavior_synthesis action server went away' in client.server_lost(3.0).message
    assert 'the /behavior_synthesis action server went away' in \
        SynthesisClient(ros.add_node(Node, 'operator')).server_lost(3.0).message
