"""RobotSystem: one object per robot system, read once, its kind decided when it is read."""

import argparse
import os
import shutil
from pathlib import Path

import pytest

from ltl_specification import compile_task
from respec.robot import (ABSTRACTION_KIND, CAPABILITIES_KIND, RobotSystem, SystemCatalog, robot_system,
                          robot_system_from_files)
from respec.robot.abstraction import AbstractionConfigError
from respec.robot.cnu import CapabilityConfigError
from respec.robot.files import (CONFIG_DIR_ENV, ConfigDirectoryNotFoundError, ConfigFileInvalidError,
                                SystemNotFoundError, add_config_dir_argument, config_search_path)

CONFIG = Path(__file__).resolve().parents[2] / 'config'


def test_atlas_is_an_abstraction_kind_system_with_its_sections():
    atlas = robot_system('atlas')
    assert atlas.kind == ABSTRACTION_KIND and atlas.capabilities is None
    assert atlas.name == 'atlas' and atlas.config_file == 'config/atlas.yaml'
    assert 'look_down' in atlas.abstraction.actions
    assert set(atlas.section('flexbe')) >= {'states'} and atlas.has_section('simulation')
    assert list(atlas.files) == ['atlas.yaml'] and atlas.files['atlas.yaml'] == (CONFIG / 'atlas.yaml').read_text()
    assert robot_system(atlas) is atlas  # already resolved: taken as it is


def test_a_missing_section_is_named():
    with pytest.raises(ConfigFileInvalidError, match="missing or invalid section 'nope'"):
        robot_system('atlas').section('nope')


def test_unknown_and_broken_systems_are_reported_with_the_offending_item(tmp_path):
    with pytest.raises(SystemNotFoundError, match='known systems: atlas, delivery_rover, mobile_manipulator'):
        robot_system('marsrover')
    (tmp_path / 'broken.yaml').write_text('abstraction:\n  actions: {a: [b]}\n')
    with pytest.raises(AbstractionConfigError) as raised:
        robot_system('broken', tmp_path)
    assert raised.value.item
    (tmp_path / 'cnu.yaml').write_text('system: cnu\ncnu_capabilities: missing.yaml\n')
    with pytest.raises(CapabilityConfigError, match="cnu_capabilities 'missing.yaml' cannot be read"):
        robot_system('cnu', tmp_path)


def test_a_binary_or_huge_number_config_file_is_invalid_in_few_words(tmp_path):
    """Issue 34 item 11: not an internal error, and the message does not carry the file."""
    (tmp_path / 'binary.yaml').write_bytes(bytes(range(128, 256)) * 94)  # 11.8 KB, not UTF-8
    (tmp_path / 'digits.yaml').write_text('abstraction:\n  actions: {a: ' + '9' * 60_000 + '}\n')
    (tmp_path / 'cnu.yaml').write_text('system: cnu\ncnu_capabilities: capabilities.yaml\n')
    (tmp_path / 'capabilities.yaml').write_text('x: ' + '9' * 60_000 + '\n')
    for name, words in [('binary', 'not UTF-8 text (byte 0x80 at position 0)'),
                        ('digits', 'an integer has more than 4300 digits')]:
        with pytest.raises(ConfigFileInvalidError) as raised:
            robot_system(name, tmp_path)
        assert words in str(raised.value) and len(str(raised.value)) < 300
        assert raised.value.code == 'CONFIG_FILE_INVALID'
    with pytest.raises(CapabilityConfigError, match='an integer has more than 4300 digits'):
        robot_system('cnu', tmp_path)


def test_a_system_rebuilt_from_its_files_is_the_same_system():
    atlas = robot_system('atlas')
    copy = robot_system_from_files('atlas', dict(atlas.files))
    assert copy == atlas and copy.config_file == atlas.config_file
    assert copy.section('flexbe') == atlas.section('flexbe')
    first = compile_task(atlas, ['stand_prep'], ['look_down', 'pickup_object'])
    second = compile_task(copy, ['stand_prep'], ['look_down', 'pickup_object'])
    assert first.to_structuredslugs() == second.to_structuredslugs()


