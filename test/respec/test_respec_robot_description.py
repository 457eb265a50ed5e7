"""The robot interface (respec.robot.description): both formats answer what the surfaces ask,
each layer keeps what it does per format in a registry, and the format is told apart in one place."""

import ast
import re
from pathlib import Path

import pytest

from respec.robot import RobotDescription, for_description, robot_system
from respec.robot.abstraction import RobotAbstraction
from respec.robot.cnu import CapabilitySystem

ROOT = Path(__file__).resolve().parents[2]


def test_a_mode_robot_answers_every_question_of_the_interface():
    atlas = robot_system('atlas')
    description: RobotDescription = atlas.description
    assert description is atlas.abstraction and description.system == 'atlas'
    assert description.default_initial_conditions == ['stand_prep']
    assert description.reads_robot_state_by_default is True   # it reports its mode and completed actions
    assert description.orders_goals is True
    assert description.sensors == ('obj_detected',)


def test_a_capability_robot_answers_every_question_of_the_interface():
    picker = robot_system('shelf_picker')
    description: RobotDescription = picker.description
    assert description is picker.capabilities and description.system == 'shelf_picker'
    assert description.default_initial_conditions == []      # its spec file gives them
    assert description.reads_robot_state_by_default is False
    assert description.orders_goals is False
    assert description.sensors == ('item_on_shelf',)         # its spec file's INPUT


def test_the_system_passes_its_descriptions_answers_on():
    for name in ('atlas', 'mobile_manipulator', 'delivery_rover', 'shelf_picker'):
        system = robot_system(name)
        assert system.default_initial_conditions == system.description.default_initial_conditions
        assert system.reads_robot_state_by_default == system.description.reads_robot_state_by_default
        assert system.orders_goals == system.description.orders_goals


def test_a_file_without_a_description_is_of_our_own_format(tmp_path):
    (tmp_path / 'bare.yaml').write_text('flexbe:\n  states: {}\n')
    bare = robot_system('bare', tmp_path)
    assert bare.description is None
    assert bare.default_initial_conditions == [] and bare.reads_robot_state_by_default and bare.orders_goals


def test_a_layer_finds_its_entry_by_the_descriptions_class(tmp_path):
    registry = {RobotAbstraction: 'modes', CapabilitySystem: 'capabilities'}
    assert for_description(registry, robot_system('atlas'), missing='none') == 'modes'
    assert for_description(registry, robot_system('delivery_rover'), missing='none') == 'capabilities'
    (tmp_path / 'bare.yaml').write_text('flexbe:\n  states: {}\n')
    assert for_description(registry, robot_system('bare', tmp_path), missing='none') == 'none'
    with pytest.raises(TypeError, match='no entry for a robot described by CapabilitySystem .known: RobotAbstraction'):
        for_description({RobotAbstraction: 'modes'}, robot_system('delivery_rover'), missing='none')


# What tells the two formats apart by hand instead of asking the interface or a registry.
KIND_CHECK = re.compile(r'is_capability_system|(==|!=|\bif)\s*(ABSTRACTION|CAPABILITIES)_KIND\b'
                        r'|\b(ABSTRACTION|CAPABILITIES)_KIND\s*(==|!=|if\b)'
                        r'|\b(capabilities|abstraction) is (not )?None'
                        r'|isinstance\([^)]*\b(CapabilitySystem|RobotAbstraction)\b')
# The implementations, and respec.robot.system, where a RobotSystem is built from its file.
IMPLEMENTATIONS = {'respec/robot/system.py', 'respec/robot/abstraction.py', 'respec/robot/cnu.py',
                   'respec/robot/description.py'}
PACKAGES = ('respec', 'ltl_specification', 'ltl_synthesizer', 'sm_generation', 'atlas_sim', 'synthesis_manager',
            'bench')


def kind_checks_outside_the_implementations() -> list[str]:
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob('*.py')):
            relative = path.relative_to(ROOT).as_posix()
            if relative in IMPLEMENTATIONS:
                continue
            for number, line in enumerate(path.read_text(encoding='utf-8').splitlines(), 1):
                if KIND_CHECK.search(line):
                    found.append(f'{relative}:{number}: {line.strip()}')
    return found


def test_the_surfaces_ask_the_interface_not_the_kind():
    found = kind_checks_outside_the_implementations()
    assert len(found) <= 2, '\n'.join(found)


# --- names resolved at the edges ---------------------------------------------------------------------

def functions_taking_a_system_and_a_config_dir() -> list[str]:
    """Every function whose parameters name a system (or its name) and a config_dir."""
    found = []
    for package in PACKAGES:
        for path in sorted((ROOT / package).rglob('*.py')):
            for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    arguments = node.args
                    names = [a.arg for a in [*arguments.posonlyargs, *arguments.args, *arguments.kwonlyargs]]
                    if any(n in ('config_dir', 'config_dirs') for n in names) and any(n in ('system', 'name')
                                                                                      for n in names):
                        found.append(f'{path.relative_to(ROOT).as_posix()}:{node.lineno} {node.name}')
    return found


def test_a_name_becomes_a_robot_system_at_the_edge_alone():
    found = functions_taking_a_system_and_a_config_dir()   # today: respec.robot.system.robot_system alone
    assert 'robot_system' in [entry.split(' ')[1] for entry in found] and len(found) <= 3, found
