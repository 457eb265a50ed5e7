"""What the launch files need to find the suite: its scripts, installed with the suite's own
Python (this repository's `make setup` venv, or any Python with behavior-synthesis installed),
which need not be the Python that runs `ros2`."""

import os
import shutil
from pathlib import Path

SUITE_SCRIPT = 'behavior-synthesis'
#: Names the suite's behavior-synthesis script when it is not on PATH.
SUITE_SCRIPT_VARIABLE = 'BEHAVIOR_SYNTHESIS'


def suite_script(name: str = SUITE_SCRIPT) -> str:
    """The suite's script ``name`` (``atlas-sim-node``, ...): beside its behavior-synthesis."""
    script = os.environ.get(SUITE_SCRIPT_VARIABLE) or shutil.which(SUITE_SCRIPT)
    if not script:
        raise RuntimeError(f'{SUITE_SCRIPT} not found: add the suite\'s bin folder to PATH '
                           f'(e.g. export PATH=$PATH:$HOME/behavior_synthesis/.venv/bin) or set '
                           f'{SUITE_SCRIPT_VARIABLE} to its {SUITE_SCRIPT}')
    found = Path(script).parent / name
    if not found.is_file():
        raise RuntimeError(f'{found} does not exist (the suite\'s scripts are found beside {script})')
    return str(found)


def suite_python() -> str:
    """The interpreter of the suite's scripts (their #! line)."""
    script = suite_script()
    with open(script, 'rb') as file:
        first = file.readline().decode().strip()
    if not first.startswith('#!'):
        raise RuntimeError(f'{script} is not a script of the suite (no #! line)')
    return first[2:].strip().split()[0]
