"""The real FlexBE WebUI (pinned 4.0.3 from FLEXBE_SOURCES) against `behavior-synthesis serve`.

Its backend (FastAPI + a ROS node) runs as its own process with its older web stack
(`make flexbe`), our suite as another, both on a reserved ROS domain on loopback; the
editor page runs in headless Chromium. The test clicks what a FlexBE user clicks (add a
container, "Display synthesis", the task, Synthesize) and reads the result from the page's own
JavaScript model (``Behavior.getStatemachine()``). Our behaviors (the synthesized one as
`export-behavior` writes it, and atlas_sim's) open through the behavior dashboard's loader. The
WebUI starts as README tells users without a FlexBE install (``make webui``); a machine saved in
it with README's two manual imports runs on FlexBE's onboard executive.
"""

import contextlib
import os
import signal
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest

from synthesis_manager.client import SynthesisClient, make_goal
from synthesis_manager.ros.harness import RosHarness, reserve_domain_id
from synthesis_manager.ros.env import prepare_ros_environment

import headless_chromium
from flexbe_onboard_system import OnboardSystem, Operator, finished_with
from flexbe_webui_port import WEBUI_PORT, port_for_this_run

pytestmark = [pytest.mark.usefixtures('flexbe'), pytest.mark.ros, pytest.mark.browser, pytest.mark.flexbe]

REPOSITORY = Path(__file__).resolve().parents[2]
# fastapi/starlette as the WebUI needs them (starlette<0.47), put first on its path only.
WEBUI_SITE = REPOSITORY / 'build' / 'flexbe_webui_site'
# README's workaround for the upstream mismatch, typed under the Dashboard's Manual Imports:
# WebUI 4.0.3 calls these two names of engine 2.3.3 without importing them.
MANUAL_IMPORTS = ('from flexbe_core import StateLogger', 'from flexbe_core.proxy import initialize_proxies')
# What the WebUI's check writes to its terminal and console for a parameter value it cannot resolve.
UNRESOLVED_PARAMETER = 'Unknown variable for parameter'
PAPER_TASK = ('stand_prep', 'look_down, pickup_object')

# The container's content in the page model: states, transitions, initial state, outcomes.
READ_CONTAINER = """path => {
    const container = Behavior.getStatemachine().getStateByPath(path);
    if (!container || !container.getStates) return null;
    return {
        states: container.getStates().map(s => ({name: s.getStateName(), path: s.getStatePath(),
                                                 state_class: s.getStateClass()})),
        transitions: container.getTransitions().map(t => [t.getFrom().getStateName(), t.getOutcome(),
                                                          t.getTo() ? t.getTo().getStateName() : null]),
        initial: container.getInitialState() ? container.getInitialState().getStateName() : null,
        outcomes: container.getOutcomes()};
}"""


@contextlib.contextmanager
def running(command, environment, ready, timeout: float, log_path: Path):
    """A subprocess (output to ``log_path``) that ``ready()`` confirms up; stopped with SIGINT to
    its process group (``make webui`` waits for the WebUI it started), then SIGTERM: after the
    Runtime Control test the WebUI 4.0.3's executor never woke for the SIGINT (it ended only at
    the 20 s SIGKILL); SIGTERM wakes it and it runs its KeyboardInterrupt shutdown at once."""
    with open(log_path, 'w') as log:
        process = subprocess.Popen(command, env=environment, stdout=log, stderr=subprocess.STDOUT,
                                   start_new_session=True)
        try:
            deadline = time.monotonic() + timeout
            while not ready():
                if process.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f'{command[0]} did not come up:\n{log_path.read_text()[-3000:]}')
                time.sleep(0.2)
            yield process
        finally:
            for signal_number, grace in ((signal.SIGINT, 3), (signal.SIGTERM, 20)):
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(process.pid, signal_number)
                with contextlib.suppress(subprocess.TimeoutExpired):
                    process.wait(timeout=grace)
                    break
            else:
                os.killpg(process.pid, signal.SIGKILL)
                process.wait()


