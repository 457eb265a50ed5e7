"""Shared fixtures and the markers that select kinds of tests.

``test/`` mirrors the packages (test/respec, test/ltl_specification, test/ltl_synthesizer,
test/sm_generation, test/atlas_sim, test/synthesis_manager), with test/integration for tests that
span packages or run the real FlexBE, and test/bench for the benchmarks' own tests.

Markers, declared by each module (``pytestmark = [pytest.mark.ros, ...]``) or test:

    ros       starts ROS 2 (the ``ros`` fixture, the shell's nodes or its processes)
    browser   drives headless Chromium
    mujoco    runs the MuJoCo simulator
    flexbe    runs the real FlexBE (``flexbe_sources``, ``flexbe``)
    external  runs a program that is not Python (Graphviz' dot, slugs, Node.js)
    slow      takes more than a few seconds on a 2-core machine
    netns     builds private network namespaces (needs root and ``ip``; fails without them)

A test that starts ROS, a browser, MuJoCo, the real FlexBE or (without any of those markers) a
program that is not Python, and lacks the marker, fails with a message naming it
(test/declared_kinds.py).

The pure-core tests alone (Python only; -n 2: both cores, pytest-xdist)::

    .venv/bin/python -m pytest -n 2 -m "not (ros or browser or mujoco or flexbe or external or slow)"

Tests against the real FlexBE find its pinned sources through FLEXBE_SOURCES, by default
../shared/third_party beside the repository when present; `make flexbe` (run by `make test`)
builds and registers them in the venv. Without any sources (a user's machine) those tests skip
with that reason; with FLEXBE_SOURCES set (CI) broken sources fail them.
"""

import os
import sys
from pathlib import Path

import pytest

import declared_kinds

os.environ.setdefault('MUJOCO_GL', 'egl')

REPOSITORY = Path(__file__).resolve().parents[1]
DEFAULT_FLEXBE_SOURCES = REPOSITORY.parent / 'shared' / 'third_party'
# Where `make flexbe` registers the FlexBE packages (the AMENT_PREFIX_PATH entry for them).
FLEXBE_AMENT_PREFIX = Path(sys.prefix) / 'flexbe'
# Tests write system files that point at CNU's example files where the sources lie; a system
# file's references must resolve inside a config folder, so that folder is on every test's
# (and child process's) search path, as docs/cnu.md tells users to put their FlexBE workspace.
_CNU_FOLDER = Path(os.environ.get('FLEXBE_SOURCES') or DEFAULT_FLEXBE_SOURCES) / 'flexbe_synthesis'
if _CNU_FOLDER.is_dir() and 'BEHAVIOR_SYNTHESIS_CONFIG_DIR' not in os.environ:
    os.environ['BEHAVIOR_SYNTHESIS_CONFIG_DIR'] = str(_CNU_FOLDER)

MARKERS = {
    'ros': 'starts ROS 2 (the ros fixture, the shell\'s nodes or its processes)',
    'browser': 'drives headless Chromium',
    'mujoco': 'runs the MuJoCo simulator',
    'flexbe': 'runs the real FlexBE',
    'external': 'runs a program that is not Python (dot, slugs, node)',
    'slow': 'takes more than a few seconds on a 2-core machine',
    'netns': 'builds private network namespaces (root and ip)',
}


def pytest_configure(config):
    for name, meaning in MARKERS.items():
        config.addinivalue_line('markers', f'{name}: {meaning}')
    declared_kinds.install()


def pytest_collection_modifyitems(config, items):
    if any(item.get_closest_marker('ros') for item in items):
        # Before any test runs: DDS stays on loopback in this process and every process it
        # starts, whether or not a test starts ROS itself.
        from synthesis_manager.ros.env import prepare_ros_environment

        prepare_ros_environment()


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item, nextitem):
    with declared_kinds.running(item):
        return (yield)


@pytest.fixture(autouse=True)
def declares_what_it_starts(request):
    """Fails a test that starts a kind of thing its markers do not declare (test/declared_kinds.py)."""
    declared_kinds.check_fixtures(request)
    yield
    complaints = declared_kinds.late_complaints()
    if complaints:
        pytest.fail('\n'.join(complaints), pytrace=False)


