"""Issue 16 in headless Chromium, as a FlexBE user drives the page: plain-words diagnosis,
a readable drawing, honest progress and connection handling, and the simulation view.

Screenshots of every check are written to $BEHAVIOR_SYNTHESIS_GUI_SHOTS (a directory) when set.
"""

import io
import os
import socket
import threading
import time
from pathlib import Path

import pytest
from PIL import Image

from synthesis_manager.programs.gui import listening_socket, make_server
from synthesis_manager.web.backend import SynthesisBackend
from synthesis_manager.web.outcome import JobOutcome
from synthesis_manager.web.routes import create_app
from respec.robot import robot_system
from gui_in_browser import LONG_LIMITS, USABILITY_WINDOW, choose_task, open_page, result_code

pytestmark = [pytest.mark.ros, pytest.mark.browser]

SIX_GOALS = ['look_down', 'pickup_object', 'grasp_object', 'pregrasp', 'approach_object', 'footstep_execution']
SHOTS_ENV = 'BEHAVIOR_SYNTHESIS_GUI_SHOTS'


# The conftest's GUI and tab: long time limits for the 6-goal machine on a shared machine, 1400x900.
GUI_LIMITS, WINDOW = LONG_LIMITS, USABILITY_WINDOW


def shot(page, name):
    """A screenshot of the page now (kept only when $BEHAVIOR_SYNTHESIS_GUI_SHOTS is set)."""
    picture = page.screenshot()
    if os.environ.get(SHOTS_ENV):
        Path(os.environ[SHOTS_ENV]).mkdir(parents=True, exist_ok=True)
        (Path(os.environ[SHOTS_ENV]) / f'{name}.png').write_bytes(picture)
    return picture


# --- 1. diagnosis -------------------------------------------------------------------------

def test_unrealizable_request_banner_names_the_missing_transition(page):
    choose_task(page, ['look_down', 'stand_prep'])
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    sentence = page.inner_text('#result-message')
    assert sentence.startswith('Goal 2 (stand_prep) can never be achieved')
    assert 'stand -> stand_prep is not a transition in config/atlas.yaml' in sentence
    assert page.is_hidden('#result-details-text')  # the evidence is there, folded
    page.click('#result-details summary')
    details = page.inner_text('#result-details-text')
    assert 'eq. (9) control-mode topology for stand' in details and 'Details from the synthesizer' in details
    assert 'How the environment wins' in details
    shot(page, 'unrealizable-banner')


def test_a_request_the_compiler_refuses_shows_the_forms_sentence_and_the_same_evidence(page):
    # from stand the compiler refuses (INVALID_GOALS); the banner leads with the sentence the goal
    # list shows, and the folded details hold the core and the play, as for a start in stand_prep
    choose_task(page, ['look_down', 'stand_prep'], initial_conditions=('stand',))
    page.wait_for_function("document.querySelector('#goals li[data-goal=\"stand_prep\"] .goal-warning')"
                           ".textContent.includes('goal 1 (look_down) needs the robot in stand')")
    warning = page.inner_text('#goals li[data-goal="stand_prep"] .goal-warning')
    page.click('#synthesize')
    assert result_code(page) == 'INVALID_GOALS'
    assert page.inner_text('#result-message') == f'LTL compilation failed: {warning}'
    page.click('#result-details summary')
    details = page.inner_text('#result-details-text')
    assert 'eq. (9) control-mode topology for stand' in details
    assert 'How the environment wins' in details and 'state look_down (TiltHeadState) starts' in details


def test_goal_picker_says_which_goals_are_impossible_and_why(page):
    choose_task(page, [])
    assert page.get_attribute('#goal-choice option[value="stand"]', 'title') == \
        'reached from: stand_prep, manipulate, step, walk'
    assert page.get_attribute('#goal-choice option[value="stand_prep"]', 'title') == 'reached from: no other mode'
    choose_task(page, ['look_down'])
    page.wait_for_function(
        "document.querySelector('#goal-choice option[value=\"stand_prep\"]').textContent.includes('impossible')")
    assert 'stand -> stand_prep is not a transition' in page.get_attribute(
        '#goal-choice option[value="stand_prep"]', 'title')
    page.select_option('#goal-choice', 'stand_prep')
    page.click('#add-goal')
    page.wait_for_selector('#goals li.impossible[data-goal="stand_prep"]')
    assert 'stand -> stand_prep' in page.inner_text('#goals li[data-goal="stand_prep"] .goal-warning')
    page.check('#unordered')  # in any order, stand_prep holds from the start: possible
    page.wait_for_selector('#goals li.impossible', state='detached')
    shot(page, 'goal-picker')


