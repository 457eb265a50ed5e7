"""Winning by cheating is flagged in every channel (issue 33 item 4): a robot whose spec file
assumes something the controller can force the environment to break still gets its state
machine, with the warning naming the assumptions in BehaviorSynthesis' error_code.message,
CNU's FlexBESynthesis messages[], the GUI's job result (its banner) and `compile --diagnose`."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from fastapi.testclient import TestClient

from suite_settings import suite_args
from synthesis_manager.client import SynthesisClient, make_flexbe_goal, make_goal
from synthesis_manager.programs.gui import RosGoalRunner
from synthesis_manager.suite import suite_node_factories
from synthesis_manager.web.backend import SynthesisBackend
from synthesis_manager.web.routes import create_app

pytestmark = pytest.mark.ros

CONFIG = Path(__file__).resolve().parents[2] / 'config'
# The battery check never answers: the rover starts every delivery with it (SYS_INIT), so the
# environment cannot keep the check's answer assumptions (ENV_TRANS) from the first step.
NEVER_ANSWERS = '''    - "charge_c' -> !battery_low'"
    - "check_battery_a -> !check_battery_c' & !check_battery_l'"'''
INVOLVED = "env_trans #11 'check_battery_a -> !next(check_battery_c) & !next(check_battery_l)'"


@pytest.fixture
def cheating_rover(tmp_path, flexbe, monkeypatch) -> Path:
    """A config directory whose delivery_rover assumes a battery check that never answers."""
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(flexbe))
    config = tmp_path / 'config'
    config.mkdir()
    shutil.copy(CONFIG / 'delivery_rover.yaml', config)
    shutil.copytree(CONFIG / 'delivery_rover', config / 'delivery_rover')
    spec_file = config / 'delivery_rover' / 'spec.yaml'
    text = spec_file.read_text()
    assert '''    - "charge_c' -> !battery_low'"''' in text
    spec_file.write_text(text.replace('''    - "charge_c' -> !battery_low'"''', NEVER_ANSWERS))
    return config


@pytest.mark.flexbe
def test_the_warning_reaches_every_channel_and_the_machine_is_still_made(ros, tmp_path, cheating_rover):
    from rclpy.node import Node

    compiled = subprocess.run([sys.executable, '-m', 'synthesis_manager', 'compile', '--system', 'delivery_rover',
                               '--config-dir', str(cheating_rover), '--goals', 'hand_over', '--diagnose',
                               '-o', os.devnull], capture_output=True, text=True, timeout=120)
    assert compiled.returncode == 0, compiled.stderr
    warning = compiled.stderr.strip()
    assert warning.startswith('Warning: the controller can win by forcing the environment to break its assumptions')
    assert INVOLVED in warning

    for factory in suite_node_factories(suite_args(tmp_path / 'byproducts', config_dir=str(cheating_rover))):
        ros.add_node(factory)
    node = ros.add_node(Node, 'well_separation_channels')
    ours, cnus = SynthesisClient(node, 'behavior_synthesis'), SynthesisClient(node, 'flexbe_synthesis')
    assert ours.wait_for_server(timeout=10.0) and cnus.wait_for_server(timeout=10.0)

    result = ours.run(make_goal('delivery_rover', [], ['hand_over']), timeout=120)
    assert (result.error_name, result.message) == ('SUCCESS', warning)
    assert result.states   # the machine is made all the same
    cnu = cnus.run(make_flexbe_goal('delivery_rover', [], ['hand_over']), timeout=120)
    assert cnu.error_name == 'SUCCESS' and warning in cnu.message.split('\n')

    backend = SynthesisBackend(RosGoalRunner(ours, goal_timeout=120), config_dir=str(cheating_rover))
    with TestClient(create_app(backend)) as gui:
        started = gui.post('/api/jobs', json={'system': 'delivery_rover', 'initial_conditions': [],
                                              'goals': ['hand_over']})
        assert started.status_code == 202, started.text
        job_id = started.json()['id']
        with gui.stream('GET', f'/api/jobs/{job_id}/events', timeout=180) as events:
            for _ in events.iter_lines():
                pass
        outcome = gui.get(f'/api/jobs/{job_id}').json()['outcome']
    assert (outcome['error_name'], outcome['message']) == ('SUCCESS', warning)   # the banner's text


def test_custom_ltl_assumptions_are_named_as_the_core_names_them_and_honest_tasks_get_no_message(ros, tmp_path):
    from rclpy.node import Node

    custom = tmp_path / 'custom.yaml'
    custom.write_text('env_trans:\n  - "look_down_a -> !next(look_down_c)"\n')
    compiled = subprocess.run([sys.executable, '-m', 'synthesis_manager', 'compile', '--system', 'atlas',
                               '--initial-conditions', 'stand', '--goals', 'look_down', '--sm-outcomes', 'finished',
                               '--custom-ltl', str(custom), '--diagnose', '-o', os.devnull],
                              capture_output=True, text=True, timeout=120)
    warning = compiled.stderr.strip()
    assert 'custom LTL env_trans[0] (request custom LTL)' in warning and 'eq. (7) completion fairness' in warning

    for factory in suite_node_factories(suite_args(tmp_path / 'byproducts')):
        ros.add_node(factory)
    client = SynthesisClient(ros.add_node(Node, 'honest_client'), 'behavior_synthesis')
    assert client.wait_for_server(timeout=10.0)
    cheating = client.run(make_goal('atlas', ['stand'], ['look_down'], sm_outcomes=['finished'],
                                    ltl_specification={'env_trans': ['look_down_a -> !next(look_down_c)']}),
                          timeout=120)
    assert (cheating.error_name, cheating.message) == ('SUCCESS', warning)  # named from the provenance
    honest = client.run(make_goal('atlas', ['stand_prep'], ['look_down', 'pickup_object']), timeout=120)
    assert (honest.error_name, honest.message) == ('SUCCESS', '')
