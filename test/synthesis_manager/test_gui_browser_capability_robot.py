"""A capability robot (CNU's format: config/delivery_rover) on every GUI surface, in headless
Chromium at 1280x720 against a real `behavior-synthesis gui` with the FlexBE workspace on
AMENT_PREFIX_PATH (issue 45): the form built from the robot, its capability graph with the task's
path, synthesis, a simulation with Runtime Control (the operator forces the battery check's
`low` and a failing drive; the outcomes and the trace check, worded with who chose), and
"Suggest fixes" repairing a refused rover task. With $BEHAVIOR_SYNTHESIS_DOCS_SHOTS set to a
directory, the graph and the run waiting for the operator are also written there
(docs/gui-capability-graph.png, docs/gui-capability-run.png)."""

import io
import zipfile
from pathlib import Path

import pytest

from gui_in_browser import STATUS_DONE, docs_shot, flexbe_gui_server, open_page, result_code

pytestmark = [pytest.mark.ros, pytest.mark.browser, pytest.mark.flexbe]

SIZE = {'width': 1280, 'height': 720}


@pytest.fixture(scope='module')
def gui(tmp_path_factory, flexbe):
    with flexbe_gui_server(tmp_path_factory, flexbe, 'gui-capability-robot') as served:  # the rover's state classes
        yield served


@pytest.fixture
def page(gui, browser_context):
    with open_page(browser_context, gui[0], viewport=SIZE) as page:
        page.select_option('#system', 'delivery_rover')
        page.wait_for_selector('#goal-choice option[value="hand_over"]', state='attached')
        yield page


def add_goals(page, goals):
    for goal in goals:
        page.select_option('#goal-choice', goal)
        page.click('#add-goal')


def wait_for_question(page, start):
    page.wait_for_function("start => !document.getElementById('operator-request').hidden && "
                           "document.getElementById('operator-question').textContent.startsWith(start)",
                           arg=start, timeout=60_000)


def force(page, outcome):
    page.click(f'#operator-outcome-buttons button[data-outcome="{outcome}"]')


def test_the_form_and_the_capability_graph_come_from_the_robot(page):
    # no control-mode heading; the robot's memories and sensor to start from, nothing checked
    assert page.is_hidden('#initial-control-modes')
    assert 'Control mode' not in page.inner_text('#initial-conditions')
    starts = page.locator('input[name="initial-condition"]').evaluate_all(
        'boxes => boxes.map(b => [b.value, b.checked])')
    assert starts == [['battery_ok', False], ['battery_low', False]]
    assert 'starts as its spec says (check_battery_a)' in page.inner_text('#initial-note')
    assert page.inner_text('#robot-sensor-list') == 'battery_low reported by check_battery'
    # goals: what the capabilities make true, none flagged impossible, the first one reachable
    goals = page.locator('#goal-choice option').evaluate_all('options => options.map(o => o.value)')
    assert goals[:4] == ['battery_ok', '!battery_ok', 'drive', 'hand_over'] and 'check_battery' not in goals
    page.wait_for_function("document.querySelector('#goal-choice option').textContent === 'battery_ok'")
    assert page.locator('#goal-choice option.impossible').count() == 0

    # the capability graph: capabilities, propositions, the sensor; the task's path highlighted
    assert page.get_attribute('#abstraction', 'open') is not None   # beside the form until a result
    graph = page.locator('#capability-graph')
    graph.wait_for()
    for node in ('cap:check_battery', 'cap:charge', 'cap:drive', 'cap:hand_over', 'prop:battery_ok',
                 'prop:drive', 'prop:hand_over', 'sensor:battery_low'):
        assert graph.locator(f'g[id="capability-{node}"]').count() == 1, node
    assert graph.locator('g.on-path').count() == 0
    add_goals(page, ['hand_over'])
    page.wait_for_selector('g[id="capability-cap:hand_over"].on-path')
    on_path = graph.locator('g.capability.on-path').evaluate_all('nodes => nodes.map(n => n.id)')
    assert sorted(on_path) == ['capability-cap:charge', 'capability-cap:check_battery', 'capability-cap:drive',
                               'capability-cap:hand_over']
    assert page.inner_text('#abstraction-path').startswith('Task path: check_battery → ')
    assert graph.locator('g[id="capability-prop:hand_over"].goal').count() == 1
    docs_shot(page, 'gui-capability-graph.png')
    # a memory that holds at the start cuts the path short: no battery check or charge needed
    page.check('input[name="initial-condition"][value="battery_ok"]')
    page.wait_for_function("!document.querySelector('g[id=\"capability-cap:charge\"]').classList.contains('on-path')")
    assert page.locator('g[id="capability-cap:drive"].on-path').count() == 1


