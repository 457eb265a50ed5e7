"""FlexBE's own onboard executive with our robot and operator as processes, shared by
test/integration/test_flexbe_onboard.py (and the tests that import from it) and
bench/bench_flexbe_onboard.py.

An exported behavior package is installed into a prefix the way a user without colcon does
(pip); ``OnboardSystem`` starts ``atlas-sim-node`` (the robot), ``atlas-sim-operator`` (answers
InputState as flexbe_input's ``input_action_server`` does) and ``flexbe_onboard.start_behavior``
on a ROS domain; ``Operator`` watches ``flexbe/status`` and ``flexbe/log`` and starts a behavior
with a ``flexbe_msgs/BehaviorSelection`` as be_launcher does.
"""

from __future__ import annotations

import importlib
import os
import signal
import subprocess
import sys
import threading
import time
import zlib
from pathlib import Path

from rclpy.action import ActionClient
from rclpy.node import Node

BIN = Path(sys.executable).parent


def exported_and_installed(work: Path, export_arguments, package='synthesized_flexbe_behaviors', environment=None,
                           edit=None):
    """``export-behavior`` with ``export_arguments``, its package installed into a prefix with pip (no colcon);
    ``edit(package_folder)``, when given, changes the exported files first."""
    exported = subprocess.run([str(BIN / 'behavior-synthesis'), 'export-behavior', *export_arguments,
                               '--package', package, '-o', str(work / 'src')],
                              capture_output=True, text=True, timeout=120, env=environment)
    assert exported.returncode == 0, exported.stderr
    if edit:
        edit(work / 'src' / package)
    prefix = work / 'install'
    pip = subprocess.run([sys.executable, '-m', 'pip', 'install', '--quiet', '--no-deps', '--no-build-isolation',
                          '--no-index', '--prefix', str(prefix), str(work / 'src' / package)],
                         capture_output=True, text=True, timeout=300)
    assert pip.returncode == 0, pip.stderr
    return prefix


class OnboardSystem:
    """The robot, the operator and FlexBE's onboard executive as processes on ``ros.domain_id``."""

    def __init__(self, ros, prefix: Path, flexbe_prefix: Path, logs: Path, sim_arguments=(), operator_arguments=(),
                 operator_command=None, operator_path=(), robot=True):
        self.site = prefix / 'lib' / f'python{sys.version_info.major}.{sys.version_info.minor}' / 'site-packages'
        self.ament_prefix_path = os.pathsep.join([str(prefix), str(flexbe_prefix), sys.prefix])
        self.environment = dict(os.environ, ROS_DOMAIN_ID=str(ros.domain_id), MUJOCO_GL='egl',
                                AMENT_PREFIX_PATH=self.ament_prefix_path,
                                PYTHONPATH=os.pathsep.join(filter(None, [str(self.site), *operator_path,
                                                                           os.environ.get('PYTHONPATH')])))
        self.logs = logs
        self.processes = {}
        if robot:  # a behavior of FlexBE's own states (CNU's LogState capabilities) needs no robot
            self.start('sim', [str(BIN / 'atlas-sim-node'), '--ros-args', '-p', 'speed:=20.0', *sim_arguments])
            self.start('operator', operator_command or [str(BIN / 'atlas-sim-operator'), *operator_arguments])
        self.start('onboard', [sys.executable, '-m', 'flexbe_onboard.start_behavior'])

    def start(self, name, command):
        log = open(self.logs / f'{name}.log', 'w', encoding='utf-8')  # noqa: SIM115 - closed in stop()
        self.processes[name] = (subprocess.Popen(command, env=self.environment, stdout=log, stderr=subprocess.STDOUT,
                                                 text=True), log)

    def log(self, name) -> str:
        path = self.logs / f'{name}.log'
        return path.read_text(encoding='utf-8', errors='replace') if path.exists() else f'(no {name} process)'


    def stop(self):
        for process, _ in self.processes.values():
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
        for name, (process, log) in self.processes.items():
            try:
                process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                process.kill()
                process.wait()
            log.close()


