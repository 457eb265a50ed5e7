"""The check that a test declares the kinds of things it starts (installed by test/conftest.py).

A test declares them as markers: ``pytestmark = [pytest.mark.ros, ...]`` in its module or a mark
on the test. While a test runs (its fixtures' setup included), wrappers around the places that
start each kind fail it when its marker is missing, naming the marker:

    ros       rclpy.init (RosHarness, the GUI's in-process suite, a node of the test's own), and a
              child process running a ROS program: behavior-synthesis serve, gui, execute,
              export-behavior, send-goal, start-behavior or demo, a node script, ros2; unless
              it only showed its --help or ended with the usage status (2: it refused its
              command line or its input file before starting ROS)
    browser   Playwright started, or launching Chromium
    mujoco    a MuJoCo model created
    flexbe    the ``flexbe`` or ``flexbe_sources`` fixture
    external  a child process running a program that is not Python (Graphviz' dot, slugs, Node.js),
              from a test that has none of the markers above (nor slow): the pure-core selection
              runs Python only

Starts in a thread of the test, and ROS programs (judged by how they ended), fail it at its
teardown. What a child process starts in turn is not followed (a ros test's GUI simulates with
MuJoCo in a child process of its own).
"""

from __future__ import annotations

import contextlib
import importlib.abc
import importlib.util
import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest

KINDS = ('ros', 'browser', 'mujoco', 'flexbe')
# A test marked with any of these may run programs that are not Python.
MAY_RUN_PROGRAMS = (*KINDS, 'slow', 'netns', 'external')
ROS_COMMANDS = {'serve', 'gui', 'execute', 'export-behavior', 'send-goal', 'start-behavior', 'demo'}
ROS_PROGRAMS = {'ros2', 'ltl-compilation-node', 'ltl-synthesis-node', 'sm-generation-node',
                'behavior-synthesis-server', 'atlas-sim-node', 'atlas-sim-operator'}
FLEXBE_FIXTURES = {'flexbe', 'flexbe_sources'}
USAGE_STATUS = 2  # README's exit status table: a bad command line or an unreadable argument file


class _Running:
    """The test running now and what its threads started undeclared."""

    item = None
    late: list[str] = []
    ros_programs: list = []  # (process, what) of the ROS programs the test started


def current_markers() -> set[str] | None:
    """The markers of the test running now (None between tests)."""
    item = _Running.item
    return None if item is None else {marker.name for marker in item.iter_markers()}


def starting(kind: str, what: str) -> None:
    """``what`` (a kind ``kind`` of thing) is starting: fail the running test unless it declares ``kind``."""
    markers = current_markers()
    if markers is None or kind in markers:
        return
    complaint = _complaint(kind, what)
    if threading.current_thread() is threading.main_thread():
        pytest.fail(complaint, pytrace=False)
    _Running.late.append(complaint)


def _complaint(kind: str, what: str) -> str:
    return f'{_Running.item.nodeid} {what} without the marker {kind!r}: add pytest.mark.{kind} to it'


def check_fixtures(request) -> None:
    """A test using FlexBE's fixtures runs the real FlexBE."""
    used = FLEXBE_FIXTURES & set(request.fixturenames)
    if used:
        starting('flexbe', f'uses the fixture {sorted(used)[0]} (the real FlexBE)')


@contextlib.contextmanager
def running(item):
    """While ``item`` runs (setup, call and teardown), starts are checked against its markers."""
    _Running.item, _Running.late, _Running.ros_programs = item, [], []
    try:
        yield
    finally:
        _Running.item = None


def late_complaints() -> list[str]:
    """What the test started undeclared in threads, and ROS programs that did more than refuse."""
    for process, what in _Running.ros_programs:
        if process.poll() != USAGE_STATUS:
            _Running.late.append(_complaint('ros', what))
    complaints, _Running.late, _Running.ros_programs = _Running.late, [], []
    return complaints


# --- the wrappers -----------------------------------------------------------------------------