def test_synthesize_then_simulate_with_runtime_control_forcing_low_and_a_failing_drive(page):
    add_goals(page, ['hand_over'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.wait_for_selector('.graph-viewport svg g.node')
    with page.expect_download() as download_info:  # the behavior package, on FlexBE's own states
        page.click('a[data-artifact="flexbe_behavior.zip"]')
    package = zipfile.ZipFile(io.BytesIO(Path(download_info.value.path()).read_bytes()))
    code = next(package.read(name).decode() for name in package.namelist() if name.endswith('_sm.py'))
    assert 'from flexbe_states.operator_decision_state import OperatorDecisionState' in code
    assert page.is_visible('#simulation-controls') and page.is_hidden('#simulation-note')
    assert 'every time' in page.get_attribute('label[for="fail-first"]', 'title')
    assert page.is_visible('#simulation-sensor-battery_low')
    assert 'simulated capability robot' in page.inner_text('#simulator-name')

    page.select_option('#autonomy', '0')   # Off: every answer waits for the operator
    page.click('#simulate')
    wait_for_question(page, 'check_battery returned “ok”')
    force(page, 'low')                     # the battery check says the battery is low
    wait_for_question(page, 'charge returned')
    asked = 'charge returned'
    while not asked.startswith('drive returned'):   # on to the drive (a new battery check first, perhaps)
        answered = page.inner_text('#operator-question')  # read before the click: the next may come at once
        page.click('#operator-confirm')
        page.wait_for_function("asked => !document.getElementById('operator-request').hidden && "
                               "document.getElementById('operator-question').textContent !== asked",
                               arg=answered, timeout=60_000)
        asked = page.inner_text('#operator-question')
    docs_shot(page, 'gui-capability-run.png')
    force(page, 'failed')                  # the drive fails
    page.wait_for_function(STATUS_DONE, timeout=60_000)
    status = page.inner_text('#simulation-status')
    assert status.startswith('Outcome: failed after'), status
    rows = page.locator('#simulation-steps tr[data-state]')
    first = rows.first.inner_text()
    assert 'check_battery low (chosen by the operator)' in first and 'low → charge' in first
    last = rows.last.inner_text()
    assert 'drive failed (chosen by the operator)' in last and 'failed → failed' in last
    assert page.inner_text('#simulation-check').startswith('Trace check against the specification: ok')

    # the battery held not low, the operator's `low` breaks an assumption: the check says who
    page.select_option('#simulation-sensor-battery_low', 'false')
    page.click('#simulate')
    wait_for_question(page, 'check_battery returned “ok”')
    force(page, 'low')
    page.wait_for_function(STATUS_DONE, timeout=60_000)
    check = page.inner_text('#simulation-check')
    assert check.startswith('Trace check: 1 violation(s): The operator forced \'low\' on check_battery at step 1 '
                            'with battery_low=false; the task assumed env_trans'), check
    assert page.locator('#simulation-check.bad').count() == 1

    # the operator sets the sensor during a run: the robot answers by it
    page.select_option('#simulation-sensor-battery_low', '')
    page.click('#simulate')
    wait_for_question(page, 'check_battery returned “ok”')
    page.select_option('#simulation-sensor-battery_low', 'true')
    wait_for_question(page, 'check_battery returned “low”')   # asked again: the robot reads the sensor
    page.click('#operator-confirm')
    page.wait_for_selector('#simulation-steps tr[data-state] >> nth=0')
    page.wait_for_function("(document.querySelector('#simulation-steps tr[data-state]') || {}).innerText"
                           "?.includes('check_battery low (chosen by the robot)')", timeout=60_000)
    page.click('#stop-run')
    page.wait_for_function(STATUS_DONE, timeout=60_000)
    assert 'the operator stopped the run' in page.inner_text('#simulation-status')


def test_suggest_fixes_repairs_a_refused_rover_task(page):
    add_goals(page, ['drive', '!drive'])
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    page.click('#suggest-fixes')
    dropped = page.locator('li.proposal[data-kind="drop_goal"]').first
    dropped.wait_for(timeout=60_000)
    dropped.locator('button.apply-fix').click()
    page.wait_for_function("document.querySelector('#result-code').textContent === 'SUCCESS'", timeout=120_000)
    assert len(page.locator('#goals li').all()) == 1
    page.wait_for_selector('.graph-viewport svg g.node')
