"""sm_generation.flexbe_behavior: a generated machine as a FlexBE behavior package (no ROS).

What the real FlexBE engine makes of the package is tested in test_flexbe_engine.py.
"""

import ast
import dataclasses
from pathlib import Path

import pytest

from sm_generation import SMGenerationError, StateMachine, generate_state_machine, load_automaton
from respec.robot import robot_system
from sm_generation.config import flexbe_config, parse_flexbe_config
from sm_generation.flexbe_behavior import (behavior_class_name, behavior_module_name, behavior_package,
                                           state_module_name)
from sm_generation.generator import generate_from_config

ROOT = Path(__file__).resolve().parents[2]
AUTOMATA = ROOT / 'test' / 'automata'
DATE = 'Sun Nov 22 2026'


def export(automaton='concurrent.yaml', name='Look Down And Pickup', **kwargs):
    machine = generate_state_machine(load_automaton(AUTOMATA / automaton), robot_system('atlas'))
    return machine.to_instantiations(), behavior_package(machine, flexbe_config(robot_system('atlas')), name, date=DATE, **kwargs)


def create_method(code):
    tree = ast.parse(code)
    cls = next(node for node in tree.body if isinstance(node, ast.ClassDef))
    return next(f for f in cls.body if isinstance(f, ast.FunctionDef) and f.name == 'create')


def test_names_follow_the_flexbe_editor():
    assert behavior_class_name('Pickup Object') == 'PickupObjectSM'
    assert behavior_module_name('Pickup Object') == 'pickup_object_sm'
    assert state_module_name('ChangeControlModeActionState') == 'change_control_mode_action_state'
    assert state_module_name('WalktoTemplateSM') == 'walkto_template_sm'
    assert state_module_name('InputState') == 'input_state'


def test_package_layout_manifest_and_package_xml():
    _, package = export()
    assert sorted(package.files) == [
        'manifest/look_down_and_pickup.xml', 'package.xml', 'resource/synthesized_flexbe_behaviors',
        'setup.cfg', 'setup.py', 'synthesized_flexbe_behaviors/__init__.py',
        'synthesized_flexbe_behaviors/look_down_and_pickup_sm.py']
    manifest = package.files['manifest/look_down_and_pickup.xml']
    assert '<behavior name="Look Down And Pickup">' in manifest
    assert ('<executable package_path="synthesized_flexbe_behaviors.look_down_and_pickup_sm" '
            'class="LookDownAndPickupSM" />') in manifest
    package_xml = package.files['package.xml']
    assert '<flexbe_behaviors />' in package_xml and '<name>synthesized_flexbe_behaviors</name>' in package_xml
    assert '<exec_depend>atlas_sim_flexbe_states</exec_depend>' in package_xml


def test_code_imports_each_class_from_its_configured_package_and_is_valid_python():
    _, package = export()
    code = package.files['synthesized_flexbe_behaviors/look_down_and_pickup_sm.py']
    ast.parse(code)
    assert 'from flexbe_states.input_state import InputState' in code
    assert ('from atlas_sim_flexbe_states.change_control_mode_action_state import '
            'ChangeControlModeActionState') in code
    assert 'class LookDownAndPickupSM(Behavior):' in code and "self.name = 'Look Down And Pickup'" in code


def test_concurrent_activation_becomes_a_concurrency_container_with_its_conditions():
    states, package = export()
    code = package.files['synthesized_flexbe_behaviors/look_down_and_pickup_sm.py']
    container = next(s for s in states if s.state_class == ':CONCURRENCY')
    assert f'_sm_{container.name}_0 = ConcurrencyContainer(' in code
    for outcome, condition in zip(container.cond_outcome, container.cond_transition):
        pairs = ', '.join(f"('{n}', '{o}')" for n, o in zip(condition.state_name, condition.state_outcome))
        assert f"('{outcome}', [{pairs}])" in code
    assert "input_keys=['template_id']" in code and "output_keys=['template_id']" in code


def test_userdata_lives_in_the_root_and_reaches_the_pickup_behavior():
    states, package = export('two_behaviors.yaml', name='Pickup And Grasp')
    code = package.files['synthesized_flexbe_behaviors/pickup_and_grasp_sm.py']
    assert '_state_machine.userdata.template_id = None' in code
    assert "self.add_behavior(PickupObjectSM, 'pickup_object', node)" in code
    assert "self.use_behavior(PickupObjectSM, 'pickup_object')" in code
    assert "remapping={'template_id': 'template_id'}" in code
    assert 'from atlas_sim_flexbe_behaviors.pickup_object_sm import PickupObjectSM' in code
    manifest = package.files['manifest/pickup_and_grasp.xml']
    assert '<contains name="Grasp Object" />' in manifest and '<contains name="Pickup Object" />' in manifest