def _runs_python(program: str) -> bool:
    """``program`` is a Python interpreter or script, or nothing at all (no such program runs)."""
    path = shutil.which(program) or program
    if not os.path.isfile(path):
        return True
    if Path(path).name.startswith('python') or os.path.realpath(path) == os.path.realpath(sys.executable):
        return True
    try:
        with open(path, 'rb') as file:
            first = file.readline(200)
    except OSError:
        return False
    return first.startswith(b'#!') and b'python' in first


def _check_command(args) -> str | None:
    """Fails a test running a program that is not Python undeclared; returns what a ROS program is."""
    argv = [str(args)] if isinstance(args, (str, bytes, os.PathLike)) else [str(part) for part in args]
    if not argv:
        return None
    program = Path(argv[0]).name
    words = argv[1:]
    if (program == 'behavior-synthesis' and words and words[0] in ROS_COMMANDS or program in ROS_PROGRAMS) \
            and not {'--help', '-h'} & set(words):
        ros = f'runs `{program} {words[0]}` (ROS)' if program == 'behavior-synthesis' else f'runs `{program}` (ROS)'
    else:
        ros = None
    markers = current_markers()
    if markers is not None and not markers & set(MAY_RUN_PROGRAMS) and not _runs_python(argv[0]):
        starting('external', f'runs {argv[0]!r}, a program that is not Python')
    return ros


def _wrap_subprocess() -> None:
    execute_child = subprocess.Popen._execute_child

    def checked_execute_child(self, args, executable, *more, **options):
        ros = _check_command(args if executable is None or isinstance(args, (str, bytes)) else
                             [executable, *list(args)[1:]])
        started = execute_child(self, args, executable, *more, **options)
        markers = current_markers()
        if ros and markers is not None and 'ros' not in markers:
            _Running.ros_programs.append((self, ros))  # judged at the test's teardown by how it ended
        return started

    subprocess.Popen._execute_child = checked_execute_child


def _wrap_rclpy(rclpy) -> None:
    init = rclpy.init

    def checked_init(*args, **kwargs):
        starting('ros', 'starts ROS (rclpy.init)')
        return init(*args, **kwargs)

    rclpy.init = checked_init


def _wrap_mujoco(mujoco) -> None:
    for name in ('from_xml_path', 'from_xml_string', 'from_binary_path'):
        create = getattr(mujoco.MjModel, name)

        def checked_create(*args, _create=create, **kwargs):
            starting('mujoco', 'creates a MuJoCo model')
            return _create(*args, **kwargs)

        setattr(mujoco.MjModel, name, staticmethod(checked_create))


def _wrap_playwright(sync_api) -> None:
    sync_playwright = sync_api.sync_playwright

    def checked_sync_playwright(*args, **kwargs):  # its driver (Node.js) starts before the browser
        starting('browser', 'starts Playwright (a browser)')
        return sync_playwright(*args, **kwargs)

    sync_api.sync_playwright = checked_sync_playwright
    for name in ('launch', 'launch_persistent_context'):
        launch = getattr(sync_api.BrowserType, name)

        def checked_launch(self, *args, _launch=launch, **kwargs):
            starting('browser', 'launches a browser (Playwright)')
            return _launch(self, *args, **kwargs)

        setattr(sync_api.BrowserType, name, checked_launch)


class _AfterImport(importlib.abc.MetaPathFinder):
    """Wraps a module as soon as it is imported (or at once if it already is)."""

    def __init__(self, wrappers: dict):
        self.pending = {}
        for name, wrap in wrappers.items():
            if name in sys.modules:
                wrap(sys.modules[name])
            else:
                self.pending[name] = wrap

    def find_spec(self, name, path, target=None):
        wrap = self.pending.pop(name, None)
        if wrap is None:
            return None
        spec = importlib.util.find_spec(name)
        if spec is not None and spec.loader is not None:
            execute = spec.loader.exec_module

            def execute_and_wrap(module):
                execute(module)
                wrap(module)

            spec.loader.exec_module = execute_and_wrap
        return spec


def install() -> None:
    """Wrap the places that start ROS, a browser, MuJoCo and other programs."""
    _wrap_subprocess()
    sys.meta_path.insert(0, _AfterImport({'rclpy': _wrap_rclpy, 'mujoco': _wrap_mujoco,
                                          'playwright.sync_api': _wrap_playwright}))
