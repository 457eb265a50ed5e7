"""The FlexBE user's loop on FlexBE's own onboard executive (FLEXBE_SOURCES), no driver of ours.

An exported behavior package is installed into a prefix the way a user without colcon does
(pip), FlexBE's ``flexbe_onboard.start_behavior`` runs in its own process and finds it through
the ament index, ``atlas-sim-node`` is the robot and ``atlas-sim-operator`` answers InputState
exactly as flexbe_input's ``input_action_server`` does (a pickled value and nothing else). A
``flexbe_msgs/BehaviorSelection`` on ``flexbe/start_behavior`` starts it, as be_launcher and
the WebUI do; ``flexbe/status`` (BEStatus) reports the outcome. One test uses flexbe_input's
own ``input_action_server`` with its Qt window (PyQt5, offscreen) and a scripted typist. A CNU
capability system (CNU's vending_demo, LogState capabilities, from a config folder of the user's)
is exported and run the same way, with no robot but FlexBE's own states, and so is our own
config/delivery_rover (a battery sensor; a drive that fails when its operator decision says so).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

# The processes and the operator, shared with bench/bench_flexbe_onboard.py (which runs them 100 times).
from flexbe_onboard_system import Operator, OnboardSystem, exported_and_installed, finished_with

from cnu_systems import copied_rover, example_system

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.ros, pytest.mark.flexbe]

PAPER_TASK = ['--initial-conditions', 'stand_prep', '--goals', 'look_down,pickup_object']
BEHAVIOR = 'Onboard Pickup'
CNU_BEHAVIOR = 'CNU Vending Soda'


@pytest.fixture(scope='module')
def installed_prefix(tmp_path_factory):
    """The paper task exported and installed."""
    return exported_and_installed(tmp_path_factory.mktemp('onboard'),
                                  ['--system', 'atlas', *PAPER_TASK, '--name', BEHAVIOR])


@pytest.fixture
def onboard(ros, flexbe, tmp_path, monkeypatch, request):
    """Start the processes (sim and operator arguments as given; by default the paper task's
    package, else ``prefix``'s, with the robot unless ``robot=False``); stopped after the test."""
    systems = []

    def start(sim_arguments=(), operator_arguments=(), operator_command=None, operator_path=(), prefix=None,
              robot=True):
        prefix = prefix or request.getfixturevalue('installed_prefix')
        system = OnboardSystem(ros, prefix, flexbe, tmp_path, sim_arguments, operator_arguments,
                               operator_command, operator_path, robot)
        systems.append(system)
        monkeypatch.setenv('AMENT_PREFIX_PATH', system.ament_prefix_path)  # this process's BehaviorLibrary
        monkeypatch.syspath_prepend(str(system.site))
        return system

    yield start
    for system in systems:
        system.stop()


# Not 2x faster (issue 50): FlexBE's onboard engine, the robot, the operator and be_launcher start as processes, and
# the behavior runs to its end (14.7 s).
def test_be_launcher_starts_the_installed_behavior(ros, onboard, flexbe_sources):
    """FlexBE's own command line (flexbe_widget's be_launcher), as README tells users to start it."""
    from flexbe_msgs.msg import BEStatus

    system = onboard()
    operator = Operator(ros)
    operator.wait_for_servers()
    operator.wait_until(lambda: any(s.code == BEStatus.READY for s in operator.statuses), 40, 'READY from onboard')
    engine = flexbe_sources / 'flexbe_behavior_engine'
    system.environment['PYTHONPATH'] = os.pathsep.join(
        [system.environment['PYTHONPATH'], *(str(engine / name) for name in ('flexbe_widget', 'flexbe_input',
                                                                              'flexbe_mirror')),
         str(flexbe_sources / 'rosidl_runtime_py')])
    system.start('launcher', [sys.executable, str(engine / 'flexbe_widget' / 'bin' / 'be_launcher'),
                              '-b', BEHAVIOR, '-a', '3'])
    ended = (BEStatus.FINISHED, BEStatus.FAILED, BEStatus.ERROR)
    status = operator.wait_until(lambda: next((s for s in operator.statuses if s.code in ended), None), 120,
                                 'end of the behavior started by be_launcher')
    ok, details = finished_with(status, 'finished', system)
    assert ok, details + '\n--- be_launcher\n' + system.log('launcher')[-2000:]


def test_flexbe_inputs_own_input_server_and_window_answer_the_input_state(ros, onboard, flexbe_sources):
    """The operator types 1 into flexbe_input's real Qt window (offscreen): the behavior finishes."""
    engine = flexbe_sources / 'flexbe_behavior_engine'
    system = onboard(operator_command=[sys.executable, str(Path(__file__).parents[1] / 'flexbe_env' / 'typing_operator.py'),
                                       '1'],
                     operator_path=[str(engine / 'flexbe_input')])
    status = Operator(ros).start_behavior(BEHAVIOR)
    ok, details = finished_with(status, 'finished', system)
    assert ok, details
    assert "typing '1' into: 'Specify desired object template\\nint'" in system.log('operator')


def test_an_exported_behavior_finishes_onboard_with_flexbe_inputs_plain_answer(ros, onboard):
    system = onboard()
    operator = Operator(ros)
    status = operator.start_behavior(BEHAVIOR)
    ok, details = finished_with(status, 'finished', system)
    assert ok, details
    # The state topic is periodic: the newest message received may predate the end of pickup_object.
    last = operator.wait_until(lambda: next((m for m in reversed(operator.robot)
                                             if 'pickup_object' in m.completed_actions), None),
                               10, 'a robot state after pickup_object')
    # The robot acted on the template id that flowed through userdata: it never ran object_template.
    assert last.holding_object and last.mode == 'manipulate'
    assert 'object_template' not in last.completed_actions and 'pickup_object' in last.completed_actions
    assert 'answered 1' in system.log('operator')


def test_an_injected_fault_ends_the_behavior_failed(ros, onboard):
    system = onboard(sim_arguments=['-p', 'fail:=pickup_object'])
    status = Operator(ros).start_behavior(BEHAVIOR)
    ok, details = finished_with(status, 'failed', system)
    assert ok, details


def test_a_template_id_naming_no_object_fails_with_the_robots_reason(ros, onboard):
    system = onboard(operator_arguments=['--answer', '0=7'])
    operator = Operator(ros)
    status = operator.start_behavior(BEHAVIOR)
    ok, details = finished_with(status, 'failed', system)
    assert ok, details
    assert 'template_id 7 names no object of the scene (known template ids: 1)' in \
        operator.log_text() + system.log('onboard')


def test_a_cnu_capability_system_exports_and_finishes_onboard(ros, onboard, flexbe, flexbe_sources, tmp_path):
    """CNU's vending_demo, a system file in the user's own folder (``--config-dir``, beside the
    shipped ATLAS), exported by export-behavior and run by FlexBE's onboard to ``finished``:
    its LogState capabilities log, in order, the path the synthesized machine takes."""
    from respec.robot import robot_system

    config = tmp_path / 'config'
    example = example_system(config, flexbe_sources / 'flexbe_synthesis', 'vending_demo')
    prefix = exported_and_installed(
        tmp_path / 'export', ['--system', 'vending_demo', '--config-dir', str(config),
                              '--initial-conditions', ','.join(example['initial_conditions']),
                              '--goals', ','.join(example['goals']), '--name', CNU_BEHAVIOR],
        package='cnu_flexbe_behaviors', environment=dict(os.environ, AMENT_PREFIX_PATH=str(flexbe)))
    system = onboard(prefix=prefix, robot=False)
    operator = Operator(ros)
    status = operator.start_behavior(CNU_BEHAVIOR, robot=False)
    ok, details = finished_with(status, 'finished', system)
    assert ok, details
    capabilities = robot_system('vending_demo', config).capabilities.capabilities
    texts = [capabilities[name].parameters['text'] for name in ('prep_pay', 'pay', 'select', 'soda')]
    logged = operator.wait_until(lambda: [m.text for m in operator.logs if m.text in texts] == texts or None, 10,
                                 f'the log lines {texts}')
    assert logged


ROVER_TASK = ['--initial-conditions', 'check_battery_a', '--goals', 'hand_over', '--sm-outcomes', 'finished,failed']


def rover_variant(config: Path, suggestions: dict[str, str]) -> Path:
    """The shipped delivery_rover in a folder of the user's (``--config-dir``, shadowing config/'s),
    its OperatorDecisionStates suggesting ``suggestions`` (capability -> outcome): a sensor
    reading or a failure injected the way an operator would choose it."""
    import yaml

    path = copied_rover(config) / 'delivery_rover' / 'capabilities.yaml'
    capabilities = yaml.safe_load(path.read_text(encoding='utf-8'))
    for name, outcome in suggestions.items():
        capabilities['capabilities'][name]['parameters']['suggestion'] = outcome
    path.write_text(yaml.safe_dump(capabilities, sort_keys=False), encoding='utf-8')
    return config


def rover_run_ends(ros, onboard, flexbe, tmp_path, name: str, package: str, config_arguments, outcome: str):
    """Export the rover task as behavior ``name`` in ``package``, run it on FlexBE's onboard and
    assert it ends in ``outcome``; returns the operator (its logs tell which states ran)."""
    prefix = exported_and_installed(tmp_path / 'export', ['--system', 'delivery_rover', *config_arguments,
                                                          *ROVER_TASK, '--name', name],
                                    package=package, environment=dict(os.environ, AMENT_PREFIX_PATH=str(flexbe)))
    system = onboard(prefix=prefix, robot=False)
    operator = Operator(ros)
    ok, details = finished_with(operator.start_behavior(name, robot=False), outcome, system)
    assert ok, details
    return operator


def logged(operator, text: str) -> bool:
    """Whether ``text`` was logged (called by ``Operator.wait_until``, which holds its lock)."""
    return any(m.text == text for m in operator.logs)


def test_the_delivery_rover_exports_and_finishes_onboard(ros, onboard, flexbe, tmp_path):
    """config/delivery_rover (CNU's format, a battery sensor, FlexBE's own states), exported by
    export-behavior and run by FlexBE's onboard to ``finished``: the battery is fine, so the rover
    drives and hands the parcel over without charging."""
    operator = rover_run_ends(ros, onboard, flexbe, tmp_path, 'Rover Delivery', 'rover_flexbe_behaviors',
                              [], 'finished')
    assert operator.wait_until(lambda: logged(operator, 'Handing the parcel over'), 10, 'the hand-over')
    assert not logged(operator, 'Charging the battery')


def test_the_delivery_rover_charges_on_a_low_battery_and_ends_failed_when_its_drive_fails(ros, onboard, flexbe,
                                                                                         tmp_path):
    """The battery check reports the sensor low (the machine reacts: it charges), then the drive
    fails; the request asked for ``failed``, so the behavior ends there instead of retrying."""
    config = rover_variant(tmp_path / 'config', {'check_battery': 'low', 'drive': 'failed'})
    # Another behavior name and package: this process has loaded the first one's source.
    operator = rover_run_ends(ros, onboard, flexbe, tmp_path, 'Rover Failing Delivery',
                              'rover_failing_flexbe_behaviors', ['--config-dir', str(config)], 'failed')
    assert operator.wait_until(lambda: logged(operator, 'Charging the battery'), 10, 'the charge')
    assert not logged(operator, 'Handing the parcel over')
