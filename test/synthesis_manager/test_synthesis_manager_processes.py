"""The four nodes as separate processes on loopback, driven by an in-process client."""

import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.ros.harness import RosHarness
from synthesis_manager.ros.env import prepare_ros_environment

pytestmark = pytest.mark.ros

NODE_SCRIPTS = ('ltl-compilation-node', 'ltl-synthesis-node', 'sm-generation-node',
                'behavior-synthesis-server')


def test_four_node_processes_serve_a_goal_and_stop_cleanly(tmp_path):
    from synthesis_manager.ros.harness import reserve_domain_id
    from rclpy.node import Node

    bin_dir = Path(sys.executable).parent
    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ=dict(os.environ))
        processes = [subprocess.Popen([str(bin_dir / script), '--ros-args', '-p',
                                       f'byproducts_dir:={tmp_path}'] if script == 'ltl-synthesis-node'
                                      else [str(bin_dir / script)],
                                      env=environment, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                      text=True)
                     for script in NODE_SCRIPTS]
        try:
            with RosHarness(domain_id=domain) as ros:
                client = SynthesisClient(ros.add_node(Node, 'process_test_client'))
                assert client.wait_for_server(timeout=30.0)
                outcome = client.run(make_goal('atlas', ['stand_prep'], ['look_down', 'pickup_object']),
                                     timeout=60)
            assert outcome.error_name == 'SUCCESS', outcome.message
            assert outcome.states
            assert list(tmp_path.glob('*.slugsin'))
        finally:
            for process in processes:
                process.send_signal(signal.SIGTERM)
            outputs = [process.communicate(timeout=20)[0] for process in processes]
        for script, process, output in zip(NODE_SCRIPTS, processes, outputs):
            assert process.returncode == 0, f'{script}: {output}'
            assert 'ready' in output, f'{script}: {output}'