@pytest.fixture(scope='module')
def ros_domain():
    with reserve_domain_id() as domain:
        yield domain


@pytest.fixture(scope='module')
def synthesis_server(ros_domain, tmp_path_factory):
    """`behavior-synthesis serve` as a FlexBE user starts it."""
    folder = tmp_path_factory.mktemp('serve')
    log_path = folder / 'serve.log'
    environment = prepare_ros_environment(ros_domain, environ=dict(os.environ))
    command = [str(Path(sys.executable).parent / 'behavior-synthesis'), 'serve',
               '--byproducts-dir', str(folder / 'byproducts'), '--default-system', 'atlas']
    with running(command, environment, lambda: 'suite up' in log_path.read_text(), 60, log_path):
        yield folder


@pytest.fixture(scope='module')
def exported_behavior(tmp_path_factory):
    """The paper task as `export-behavior` writes it, installed with pip into a prefix of its own
    (as a user without colcon does): (name, top-level states, prefix, its site-packages)."""
    from ltl_specification import compile_task
    from ltl_synthesizer import synthesize
    from respec.automaton import automaton_from_strategy
    from sm_generation import generate_state_machine
    from respec.robot import robot_system
    from sm_generation.config import flexbe_config
    from sm_generation.flexbe_behavior import behavior_package

    initial, goals = ['stand_prep'], ['look_down', 'pickup_object']
    spec = compile_task(robot_system('atlas'), initial, goals)
    states = generate_state_machine(automaton_from_strategy(synthesize(spec).strategy, spec), robot_system('atlas'),
                                    initial_conditions=initial)
    package = behavior_package(states, flexbe_config(robot_system('atlas')), 'Look Down Pickup Object')
    states = states.to_instantiations()
    work = tmp_path_factory.mktemp('exported')
    folder = package.write(work / 'src')
    prefix = work / 'install'
    installed = subprocess.run([sys.executable, '-m', 'pip', 'install', '--quiet', '--no-deps',
                                '--no-build-isolation', '--no-index', '--prefix', str(prefix), str(folder)],
                               capture_output=True, text=True, timeout=300)
    assert installed.returncode == 0, installed.stderr
    site = prefix / 'lib' / f'python{sys.version_info.major}.{sys.version_info.minor}' / 'site-packages'
    top = sorted(s.name for s in states if s.parent_path == '/' and s.state_class != ':OUTCOME')
    return package.behavior_name, top, prefix, site


@pytest.fixture(scope='module')
def webui_log(tmp_path_factory) -> Path:
    """Where the WebUI process's output (its terminal) goes."""
    return tmp_path_factory.mktemp('webui') / 'webui.log'


@pytest.fixture(scope='module')
def webui(flexbe, flexbe_sources, ros_domain, synthesis_server, exported_behavior, webui_log):
    """The WebUI backend started as README tells users without a FlexBE install (``make webui``
    with the exported package's prefix); yields its URL."""
    if not (WEBUI_SITE / 'starlette').is_dir():
        pytest.fail(f'{WEBUI_SITE} is missing: `make flexbe` installs the web stack of the WebUI')
    environment = prepare_ros_environment(ros_domain, environ=dict(os.environ, FLEXBE_SOURCES=str(flexbe_sources)))
    url = f'http://127.0.0.1:{WEBUI_PORT}/'

    def answers():
        with contextlib.suppress(OSError):
            with urllib.request.urlopen(url, timeout=2) as response:
                return response.status == 200
        return False

    command = ['make', '-s', '-C', str(REPOSITORY), 'webui', f'WEBUI_BEHAVIORS={exported_behavior[2]}']
    with port_for_this_run(WEBUI_PORT), running(command, environment, answers, 120, webui_log):
        yield url


@pytest.fixture(scope='module')
def browser():
    with headless_chromium.browser_context(viewport={'width': 1600, 'height': 1000}) as context:
        yield context


