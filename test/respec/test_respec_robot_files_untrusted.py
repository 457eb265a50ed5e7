"""Robot files are untrusted input (issue 48, item 3): YAML aliases, depth and size are bounded
in every robot file, and the files a system file references stay inside its config folder
(no absolute path, no ``..`` out, no symbolic link out, nothing but regular files)."""

import os
import shutil
import threading
import time
from pathlib import Path

import pytest

from respec.vocabulary.errors import ErrorCode
from respec.robot import robot_system
from respec.robot.cnu import CapabilityConfigError
from respec.robot.files import MAX_CONFIG_DEPTH, MAX_CONFIG_FILE_BYTES, ConfigFileInvalidError, SystemConfigError

CONFIG = Path(__file__).resolve().parents[2] / 'config'
#: 12 KB of text that would expand to 10^9 leaves.
ALIAS_BOMB = ''.join(f'l{i}: &l{i} [{", ".join([f"*l{i - 1}"] * 10)}]\n' for i in range(1, 10))


def atlas_copy(folder: Path, extra: str) -> Path:
    folder.mkdir(exist_ok=True)
    path = folder / 'bombed.yaml'
    path.write_text((CONFIG / 'atlas.yaml').read_text() + extra)
    return path


def test_an_alias_bomb_in_a_system_file_is_refused_at_once_naming_the_line(tmp_path):
    atlas_copy(tmp_path, 'l0: &l0 [x]\n' + ALIAS_BOMB)
    began = time.monotonic()
    with pytest.raises(ConfigFileInvalidError) as raised:
        robot_system('bombed', tmp_path)
    assert time.monotonic() - began < 1.0
    assert raised.value.code == ErrorCode.CONFIG_FILE_INVALID
    message = str(raised.value)
    lines = (CONFIG / 'atlas.yaml').read_text().count('\n') + 2
    assert 'YAML aliases (*name) are not accepted' in message and f'(line {lines}, column ' in message
    assert len(message) < 300


def test_nesting_deeper_than_the_bound_is_refused(tmp_path):
    atlas_copy(tmp_path, 'deep: ' + '[' * (MAX_CONFIG_DEPTH + 5) + ']' * (MAX_CONFIG_DEPTH + 5) + '\n')
    with pytest.raises(ConfigFileInvalidError, match=f'nested deeper than {MAX_CONFIG_DEPTH} levels'):
        robot_system('bombed', tmp_path)


def test_a_file_over_the_size_bound_is_refused_without_reading_it_all(tmp_path):
    atlas_copy(tmp_path, '# ' + 'x' * MAX_CONFIG_FILE_BYTES + '\n')
    with pytest.raises(ConfigFileInvalidError, match='larger than 4 MiB, the most accepted here'):
        robot_system('bombed', tmp_path)


def test_invalid_yaml_names_line_and_column_but_quotes_no_line_of_the_file(tmp_path):
    path = tmp_path / 'broken.yaml'
    path.write_text('abstraction:\n  secret_token_here: [unclosed\n')
    with pytest.raises(ConfigFileInvalidError) as raised:
        robot_system('broken', tmp_path)
    assert 'not valid YAML' in str(raised.value) and '(line 3, column 1)' in str(raised.value)
    assert 'secret_token_here' not in str(raised.value)


def test_a_system_file_linked_to_a_file_outside_its_folder_is_refused(tmp_path):
    private = tmp_path / 'private'
    private.mkdir()
    secret = private / 'secret.yaml'
    secret.write_text((CONFIG / 'atlas.yaml').read_text())
    secret.chmod(0o600)
    robots = tmp_path / 'robots'
    robots.mkdir()
    (robots / 'leaky.yaml').symlink_to(secret)
    with pytest.raises(ConfigFileInvalidError, match='resolves outside the config folder') as raised:
        robot_system('leaky', robots)
    assert 'look_down' not in str(raised.value)


def rover_copy(folder: Path, **references: str) -> None:
    shutil.copytree(CONFIG / 'delivery_rover', folder / 'delivery_rover')
    text = (CONFIG / 'delivery_rover.yaml').read_text()
    for key, value in references.items():
        lines = [line for line in text.splitlines() if not line.startswith(f'{key}:')]
        text = '\n'.join([*lines, f'{key}: {value}']) + '\n'
    (folder / 'rover.yaml').write_text(text)


@pytest.mark.parametrize('reference', ['absolute', 'dotdot', 'link out'])
def test_references_out_of_the_config_folder_are_refused(tmp_path, reference):
    outside = tmp_path / 'secret'
    outside.mkdir()
    (outside / 'x.txt').write_text('password: hunter2\n')
    robots = tmp_path / 'robots'
    robots.mkdir()
    value = {'absolute': str(outside / 'x.txt'), 'dotdot': '../secret/x.txt', 'link out': 'delivery_rover/link.yaml'}
    rover_copy(robots, cnu_spec=value[reference])
    (robots / 'delivery_rover' / 'link.yaml').symlink_to(outside / 'x.txt')
    with pytest.raises(CapabilityConfigError) as raised:
        robot_system('rover', robots)
    assert raised.value.item == 'cnu_spec' and 'hunter2' not in str(raised.value)
    assert 'outside the config folder' in str(raised.value) or 'must be a path relative' in str(raised.value)


def test_a_fifo_referenced_by_a_system_file_is_never_waited_on(tmp_path):
    rover_copy(tmp_path, cnu_spec='delivery_rover/pipe.yaml')
    os.mkfifo(tmp_path / 'delivery_rover' / 'pipe.yaml')
    outcome = []

    def load():
        try:
            robot_system('rover', tmp_path)
        except SystemConfigError as error:
            outcome.append(error)
    reader = threading.Thread(target=load, daemon=True)
    reader.start()
    reader.join(5)
    assert not reader.is_alive() and 'not a regular file' in str(outcome[0])


def test_references_inside_the_folder_still_work(tmp_path):
    rover_copy(tmp_path)
    assert robot_system('rover', tmp_path).capabilities is not None