def test_keys_read_but_written_by_no_state_are_the_roots_input_keys_with_their_defaults():
    """Pickup and grasp without an InputState (object_template held initially): template_id comes from outside."""
    states, package = export('two_behaviors.yaml', name='Pickup And Grasp')
    assert states[0].state_path == '/' and states[0].input_keys == ['template_id']
    assert all(not s.input_keys for s in states[1:] if s.state_class != ':CONCURRENCY')
    code = package.files['synthesized_flexbe_behaviors/pickup_and_grasp_sm.py']
    assert "OperatableStateMachine(outcomes=['finished', 'failed'], input_keys=['template_id'])" in code
    assert '_state_machine.userdata.template_id = None' in code
    with_default = dataclasses.replace(flexbe_config(robot_system('atlas')), userdata={'template_id': '1'})
    code = behavior_package(StateMachine.from_instantiations(states), with_default, 'Pickup And Grasp', date=DATE).files[
        'synthesized_flexbe_behaviors/pickup_and_grasp_sm.py']
    assert '_state_machine.userdata.template_id = 1' in code


def test_keys_written_in_the_machine_are_not_input_keys():
    """The InputState writes template_id before pregrasp_pose reads it: nothing comes from outside."""
    states, _ = export('concurrent.yaml')
    assert states[0].input_keys == []
    assert generate_from_config(load_automaton(AUTOMATA / 'concurrent.yaml'),
                                flexbe_config(robot_system('atlas'))).input_keys == []


def test_writes_must_name_remapped_keys():
    section = {'sm_outcomes': {'finished': 'finished'},
               'states': {'x_a': {'class_decl': {'name': 'LogState'}, 'output_mapping': {'x_c': ['done']},
                                  'userdata_keys': ['data'], 'userdata_remapping': ['value'], 'writes': ['data']}}}
    with pytest.raises(SMGenerationError) as raised:
        parse_flexbe_config(section, 'atlas')
    assert raised.value.item == 'flexbe.states.x_a.writes'


@pytest.mark.parametrize('userdata, item', [
    ([1], 'flexbe.userdata'), ({'not a name': 1}, 'flexbe.userdata'), ({'key': [1]}, 'flexbe.userdata.key')])
def test_bad_declared_userdata_names_the_item(userdata, item):
    section = {'sm_outcomes': {'finished': 'finished'}, 'userdata': userdata,
               'states': {'x_a': {'class_decl': {'name': 'LogState'}, 'output_mapping': {'x_c': ['done']}}}}
    with pytest.raises(SMGenerationError) as raised:
        parse_flexbe_config(section, 'atlas')
    assert raised.value.item == item


def test_autonomy_levels_and_positions_come_from_the_machine():
    states, package = export()
    code = package.files['synthesized_flexbe_behaviors/look_down_and_pickup_sm.py']
    stand = next(s for s in states if s.state_path.endswith('/stand'))
    assert stand.autonomy == [2, 0]  # config: mode changes High, failures Off
    assert "autonomy={'changed': Autonomy.High, 'failed': Autonomy.Off}" in code
    for state in states:
        if state.state_class not in (':OUTCOME', ':STATEMACHINE'):
            assert f'# x:{round(state.position[0])} y:{round(state.position[1])}\n' in code


def test_initial_state_is_added_first():
    states, package = export()
    root = states[0]
    code = package.files['synthesized_flexbe_behaviors/look_down_and_pickup_sm.py']
    body = ast.get_source_segment(code, create_method(code))
    root_block = body[body.index('with _state_machine:'):]
    first_added = root_block[root_block.index("add('") + 5:].split("'", 1)[0]
    assert first_added == root.initial_state_name


def test_same_machine_same_bytes():
    assert export()[1].files == export()[1].files


@pytest.mark.parametrize('kwargs, item', [
    ({'name': '3 Bad'}, '3 Bad'), ({'name': 'Bad/Name'}, 'Bad/Name'),
    ({'package': 'Bad-Package'}, 'Bad-Package')])
def test_bad_names_are_rejected_with_the_item(kwargs, item):
    arguments = {'name': 'Fine', **kwargs}
    with pytest.raises(SMGenerationError) as error:
        export(**arguments)
    assert error.value.item == item


def test_a_class_without_a_package_names_the_state():
    machine = generate_state_machine(load_automaton(AUTOMATA / 'concurrent.yaml'), robot_system('atlas'))
    config = flexbe_config(robot_system('atlas'))
    bare = parse_flexbe_config({'sm_outcomes': config.sm_outcomes, 'states': {
        proposition: {'class_decl': {'name': s.state_class, 'behavior_class': s.behavior_class,
                                     'param_names': list(s.parameter_names),
                                     'param_values': list(s.parameter_values)},
                      'output_mapping': {k: list(v) for k, v in s.output_mapping.items()}}
        for proposition, s in config.states.items()}}, 'atlas')
    with pytest.raises(SMGenerationError) as error:
        behavior_package(machine, bare, 'No Packages')
    assert error.value.code == 'CONFIG_VARIABLE_CONFIG_INVALID' and error.value.item.startswith('/')


def test_package_manifests_are_valid_for_colcon():
    """catkin_pkg (what colcon and flexbe_onboard parse package.xml with) accepts the exported and our own."""
    from catkin_pkg.package import parse_package_string

    _, package = export()
    manifests = [package.files['package.xml']] + [
        (ROOT / 'atlas_sim' / 'flexbe' / name / 'package.xml').read_text()
        for name in ('atlas_sim_flexbe_states', 'atlas_sim_flexbe_behaviors')]
    for text in manifests:
        parsed = parse_package_string(text)
        parsed.validate()
        assert any(tag.tagname in ('flexbe_states', 'flexbe_behaviors') for tag in parsed.exports)
