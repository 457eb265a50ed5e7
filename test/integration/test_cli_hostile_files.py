"""No command prints a traceback for any input file (issue 48, item 7): each command that reads a
file is fed hostile ones (a YAML alias bomb, JSON and YAML nested 100,000 deep, bytes that are
not UTF-8, a FIFO, a directory, a 200 MB file, a missing path) and answers with a coded line
and a non-zero exit status, at once."""

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

BIN = Path(sys.executable).parent
TASK = ['--system', 'atlas', '--initial-conditions', 'stand_prep', '--goals', 'look_down']
COMMANDS = {
    'compile --custom-ltl': lambda f: ['behavior-synthesis', 'compile', *TASK, '--custom-ltl', f],
    'repair --custom-ltl': lambda f: ['behavior-synthesis', 'repair', *TASK, '--custom-ltl', f, '--time-budget', '2'],
    'generate-sm --automaton': lambda f: ['behavior-synthesis', 'generate-sm', '--automaton', f],
    'generate-sm --spec': lambda f: ['behavior-synthesis', 'generate-sm', '--automaton', strategy(f), '--spec', f],
    'send-goal --synthesis-only': lambda f: ['behavior-synthesis', 'send-goal', '--synthesis-only', f],
    'gr1synth': lambda f: ['gr1synth', f],
}


def strategy(beside: str) -> str:
    """A slugs strategy file (which needs --spec) in the hostile file's folder."""
    path = Path(beside).parent / 'strategy.json'
    path.write_text('{"variables": ["x"], "nodes": {"0": {"rank": 0, "state": [1], "trans": [0]}}}')
    return str(path)


def alias_bomb() -> str:
    return 'l0: &l0 [x]\n' + ''.join(f'l{i}: &l{i} [{", ".join([f"*l{i - 1}"] * 10)}]\n' for i in range(1, 10))


def hostile_file(folder: Path, kind: str) -> Path:
    suffix = '.json' if kind in ('deep JSON', 'FIFO', 'not UTF-8') else '.yaml'
    path = folder / f'hostile{suffix}'
    if kind == 'alias bomb':
        path.write_text(alias_bomb())
    elif kind == 'deep JSON':
        path.write_text('[' * 100_000 + ']' * 100_000)
    elif kind == 'deep YAML':
        path.write_text('{a: ' * 100_000 + '1' + '}' * 100_000)
    elif kind == 'not UTF-8':
        path.write_bytes(b'{"a": "\xff\xfe\x80"}')
    elif kind == 'FIFO':
        os.mkfifo(path)
    elif kind == 'directory':
        path.mkdir()
    elif kind == '200 MB':
        with open(path, 'wb') as file:
            file.truncate(200 * 2**20)
    return path  # 'missing': never made


@pytest.mark.parametrize('kind', ['alias bomb', 'deep JSON', 'deep YAML', 'not UTF-8', 'FIFO', 'directory',
                                  '200 MB', 'missing'])
@pytest.mark.parametrize('command', COMMANDS)
def test_every_command_refuses_a_hostile_file_with_a_line_not_a_traceback(tmp_path, command, kind):
    path = hostile_file(tmp_path, kind)
    began = time.monotonic()
    done = subprocess.run([str(BIN / word) if index == 0 else str(word) for index, word in
                           enumerate(COMMANDS[command](str(path)))], capture_output=True, text=True, timeout=60,
                          env=dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST'))
    seconds = time.monotonic() - began
    output = done.stdout + done.stderr
    assert done.returncode != 0, output[-2000:]
    assert 'Traceback' not in output and 'RecursionError' not in output, output[-3000:]
    assert len(done.stderr) < 2000, done.stderr[:500]
    assert seconds < 30, f'{seconds:.1f} s'