class Operator:
    """What a FlexBE operator sees: the status and log topics; starts behaviors like be_launcher."""

    def __init__(self, ros):
        from flexbe_msgs.msg import BehaviorLog, BEStatus
        from synthesis_msgs.msg import RobotState

        self.node = ros.add_node(Node, 'onboard_test_operator')
        self.statuses, self.logs, self.robot = [], [], []
        self.lock = threading.Lock()
        self.node.create_subscription(BEStatus, 'flexbe/status', lambda m: self._keep(self.statuses, m), 10)
        self.node.create_subscription(BehaviorLog, 'flexbe/log', lambda m: self._keep(self.logs, m), 100)
        self.node.create_subscription(RobotState, 'atlas_sim/state', lambda m: self._keep(self.robot, m), 10)

    def _keep(self, messages, message):
        with self.lock:
            messages.append(message)

    def wait_until(self, condition, timeout, what):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                found = condition()
            if found:
                return found
            time.sleep(0.05)
        raise AssertionError(f'no {what} within {timeout} s')

    def wait_for_servers(self):
        from flexbe_msgs.action import BehaviorInput
        from synthesis_msgs.action import ExecuteCapability

        for action_type, name in ((BehaviorInput, 'flexbe/behavior_input'), (ExecuteCapability, 'atlas_sim/execute')):
            client = ActionClient(self.node, action_type, name)
            assert client.wait_for_server(timeout_sec=30.0), f'{name} is not served'

    def start_behavior(self, name: str, autonomy: int = 3, robot: bool = True, timeout: float = 120):
        """A BehaviorSelection for ``name`` as be_launcher sends it; returns the final BEStatus
        (AssertionError when none comes within ``timeout`` seconds)."""
        from flexbe_core import BehaviorLibrary
        from flexbe_msgs.msg import BehaviorSelection, BEStatus

        if robot:
            self.wait_for_servers()
        self.wait_until(lambda: any(s.code == BEStatus.READY for s in self.statuses), 40, 'READY from onboard')
        library = BehaviorLibrary(self.node)
        key, entry = library.find_behavior(name)
        assert entry is not None, f'{name} is not in the behavior library'
        # The library finds the source through an import of the behavior's package: this process
        # may hold a package of that name from another prefix (an earlier run), so import afresh.
        for module in [m for m in sys.modules if m == entry['package'] or m.startswith(entry['package'] + '.')]:
            del sys.modules[module]
        importlib.invalidate_caches()
        source = Path(library.get_sourcecode_filepath(key)).read_text(encoding='utf-8')
        selection = BehaviorSelection(behavior_key=key, behavior_id=zlib.adler32(source.encode()) & 0x7fffffff,
                                      autonomy_level=autonomy)
        publisher = self.node.create_publisher(BehaviorSelection, 'flexbe/start_behavior', 10)
        self.wait_until(lambda: publisher.get_subscription_count() > 0, 10, 'subscriber of flexbe/start_behavior')
        publisher.publish(selection)
        ended = (BEStatus.FINISHED, BEStatus.FAILED, BEStatus.ERROR)
        return self.wait_until(lambda: next((s for s in self.statuses if s.code in ended), None), timeout,
                               'end of the behavior')

    def log_text(self) -> str:
        with self.lock:
            return '\n'.join(m.text for m in self.logs)


def finished_with(status, outcome, system):
    from flexbe_msgs.msg import BEStatus

    return status.code == BEStatus.FINISHED and list(status.args) == [outcome], (
        f'{status.code} {list(status.args)}\n--- onboard\n{system.log("onboard")[-3000:]}\n'
        f'--- sim\n{system.log("sim")[-1500:]}\n--- operator\n{system.log("operator")[-1500:]}')
