"""The check that a test declares what it starts (test/declared_kinds.py), on a stand-in test:
what fails it, with a message naming the marker, and what does not."""

import subprocess
import sys
from contextlib import contextmanager
from pathlib import Path

import pytest

import declared_kinds

BIN = Path(sys.executable).parent


class StandInTest:
    nodeid = 'test_stand_in.py::test_it'

    def __init__(self, *markers):
        self.markers = [getattr(pytest.mark, name).mark for name in markers]

    def iter_markers(self):
        return iter(self.markers)


@contextmanager
def running_as(*markers):
    """The check looks at a stand-in test with ``markers`` (then again at this one)."""
    this = declared_kinds._Running.item
    try:
        with declared_kinds.running(StandInTest(*markers)):
            yield
    finally:
        declared_kinds._Running.item = this


def test_starting_a_kind_undeclared_fails_naming_its_marker():
    for kind in ('ros', 'browser', 'mujoco', 'flexbe'):
        with running_as('slow'), pytest.raises(pytest.fail.Exception,
                                               match=f"without the marker '{kind}': add pytest.mark.{kind}"):
            declared_kinds.starting(kind, 'starts it')
        with running_as(kind):
            declared_kinds.starting(kind, 'starts it')  # declared: nothing happens


def test_a_program_that_is_not_python_fails_a_pure_core_test_only():
    with running_as(), pytest.raises(pytest.fail.Exception, match="runs '/bin/true', a program that is not Python"):
        subprocess.run(['/bin/true'])
    with running_as('external'):
        subprocess.run(['/bin/true'], check=True)
    with running_as():
        subprocess.run([sys.executable, '-c', 'pass'], check=True)  # Python is what the pure core runs


def test_a_ros_program_fails_an_undeclared_test_unless_it_only_refused_its_command_line():
    with running_as():
        node = subprocess.Popen([BIN / 'atlas-sim-operator'], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        node.kill()  # before it gets far: how it ended (killed, not refused) is what counts
        node.wait()
        assert declared_kinds.late_complaints() == [
            "test_stand_in.py::test_it runs `atlas-sim-operator` (ROS) without the marker 'ros': "
            'add pytest.mark.ros to it']
        refused = subprocess.run([BIN / 'atlas-sim-operator', '--answer', 'zero'], capture_output=True)
        assert refused.returncode == 2
        assert declared_kinds.late_complaints() == []
        shown = subprocess.run([BIN / 'atlas-sim-operator', '--help'], capture_output=True)
        assert shown.returncode == 0 and declared_kinds.late_complaints() == []