@pytest.fixture(autouse=True)
def ros_domain_of_test(request, monkeypatch):
    """A test marked ``ros`` runs on a ROS_DOMAIN_ID reserved for it, in os.environ too: the
    processes it starts with this environment (``execute --engine flexbe`` starts FlexBE's
    onboard engine) meet no other test's, even one running beside it under pytest-xdist."""
    if request.node.get_closest_marker('ros') is None:
        yield None
        return
    from synthesis_manager.ros.harness import reserve_domain_id

    with reserve_domain_id() as domain:
        monkeypatch.setenv('ROS_DOMAIN_ID', str(domain))
        yield domain


@pytest.fixture
def ros(ros_domain_of_test):
    from synthesis_manager.ros.harness import RosHarness

    with RosHarness(domain_id=ros_domain_of_test) as harness:
        yield harness


@pytest.fixture(scope='session')
def flexbe_sources() -> Path:
    """The folder holding FlexBE's flexbe_behavior_engine/ (and flexbe_webui/, rosidl_runtime_py/)."""
    configured = os.environ.get('FLEXBE_SOURCES')
    if not configured:
        if not (DEFAULT_FLEXBE_SOURCES / 'flexbe_behavior_engine').is_dir():
            pytest.skip('real FlexBE not available: set FLEXBE_SOURCES to the folder holding '
                        'flexbe_behavior_engine/ and run `make flexbe`')
        return DEFAULT_FLEXBE_SOURCES
    sources = Path(configured).resolve()
    if not (sources / 'flexbe_behavior_engine').is_dir():
        pytest.fail(f'FLEXBE_SOURCES={configured} holds no flexbe_behavior_engine/')
    return sources


@pytest.fixture(scope='session')
def flexbe(flexbe_sources) -> Path:
    """The real FlexBE engine importable from this venv, built from ``flexbe_sources``.

    Returns the ament prefix under which our FlexBE packages are registered.
    """
    try:
        import flexbe_core
        import flexbe_msgs.msg  # noqa: F401
        import flexbe_states  # noqa: F401
    except ImportError as error:
        pytest.fail(f'FlexBE from {flexbe_sources} is not importable ({error}); run `make flexbe`')
    engine = (flexbe_sources / 'flexbe_behavior_engine').resolve()
    found = Path(flexbe_core.__file__).resolve()
    if engine not in found.parents:
        pytest.fail(f'this venv imports flexbe_core from {found}, not from {engine}; '
                    f'run `make flexbe FLEXBE_SOURCES={flexbe_sources}`')
    if not (FLEXBE_AMENT_PREFIX / 'share' / 'ament_index').is_dir():
        pytest.fail(f'no FlexBE package index at {FLEXBE_AMENT_PREFIX}; run `make flexbe`')
    return FLEXBE_AMENT_PREFIX


@pytest.fixture
def runaway_synthesis(monkeypatch):
    """Make the in-process synthesis node's next syntheses run until cancelled or out of time.

    Multi-goal tasks synthesize in about a second now, so a GUI cancel test cannot rely on a
    task being slow. The node still runs the real synthesizer, with its own cancel event and
    deadline, on a specification whose strategy extraction would take hours (100 inputs and
    outputs that nothing constrains): cancel and timeouts are exercised end to end.
    """
    from respec.ltl import var
    from respec.spec import GR1Specification
    from ltl_synthesizer import service

    runaway = GR1Specification(env_props=[f'x{i}' for i in range(100)],
                               sys_props=[f'y{i}' for i in range(100)], sys_liveness=[var('y0')])

    # The node's specification (from the request) is replaced; the rest runs as always,
    # the synthesis in the node's synthesis process.
    monkeypatch.setattr(service, 'spec_from_text_sections', lambda sections: runaway)
    # The strategy cache keys the request's text, which the substitution leaves as it was: an
    # earlier answer to the same request must not stand in for the runaway.
    monkeypatch.setattr(service.SynthesisService, 'cache_key', lambda self, job, settings=None: None)