# --- 2. drawing, 3. progress (one 6-goal run) --------------------------------------------------

def ink_rows(png: bytes) -> int:
    """How many pixel rows of a screenshot hold dark (text) pixels."""
    image = Image.open(io.BytesIO(png)).convert('L')
    width, height = image.size
    pixels = image.load()
    return sum(1 for y in range(height) if any(pixels[x, y] < 110 for x in range(width)))


def pan_into_view(page, target):
    """Drag the drawing (as a user would) until ``target`` is inside its viewport; its box."""
    viewport = page.locator('.graph-viewport').bounding_box()
    centre = (viewport['x'] + viewport['width'] / 2, viewport['y'] + viewport['height'] / 2)
    for _ in range(20):
        box = target.bounding_box()
        inside = (viewport['x'] <= box['x'] and box['x'] + box['width'] <= viewport['x'] + viewport['width']
                  and viewport['y'] <= box['y'] and box['y'] + box['height'] <= viewport['y'] + viewport['height'])
        if inside:
            return box
        limit = viewport['height'] / 2 - 10, viewport['width'] / 2 - 10
        dy = max(-limit[0], min(limit[0], centre[1] - box['y']))
        dx = max(-limit[1], min(limit[1], centre[0] - box['x'] - box['width'] / 2))
        page.mouse.move(*centre)
        page.mouse.down()
        page.mouse.move(centre[0] + dx, centre[1] + dy, steps=4)
        page.mouse.up()
    raise AssertionError(f'could not pan {target} into view')


def test_six_goal_machine_progress_readable_drawing_details_and_one_state_count(page):
    choose_task(page, SIX_GOALS)
    page.click('#synthesize')
    page.wait_for_function("document.getElementById('status').textContent.startsWith('Synthesizing')",
                           timeout=120_000)
    # running: an indeterminate bar, a ticking clock, and the controls in view at 1400x900
    assert page.eval_on_selector('#progress', 'bar => bar.hasAttribute("value")') is False
    first = page.inner_text('#elapsed')
    page.wait_for_function(f"document.getElementById('elapsed').textContent !== {first!r}")
    for control in ('#synthesize', '#cancel', '#progress', '#status'):
        box = page.locator(control).bounding_box()
        assert 0 <= box['y'] and box['y'] + box['height'] <= 900, control
    shot(page, 'six-goals-running')
    assert result_code(page, timeout=400_000) == 'SUCCESS'
    assert page.eval_on_selector('#progress', 'bar => bar.value') == 1

    # one state count: timeline, summary and drawing agree
    count = int(page.inner_text('#timeline').split('Generated a state machine with ')[1].split(' ')[0])
    assert count >= 15
    assert f'State machine states\t{count} ' in page.inner_text('#summary')
    page.wait_for_selector('#graph svg g.node')
    drawn = page.locator('#graph svg g.node[id^="state:"]').count()
    assert drawn == count  # no containers in this machine: one box per state

    # readable after zoom: the label of a state is at least 14 px tall on screen
    label = page.locator('g[id="state:footstep_execution"] text').first
    page.click('button[aria-label="zoom in"]')
    page.eval_on_selector('.graph-viewport', 'v => v.scrollIntoView({block: "start"})')
    box = pan_into_view(page, label)
    assert box['height'] >= 14, box
    ink = ink_rows(page.screenshot(clip={'x': box['x'], 'y': box['y'] - 2, 'width': box['width'],
                                         'height': box['height'] + 4}))
    assert ink >= 10, ink  # the glyphs themselves, measured on the screenshot
    shot(page, 'six-goals-zoomed')

    # merged parallel transitions: outcomes listed together in one cell; in a machine this long
    # the failure cell is red and the column's own 'failed' box below says where it goes (no arrow)
    node_texts = page.locator('g[id="state:approach_object"] text').all_text_contents()
    assert 'failed, aborted' in node_texts
    targets = page.locator('g.edge[id^="edge:approach_object->"]').evaluate_all('edges => edges.map(e => e.id)')
    assert targets == ['edge:approach_object->target_pose']
    failing_cell = page.locator('g[id="state:approach_object"] text', has_text='failed, aborted')
    assert failing_cell.get_attribute('fill') == '#c62828'
    assert page.locator('g.node[id^="outcome:failed"]').count() >= 2

    # clicking a state explains it like the FlexBE editor
    name = page.locator('g[id="state:pregrasp_pose"] text').first
    box = pan_into_view(page, name)
    page.mouse.click(box['x'] + box['width'] / 2, box['y'] + box['height'] / 2)
    details = page.inner_text('#state-details')
    assert 'GetTemplatePregraspState' in details
    assert 'template_id ← template_id' in details and 'pre_grasp ← pregrasp_pose' in details
    assert 'not_available → failed' in details and 'autonomy' in details
    assert page.is_visible('#graph-legend') and 'concurrency container' in page.inner_text('#graph-legend')
    assert '_a' in page.inner_text('#specification-legend') and '_m' in page.inner_text('#specification-legend')
    shot(page, 'state-details')