@pytest.fixture
def editor(webui, browser):
    """The WebUI's state machine editor, connected to ROS with its synthesis client created."""
    page = browser.new_page()
    errors = []
    page.on('pageerror', lambda error: errors.append(str(error)))
    page.console = []  # what the WebUI prints to its console (its terminal, where pywebview runs it)
    page.on('console', lambda message: page.console.append(message.text))
    page.goto(webui)
    page.wait_for_function("""() => typeof RC !== 'undefined' && RC.ROS.isConnected()
        && WS.Behaviorlib.getBehaviorList().length > 0
        && document.getElementById('terminal').innerText.includes("Created action client for '/behavior_synthesis'")""",
                           timeout=120_000)
    page.click('#button_to_sm')
    yield page
    page.close()
    assert errors == []


def synthesize_in_new_container(page, initial_conditions: str, goals: str):
    page.click('[id="tool_button Add Container"]')
    page.wait_for_selector('#cb_display_synthesis', state='visible')
    page.check('#cb_display_synthesis')
    page.fill('#input_prop_synthesis_initial', initial_conditions)
    page.fill('#input_prop_synthesis_goal', goals)
    page.click('#button_prop_synthesize')


def direct_answer(domain: int, initial_conditions: str, goals: str) -> list[dict]:
    """The states our server returns for the same task, asked directly (not through the WebUI)."""
    from rclpy.node import Node

    with RosHarness(domain_id=domain) as ros:
        client = SynthesisClient(ros.add_node(Node, 'webui_test_client'))
        assert client.wait_for_server(timeout=30.0)
        outcome = client.run(make_goal('atlas', initial_conditions, goals), timeout=120)
    assert outcome.error_name == 'SUCCESS', outcome.message
    return outcome.states


def test_synthesize_fills_the_container_with_the_synthesized_machine(editor, ros_domain):
    synthesize_in_new_container(editor, *PAPER_TASK)
    editor.wait_for_function(f'() => ({READ_CONTAINER})("/Container")?.states.length > 0', timeout=120_000)
    container = editor.evaluate(READ_CONTAINER, '/Container')

    answer = direct_answer(ros_domain, *PAPER_TASK)
    states = [s for s in answer if s['state_path'] != '/' and s['state_class'] != ':OUTCOME']
    root = next(s for s in answer if s['state_path'] == '/')
    assert sorted(s['name'] for s in container['states']) == sorted(s['state_path'][1:] for s in states)
    assert all(s['path'] == f"/Container/{s['name']}" for s in container['states'])
    classes = {s['name']: s['state_class'] for s in container['states']}
    behavior_class = 'name => WS.Behaviorlib.getByName(name).getStateClass()'
    assert {s['state_path'][1:]: s['state_class'] if s['state_class'] != ':BEHAVIOR'
            else editor.evaluate(behavior_class, s['behavior_class']) for s in states} == classes
    assert classes['look_down'] == 'TiltHeadState' and classes['stand'] == 'ChangeControlModeActionState'
    expected_transitions = {(s['state_path'][1:], outcome, target)
                            for s in states for outcome, target in zip(s['outcomes'], s['transitions'])}
    assert {tuple(t) for t in container['transitions'] if t[0] != 'INIT'} == expected_transitions
    assert container['initial'] == root['initial_state_name']
    assert sorted(container['outcomes']) == ['failed', 'finished']


@pytest.mark.parametrize('goals, error_name, named', [('fly_away', 'UNKNOWN_PROPOSITION', 'fly_away'),
                                                       ('', 'INVALID_GOALS', 'goal')])