@pytest.mark.flexbe
def test_a_capability_system_keeps_every_file_it_read(tmp_path, flexbe_sources):
    cnu = flexbe_sources / 'flexbe_synthesis'
    examples = cnu / 'flexbe_synthesis_examples' / 'example' / 'vending_demo'
    (tmp_path / 'vending.yaml').write_text(
        f'cnu_capabilities: {examples}/capabilities/vending_capabilities.yaml\n'
        f'cnu_spec: {examples}/specs/vending_demo_capabilities_spec.yaml\n'
        f'cnu_mappings: {cnu}/flexbe_synthesis_generic/mappings/global_mappings.yaml\n')
    vending = robot_system('vending', tmp_path)
    assert vending.kind == CAPABILITIES_KIND and vending.abstraction is None
    assert len(vending.files) == 4  # the system file and the three CNU files
    copy = robot_system_from_files('vending', dict(vending.files))
    assert copy.capabilities == vending.capabilities
    with pytest.raises(CapabilityConfigError, match='cannot be read'):
        robot_system_from_files('vending', {'vending.yaml': vending.files['vending.yaml']})


@pytest.mark.flexbe
def test_unchanged_files_are_not_parsed_again_and_any_edit_is_seen(tmp_path, flexbe_sources):
    """Loading reads every file of the system each time; it parses them only when a text changed."""
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: []}\n')
    first = robot_system('tiny', tmp_path)
    assert robot_system('tiny', tmp_path) is first
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {waves: []}\n')  # same size, same instant
    assert list(robot_system('tiny', tmp_path).abstraction.actions) == ['waves']
    # A file the system file points at counts too (here CNU's capabilities, copied to be edited).
    examples = flexbe_sources / 'flexbe_synthesis' / 'flexbe_synthesis_examples' / 'example' / 'vending_demo'
    shutil.copy(examples / 'capabilities' / 'vending_capabilities.yaml', tmp_path / 'capabilities.yaml')
    shutil.copy(examples / 'specs' / 'vending_demo_capabilities_spec.yaml', tmp_path / 'spec.yaml')
    (tmp_path / 'vending.yaml').write_text('cnu_capabilities: capabilities.yaml\ncnu_spec: spec.yaml\n')
    vending = robot_system('vending', tmp_path)
    assert robot_system('vending', tmp_path) is vending
    text = (tmp_path / 'capabilities.yaml').read_text()
    (tmp_path / 'capabilities.yaml').write_text(text + '\n# edited\n')
    edited = robot_system('vending', tmp_path)
    assert edited is not vending and edited.files['capabilities.yaml'].endswith('# edited\n')
    (tmp_path / 'capabilities.yaml').unlink()
    with pytest.raises(CapabilityConfigError, match='cannot be read'):
        robot_system('vending', tmp_path)


def test_the_catalog_lists_and_loads_the_systems_of_its_folders(tmp_path):
    assert SystemCatalog().names() == ['atlas', 'delivery_rover', 'mobile_manipulator', 'shelf_picker']
    assert isinstance(SystemCatalog().load('mobile_manipulator'), RobotSystem)
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: []}\n')
    catalog = SystemCatalog(tmp_path)  # adds to the shipped systems
    assert catalog.names() == ['atlas', 'delivery_rover', 'mobile_manipulator', 'shelf_picker', 'tiny']
    assert catalog.load('tiny').abstraction.actions == {'wave': ()}
    assert catalog.load('atlas') == robot_system('atlas')
    # Loading reads afresh: an edit is seen by the next request.
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: [], nod: []}\n')
    assert list(catalog.load('tiny').abstraction.actions) == ['wave', 'nod']


