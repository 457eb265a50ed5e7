"""Settings declared once (issue 49 item 4): the nodes' ROS parameters, the suite's flags and
docs/nodes.md's table all come from synthesis_manager.settings."""

import argparse
from pathlib import Path

import pytest

from synthesis_manager.settings import (NODE_SETTINGS, SUITE_FLAGS, add_suite_flags, node_overrides, setting,
                                        settings_table)

DOCS = Path(__file__).resolve().parents[2] / 'docs' / 'nodes.md'
# rclpy's own parameters, which every node has.
ROS_OWN_PARAMETERS = ('use_sim_time', 'start_type_description_service')
START, END = '<!-- settings table:', '<!-- end of the settings table -->'


def test_the_docs_table_is_the_declarations():
    text = DOCS.read_text()
    table = text[text.index('\n', text.index(START)) + 1:text.index(END)]
    assert table == settings_table(), ('docs/nodes.md disagrees with synthesis_manager/settings.py: paste '
                                       '`python -m synthesis_manager.settings` between its markers')


def test_every_setting_is_of_its_declared_type_and_named_once_per_node():
    for node, settings in NODE_SETTINGS.items():
        names = [item.name for item in settings]
        assert len(names) == len(set(names)), node
        for item in settings:
            assert type(item.default_value()) is item.type, (node, item.name)
            assert item.meaning and not item.meaning.endswith('.'), (node, item.name)
            assert not item.choices or item.default_value() in item.choices


def test_every_flag_sets_declared_settings_and_tells_their_default():
    for flag in SUITE_FLAGS:
        for node, name in flag.sets:
            setting(node, name)  # raises for an undeclared one
    parser = argparse.ArgumentParser()
    add_suite_flags(parser)
    help_text = ' '.join(parser.format_help().split())
    assert "byproduct files (default 200; 0: none)" in help_text
    assert '(default 64; 0: no cache)' in help_text
    assert 'default: atlas_sim/state' in help_text


def test_flags_become_the_settings_of_each_node_they_set():
    parser = argparse.ArgumentParser()
    add_suite_flags(parser)
    args = parser.parse_args(['--synthesis-timeout', '7', '--config-dir', '/a', '--config-dir', '/b',
                              '--keep-byproducts', '3'])
    assert node_overrides(args, 'ltl_synthesis') == {'backend': 'builtin', 'slugs_executable': 'slugs',
                                                     'timeout': 7.0, 'keep_byproducts': 3}
    assert node_overrides(args, 'behavior_synthesis_server') == {
        'config_dir': '/a:/b', 'synthesis_timeout': 7.0, 'service_timeout': 5.0}
    assert node_overrides(args, 'sm_generation') == {'config_dir': '/a:/b'}
    # Without a command line (a test's suite), every node keeps its own defaults.
    assert node_overrides(None, 'ltl_synthesis') == {}


def test_every_flag_gives_each_setting_a_value_of_its_type():
    """A ROS parameter refuses a value of another type at start-up (``serve --memory-sum-limit-mb
    1024`` ended in InvalidParameterTypeException when the flag parsed floats for an int setting)."""
    parser = argparse.ArgumentParser()
    add_suite_flags(parser)
    typical = {int: '3', float: '2.5', str: 'x'}
    for flag in SUITE_FLAGS:
        if flag.add is not None:
            continue
        first = setting(*flag.sets[0])
        if first.choices:
            continue
        args = parser.parse_args([flag.option, typical[first.type]])
        for node, name in flag.sets:
            value = node_overrides(args, node)[name]
            assert type(value) is setting(node, name).type, (flag.option, node, name, value)


@pytest.mark.ros
@pytest.mark.mujoco  # the atlas_sim node builds its simulator
def test_each_node_declares_exactly_its_settings(tmp_path):
    from rclpy.parameter import Parameter

    from synthesis_manager.nodes.atlas_sim_node import AtlasSimNode
    from synthesis_manager.ros.harness import RosHarness
    from synthesis_manager.suite import suite_node_factories

    with RosHarness() as ros:
        nodes = [ros.add_node(factory) for factory in suite_node_factories()]
        nodes.append(ros.add_node(AtlasSimNode, parameter_overrides=[Parameter('speed', value=0.0)]))
        for node in nodes:
            declared = {name: value.value for name, value in node._parameters.items() if name not in ROS_OWN_PARAMETERS}
            expected = {item.name: item.default_value() for item in NODE_SETTINGS[node.get_name()]}
            if node.get_name() == 'atlas_sim':
                expected['speed'] = 0.0
            assert declared == expected, node.get_name()
            assert all(type(declared[name]) is type(value) for name, value in expected.items())


def test_no_node_declares_or_reads_a_parameter_by_hand():
    """Parameters are declared from the settings in one place and read as ``settings.<name>``."""
    shell = DOCS.parents[1] / 'synthesis_manager'
    found = [f'{path.relative_to(shell)}:{number}' for path in sorted(shell.rglob('*.py'))
             if path != shell / 'ros' / 'settings.py'
             for number, line in enumerate(path.read_text().splitlines(), 1)
             if 'declare_parameter(' in line or 'get_parameter(' in line]
    assert not found