def test_drawing_pans_and_zooms(page):
    choose_task(page, ['look_down', 'pickup_object'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.wait_for_selector('.graph-viewport svg')
    view = lambda: page.get_attribute('#state-machine-svg', 'viewBox')  # noqa: E731
    scale = lambda: float(page.get_attribute('.graph-viewport', 'data-scale'))  # noqa: E731
    before_view, before_scale = view(), scale()
    page.click('button[aria-label="zoom in"]')
    assert scale() == pytest.approx(before_scale * 1.25, rel=0.01)
    box = page.locator('.graph-viewport').bounding_box()
    page.mouse.move(box['x'] + 30, box['y'] + 30)
    page.mouse.down()
    page.mouse.move(box['x'] + 130, box['y'] + 90, steps=5)
    page.mouse.up()
    assert view() != before_view
    page.click('button[aria-label="natural size"]')
    assert scale() == pytest.approx(4 / 3, rel=0.01)


# --- 3. resilience ---------------------------------------------------------------------------

def test_an_old_download_gives_a_friendly_page(page, gui):
    url, _ = gui
    response = page.goto(f'{url}api/jobs/1-0000dead/artifacts/state_machine.yaml')
    assert response.status == 404
    assert response.headers['content-type'].startswith('text/html')
    assert 'This download is no longer available' in page.inner_text('h1')
    page.click('text=Open the synthesis page')
    page.wait_for_selector('body.ready')


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


class Server:
    """A GUI server that can be killed abruptly (as a crash or restart would)."""

    def __init__(self, backend, port):
        self.sock = listening_socket('127.0.0.1', port)
        self.server = make_server(create_app(backend), self.sock)
        self.thread = threading.Thread(target=self.server.run, kwargs={'sockets': [self.sock]}, daemon=True)
        self.thread.start()
        while not self.server.started:
            time.sleep(0.02)

    def kill(self):
        self.server.should_exit = self.server.force_exit = True
        self.thread.join(10)
        self.sock.close()


def never_finishing(request, feedback, cancel):
    feedback('Synthesizing an automaton', 0.4)
    cancel.wait(60)
    return JobOutcome(-9, 'PREEMPTED', 'cancelled')


def test_server_restart_mid_job_is_said_plainly_and_the_page_reconnects(browser_context):
    port = free_port()
    first = Server(SynthesisBackend(never_finishing), port)
    page = browser_context.new_page()
    try:
        page.goto(f'http://127.0.0.1:{port}/')
        page.wait_for_selector('body.ready')
        choose_task(page, ['look_down'])
        page.click('#synthesize')
        page.wait_for_function("document.getElementById('status').textContent.startsWith('Synthesizing')")
        first.kill()
        page.wait_for_selector('#connection:not([hidden])')
        assert 'Connection to the server lost' in page.inner_text('#connection')
        second = Server(SynthesisBackend(never_finishing), port)
        try:
            assert result_code(page, timeout=30_000) == 'CONNECTION LOST'
            assert page.inner_text('#result-message') == 'The server restarted, so this job was lost — run it again.'
            assert page.is_hidden('#connection') and page.is_enabled('#synthesize')
            shot(page, 'server-restarted')
        finally:
            second.kill()
    finally:
        page.close()


def concurrent_machine(request, feedback, cancel):
    """A runner answering every job with the machine of test/automata/concurrent.yaml (a
    concurrency container: no GUI request of the configs makes one)."""
    from sm_generation import generate_state_machine, load_automaton

    automaton = load_automaton(Path(__file__).resolve().parents[1] / 'automata' / 'concurrent.yaml')
    return JobOutcome(1, 'SUCCESS', '', machine=generate_state_machine(automaton, robot_system('atlas')))


def test_a_concurrency_container_names_its_states_when_clicked(browser_context):
    server = Server(SynthesisBackend(concurrent_machine), free_port())
    try:
        with open_page(browser_context, f'http://127.0.0.1:{server.sock.getsockname()[1]}/') as page:
            choose_task(page, ['look_down'])
            page.click('#synthesize')
            assert result_code(page) == 'SUCCESS'
            page.wait_for_selector('g[id="state:object_template_and_stand"]')
            page.focus('g[id="state:object_template_and_stand"]')
            page.keyboard.press('Enter')
            details = page.inner_text('#state-details')
            assert 'concurrency container' in details
            assert 'Contains\tobject_template (InputState), stand (ChangeControlModeActionState)' in details
    finally:
        server.kill()


# --- 4. simulation view ----------------------------------------------------------------------

def test_simulation_colours_outcomes_marks_the_drawing_and_captions_frames(page):
    choose_task(page, ['look_down', 'pickup_object'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.wait_for_selector('.graph-viewport svg')
    page.select_option('#fail-first', 'pickup_object')
    page.click('#simulate')
    page.wait_for_selector('g.node.active', timeout=60_000)  # the running state, live
    page.wait_for_function("document.getElementById('simulation-status').textContent.startsWith('Outcome')",
                           timeout=180_000)
    assert page.inner_text('#simulation-status').startswith('Outcome: failed')
    assert 'outcome-failed' in page.get_attribute('#simulation-status', 'class')
    failed_cell = page.locator('#simulation-steps tr[data-state="/pickup_object"] td.outcome')
    assert 'outcome-failed' in failed_cell.get_attribute('class')
    assert page.evaluate("getComputedStyle(document.querySelector('#simulation-status')).color") == 'rgb(180, 35, 24)'
    wrapper = page.locator('.steps-wrapper')
    assert wrapper.evaluate('w => w.scrollWidth <= w.clientWidth')  # nothing clipped sideways
    # the drawing shows where the run went and where it ended
    assert page.locator('g[id="state:pickup_object"].ended').count() == 1
    assert page.locator('g.edge.taken[id="edge:look_down->manipulate"], g.edge.taken[id^="edge:look_down->"]').count() >= 1
    assert page.locator('g.edge.taken[id="edge:pickup_object->failed"]').count() == 1
    # captioned frames and a scrubber
    captions = page.locator('#simulation-frames figcaption').all_text_contents()
    assert len(captions) >= 3 and all(c.startswith('t = ') for c in captions)
    page.eval_on_selector('#frame-scrubber', "s => { s.value = '1'; s.dispatchEvent(new Event('input')); }")
    assert page.inner_text('#simulation-frame-label').startswith(f'Frame 2 of {len(captions)}: {captions[1]}')
    shot(page, 'simulation')


def test_a_system_the_humanoid_does_not_model_gets_no_pretend_simulation(page):
    page.select_option('#system', 'mobile_manipulator')
    page.wait_for_selector('#goal-choice option[value="localize"]', state='attached')
    page.select_option('#goal-choice', 'localize')
    page.click('#add-goal')
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.wait_for_selector('#simulation-note:not([hidden])')
    assert "does not model the mobile manipulator" in page.inner_text('#simulation-note')
    assert page.is_hidden('#simulate')
    shot(page, 'no-simulation')


# --- 2. export -------------------------------------------------------------------------------

def test_export_the_behavior_as_a_flexbe_package(page, tmp_path):
    import zipfile

    choose_task(page, ['look_down', 'pickup_object'])
    page.fill('#behavior-name', 'pickup_demo')
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    with page.expect_download() as download_info:
        page.click('#export-flexbe')
    download = download_info.value
    assert download.suggested_filename == 'pickup_demo_flexbe_behavior.zip'
    names = zipfile.ZipFile(download.path()).namelist()
    package = 'synthesized_flexbe_behaviors'
    assert f'{package}/package.xml' in names and f'{package}/manifest/pickup_demo.xml' in names
    code = zipfile.ZipFile(download.path()).read(f'{package}/{package}/pickup_demo_sm.py').decode()
    assert 'class pickup_demoSM(Behavior)' in code and 'TiltHeadState' in code