def test_the_catalogs_fingerprint_changes_with_any_file_under_its_folders(tmp_path):
    """What a node watching for changes compares instead of loading every system again: the
    same while nothing changed; another one after an edit, a new file or a removed one, in a
    subfolder too (CNU's files sit beside their system file)."""
    catalog = SystemCatalog(tmp_path)
    (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: []}\n')
    (tmp_path / 'vending').mkdir()
    (tmp_path / 'vending' / 'capabilities.yaml').write_text('capabilities: {}\n')
    first = catalog.fingerprint()
    assert catalog.fingerprint() == first
    assert str(tmp_path / 'vending' / 'capabilities.yaml') in {path for path, _, _ in first}
    assert str(CONFIG / 'atlas.yaml') in {path for path, _, _ in first}  # the shipped folder too
    before = first
    for change in (lambda: (tmp_path / 'tiny.yaml').write_text('abstraction:\n  actions: {wave: [], nod: []}\n'),
                   lambda: (tmp_path / 'vending' / 'capabilities.yaml').write_text('capabilities: {a: 1}\n'),
                   lambda: (tmp_path / 'other.yaml').write_text('abstraction: {}\n'),
                   lambda: (tmp_path / 'other.yaml').unlink()):
        change()
        assert catalog.fingerprint() != before
        before = catalog.fingerprint()
    assert before == catalog.fingerprint()

def tiny_system(directory: Path, action: str) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    (directory / 'tiny.yaml').write_text(f'abstraction:\n  actions: {{{action}: []}}\n')
    return directory


def test_config_directories_add_to_the_shipped_systems_and_shadow_in_order(tmp_path, monkeypatch):
    monkeypatch.delenv(CONFIG_DIR_ENV, raising=False)
    first, second = tiny_system(tmp_path / 'first', 'wave'), tiny_system(tmp_path / 'second', 'nod')
    shutil.copy(CONFIG / 'atlas.yaml', second / 'atlas.yaml')
    (second / 'robot_b.yaml').write_text('abstraction:\n  actions: {beep: []}\n')
    joined = os.pathsep.join([str(first), str(second)])
    assert config_search_path(joined) == (first, second, CONFIG)
    assert config_search_path([first, str(second)]) == config_search_path(joined)
    assert SystemCatalog(joined).names() == ['atlas', 'delivery_rover', 'mobile_manipulator', 'robot_b', 'shelf_picker',
                                              'tiny']
    assert list(robot_system('tiny', joined).abstraction.actions) == ['wave']     # the first directory's
    assert list(robot_system('tiny', [second, first]).abstraction.actions) == ['nod']
    assert robot_system('atlas', joined).path == second / 'atlas.yaml'          # shadows config/atlas.yaml
    assert robot_system('mobile_manipulator', joined).path == CONFIG / 'mobile_manipulator.yaml'
    # The environment's directories come after the given ones and before config/.
    monkeypatch.setenv(CONFIG_DIR_ENV, str(second))
    assert config_search_path(first) == (first, second, CONFIG)
    assert list(robot_system('tiny').abstraction.actions) == ['nod'] and 'robot_b' in SystemCatalog().names()


def test_where_systems_were_looked_for_is_named(tmp_path, monkeypatch):
    monkeypatch.delenv(CONFIG_DIR_ENV, raising=False)
    with pytest.raises(SystemNotFoundError) as unknown:
        robot_system('marsrover', tmp_path)
    assert f'no marsrover.yaml in {tmp_path}, {CONFIG}' in str(unknown.value)
    with pytest.raises(ConfigDirectoryNotFoundError, match='does not exist') as missing:
        SystemCatalog(tmp_path / 'nowhere').names()
    assert missing.value.item == str(tmp_path / 'nowhere') and missing.value.code.name == 'SYSTEM_CONFIG_NOT_FOUND'
    monkeypatch.setenv(CONFIG_DIR_ENV, str(tmp_path / 'gone'))
    with pytest.raises(ConfigDirectoryNotFoundError, match='gone'):
        robot_system('atlas')


def test_config_dir_options_add_up():
    parser = argparse.ArgumentParser()
    add_config_dir_argument(parser)
    assert parser.parse_args([]).config_dir == ''
    assert parser.parse_args(['--config-dir', 'a', '--config-dir', 'b']).config_dir == os.pathsep.join(['a', 'b'])