def test_a_bad_goal_shows_our_error_name_in_the_webui(editor, goals, error_name, named):
    synthesize_in_new_container(editor, 'stand_prep', goals)
    editor.wait_for_function("""name => document.getElementById('runtime_feedback_text').innerText
                                         .includes(name)""", arg=error_name, timeout=60_000)
    log = editor.inner_text('#runtime_feedback_text')
    assert f'Behavior synthesis failed: {error_name}: ' in log and named in log
    # Our log line is published just before the goal is aborted, so the terminal's line can
    # arrive a moment later.
    editor.wait_for_function("text => document.getElementById('terminal').innerText.includes(text)",
                             arg="Goal for '/behavior_synthesis' - failed!", timeout=30_000)
    assert editor.evaluate(READ_CONTAINER, '/Container')['states'] == []


LOAD_BEHAVIOR = """name => new Promise(resolve => {
    const entry = WS.Behaviorlib.getByName(name);
    if (!entry) { resolve({error: `${name} is not in the behavior library`}); return; }
    IO.BehaviorLoader.loadBehavior(entry.getBehaviorManifest(), error => resolve({
        error: error === undefined ? null : String(error),
        states: Behavior.getStatemachine().getStates().map(s => s.getStateName()).sort()}));
})"""


def test_our_behaviors_open_in_the_behavior_dashboard(editor, exported_behavior):
    """Issue 13: the exported synthesized behavior and the behaviors the configs embed load in the editor."""
    name, top_states, _, _ = exported_behavior
    for behavior, states in [(name, top_states), ('Pickup Object', ['Check Template', 'Pick Up']),
                             ('Grasp Object', ['Check Template', 'Grasp'])]:
        loaded = editor.evaluate(LOAD_BEHAVIOR, behavior)
        assert loaded == {'error': None, 'states': states}


FIVE_GOALS = ('stand_prep', 'look_down, pregrasp, pickup_object, approach_object, footstep_execution')
# What a FlexBE user does around a synthesized container before saving: name the behavior,
# pick the package, make the container the initial state, connect its outcomes, press Save.
PREPARE_AND_SAVE = """name => {
    UI.Dashboard.setBehaviorName(name);
    UI.Dashboard.setBehaviorDescription('Synthesized in the WebUI: from stand_prep, five goals');
    UI.Dashboard.setBehaviorAuthor('behavior-synthesis test');
    UI.Dashboard.setBehaviorPackage('synthesized_flexbe_behaviors');
    const root = Behavior.getStatemachine();
    const container = root.getStateByName('Container');
    root.setInitialState(container);
    for (const outcome of ['finished', 'failed']) {
        root.addTransition(new Transition(container, root.getSMOutcomeByName(outcome), outcome, 0));
    }
    const refusal = Checking.checkBehavior();
    if (refusal === undefined) UI.Menu.saveBehaviorClicked();
    return refusal === undefined ? null : refusal;
}"""


def add_manual_imports(page, lines):
    """Type ``lines`` under the Dashboard's Manual Imports, as README's step 3 says, and go back to the editor."""
    # The WebUI's own check (Save) moves to the Dashboard when it refuses the behavior there; a
    # second click on the active button once timed out at load 11, the About box said to cover it.
    if not page.evaluate('UI.Menu.isPageDashboard()'):
        page.click('#button_to_db')
    for line in lines:
        page.fill('#input_db_manual_import_value_add', line)
        page.click('#button_db_manual_import_add')
    page.click('#button_to_sm')


