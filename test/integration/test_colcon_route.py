"""The colcon route of docs/flexbe.md, without a ROS installation, as CI can run it.

A workspace whose ``src/`` holds ``synthesis_msgs``, our two FlexBE packages, the launch package
``behavior_synthesis_bringup`` and an exported behavior package is built with ``colcon build`` (colcon-common-extensions from PyPI) in the
environment docs/flexbe.md gives; after ``source install/setup.bash`` the packages import from
the workspace, ``ros2 launch`` finds the suite's launch file there (the ament index), and
flexbe_core's BehaviorLibrary, as the onboard executive uses it, finds the behavior and its source there.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from flexbe_workspace import WORKSPACE_PACKAGES

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.ros, pytest.mark.flexbe, pytest.mark.slow]

REPOSITORY = Path(__file__).resolve().parents[2]
DOCS = REPOSITORY / 'docs' / 'flexbe.md'
BEHAVIOR = 'Colcon Pickup'
FIND_BEHAVIOR = f'''
import rclpy
from rclpy.node import Node
from flexbe_core import BehaviorLibrary
rclpy.init()
library = BehaviorLibrary(Node('colcon_route_check'))
key, entry = library.find_behavior({BEHAVIOR!r})
print(entry['package'], library.get_sourcecode_filepath(key))
rclpy.shutdown()
'''


FIND_LAUNCH_FILE = '''
from pathlib import Path
from ament_index_python.packages import get_package_share_directory
print(Path(get_package_share_directory('behavior_synthesis_bringup')) / 'launch' / 'suite.launch.py')
'''


def documented_commands() -> list[str]:
    """The sh block of docs/flexbe.md's "colcon without a ROS installation" section."""
    section = DOCS.read_text().split('## colcon without a ROS installation', 1)[1]
    block = re.search(r'```sh\n(.*?)```', section, re.S).group(1)
    return [line for line in block.splitlines() if line.strip()]


# Not 2x faster (issue 50): the documented `colcon build` of 5 packages from an empty workspace is what it tests
# (38.5 s).
def test_the_documented_colcon_build_installs_packages_flexbe_finds(tmp_path, flexbe):
    from synthesis_manager.ros.harness import reserve_domain_id
    from synthesis_manager.ros.env import prepare_ros_environment

    colcon = Path(sys.executable).parent / 'colcon'
    assert colcon.exists(), 'colcon is not installed: it comes with the test extra (pyproject.toml)'
    source = tmp_path / 'ws' / 'src'
    source.mkdir(parents=True)
    for package in WORKSPACE_PACKAGES:
        shutil.copytree(REPOSITORY / package, source / Path(package).name)
    exported = subprocess.run([str(Path(sys.executable).parent / 'behavior-synthesis'), 'export-behavior',
                               '--system', 'atlas', '--initial-conditions', 'stand_prep',
                               '--goals', 'look_down,pickup_object', '--name', BEHAVIOR, '-o', str(source)],
                              capture_output=True, text=True, timeout=120)
    assert exported.returncode == 0, exported.stderr
    commands = documented_commands()
    assert commands[-1] == 'source install/setup.bash' and commands[1].startswith('colcon build')
    with reserve_domain_id() as domain:
        environment = prepare_ros_environment(domain, environ={key: value for key, value in os.environ.items()
                                                               if key not in ('AMENT_PREFIX_PATH', 'PYTHONPATH')})
        script = '\n'.join(['set -e', f'REPO={REPOSITORY}', 'cd ws', *commands,
                            f'{sys.executable} -c "{FIND_LAUNCH_FILE}"', f'{sys.executable} -c "{FIND_BEHAVIOR}"'])
        built = subprocess.run(['bash', '-c', script], cwd=tmp_path, env=environment, capture_output=True,
                               text=True, timeout=1200)
    assert built.returncode == 0, (built.stdout[-3000:], built.stderr[-3000:])
    assert 'Summary: 5 packages finished' in built.stdout
    # `ros2 launch behavior_synthesis_bringup suite.launch.py` finds its file in the workspace
    (launch_file,) = [Path(line) for line in built.stdout.splitlines() if line.endswith('/launch/suite.launch.py')]
    assert launch_file.is_file() and launch_file.resolve().is_relative_to((tmp_path / 'ws' / 'install').resolve())
    package, source_file = built.stdout.strip().splitlines()[-1].split(' ', 1)
    install = tmp_path / 'ws' / 'install'
    assert package == 'synthesized_flexbe_behaviors'
    assert Path(source_file).resolve().is_relative_to(install.resolve()), source_file
    assert (install / 'synthesis_msgs').is_dir() and (install / 'atlas_sim_flexbe_states').is_dir()
