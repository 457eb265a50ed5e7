"""The suite serves its robot systems: a client elsewhere sees the suite's systems, not its own files."""

import shutil
import time
from pathlib import Path

import pytest
from rclpy.node import Node
from rclpy.parameter import Parameter

from respec.robot import SystemCatalog, robot_system
from synthesis_manager.nodes.ltl_compilation_node import LTLCompilationNode
from synthesis_manager.ros.robot_systems import SuiteSystems

pytestmark = pytest.mark.ros

CONFIG = Path(__file__).resolve().parents[2] / 'config'


def wait_for(condition, timeout=10.0):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return False


def test_a_client_sees_the_suite_systems_and_their_edits(ros, tmp_path):
    shutil.copy(CONFIG / 'atlas.yaml', tmp_path / 'atlas.yaml')
    (tmp_path / 'broken.yaml').write_text('abstraction: [not, a, mapping]\n')
    ros.add_node(LTLCompilationNode, parameter_overrides=[Parameter('config_dir', value=str(tmp_path))])
    systems = SuiteSystems(ros.add_node(Node, 'systems_client'))
    assert wait_for(lambda: systems.names() == ['atlas', 'broken', 'delivery_rover', 'mobile_manipulator',
                                                'shelf_picker'])  # added to config/'s
    assert systems.load('atlas') == robot_system('atlas', tmp_path)
    try:
        systems.load('broken')
    except Exception as error:  # noqa: BLE001 - the suite's own error, as it would answer a request
        assert 'abstraction' in str(error) and error.item
    else:
        raise AssertionError('a broken system must not load')
    # An edit on the suite's side reaches the client (the node looks every SYSTEMS_PERIOD).
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: []}\n')
    assert wait_for(lambda: 'tiny' in systems.names(), timeout=3 * LTLCompilationNode.SYSTEMS_PERIOD)
    assert list(systems.load('tiny').abstraction.actions) == ['wave']
    assert SystemCatalog(tmp_path).names() == systems.names()