# Not 2x faster (issue 50): a five-goal synthesis in the WebUI, its save and the saved behavior's run on FlexBE's
# onboard engine (7.3 s; the WebUI, the suite and the browser are shared by the module).
def test_a_five_goal_synthesis_saves_in_the_webui_and_runs_onboard(editor, exported_behavior, ros, flexbe, tmp_path,
                                                                    monkeypatch):
    """Every key the synthesized states read is written in the machine: the WebUI's check accepts
    it, resolves every parameter value, and with README's two manual imports the saved behavior
    defines every name it uses and runs to ``finished`` on FlexBE's onboard executive."""
    import ast
    import builtins
    import importlib


    synthesize_in_new_container(editor, *FIVE_GOALS)
    editor.wait_for_function(f'() => ({READ_CONTAINER})("/Container")?.states.length > 0', timeout=120_000)
    # README's step 3: Save refuses a behavior without a description.
    assert editor.evaluate("""() => { UI.Dashboard.setBehaviorName('Five Goals Saved');
                                      UI.Dashboard.setBehaviorDescription('');
                                      return Checking.checkBehavior(); }""") == 'behavior description needs to be set'
    add_manual_imports(editor, MANUAL_IMPORTS)
    assert editor.evaluate(PREPARE_AND_SAVE, 'Five Goals Saved') is None
    editor.wait_for_function("() => document.getElementById('terminal').innerText"
                             ".includes('Save behavior was successful!')", timeout=60_000)
    terminal = editor.inner_text('#terminal')
    assert UNRESOLVED_PARAMETER not in terminal, terminal
    assert [line for line in editor.console if UNRESOLVED_PARAMETER in line] == []
    saved = exported_behavior[3] / 'synthesized_flexbe_behaviors' / 'five_goals_saved_sm.py'
    tree = ast.parse(saved.read_text(encoding='utf-8'))
    imported = [(node.module, alias.name) for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
                for alias in node.names]
    assert ('atlas_sim_flexbe_states.object_action_state', 'ObjectActionState') not in imported  # inside a behavior
    assert ('flexbe_states.input_state', 'InputState') in imported
    missing = [f'{module}.{name}' for module, name in imported
               if not hasattr(importlib.import_module(module), name)]
    assert missing == []
    used = {node.id for node in ast.walk(tree) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load)}
    defined = ({name for _, name in imported} | set(dir(builtins))
               | {node.id for node in ast.walk(tree) if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store)}
               | {node.arg for node in ast.walk(tree) if isinstance(node, ast.arg)}
               | {node.name for node in ast.walk(tree) if isinstance(node, (ast.ClassDef, ast.FunctionDef))})
    assert sorted(used - defined) == []

    system = OnboardSystem(ros, exported_behavior[2], flexbe, tmp_path)
    monkeypatch.setenv('AMENT_PREFIX_PATH', system.ament_prefix_path)  # this process's BehaviorLibrary
    monkeypatch.syspath_prepend(str(system.site))
    try:
        status = Operator(ros).start_behavior('Five Goals Saved')
        ok, details = finished_with(status, 'finished', system)
        assert ok, details
    finally:
        system.stop()


# Not 2x faster (issue 50): FlexBE's onboard engine starts on the WebUI's domain and the WebUI's failure line is
# awaited (3.4 s; the module's teardown is 4 s, no longer 20).
def test_runtime_control_cannot_start_a_behavior_on_engine_2_3_3(editor, exported_behavior, ros_domain, flexbe,
                                                                   webui_log, tmp_path):
    """README's upstream mismatch: with FlexBE's onboard executive up on the WebUI's domain, Runtime
    Control's Start Execution fails to publish the request (WebUI 4.0.3's BehaviorRequest against
    engine 2.3.3's flexbe_msgs), so README starts behaviors with be_launcher instead."""
    from types import SimpleNamespace


    name = exported_behavior[0]
    assert editor.evaluate(LOAD_BEHAVIOR, name)['error'] is None
    system = OnboardSystem(SimpleNamespace(domain_id=ros_domain), exported_behavior[2], flexbe, tmp_path,
                           robot=False)
    try:
        editor.click('#button_to_rc')
        editor.wait_for_selector('#button_behavior_start', state='visible', timeout=60_000)
        editor.click('#button_behavior_start')
        failure = "Failed to publish '/flexbe/request_behavior' - 'Container' object has no attribute 'state_id'"
        deadline = time.monotonic() + 60
        while failure not in webui_log.read_text(errors='replace') and time.monotonic() < deadline:
            time.sleep(0.5)
        assert failure in webui_log.read_text(errors='replace'), webui_log.read_text(errors='replace')[-3000:]
        assert 'Prepare behavior id=' not in system.log('onboard'), system.log('onboard')[-2000:]  # nothing reached it
    finally:
        system.stop()
