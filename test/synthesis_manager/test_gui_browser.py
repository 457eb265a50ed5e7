"""The web GUI in headless Chromium (Playwright) against the real server and pipeline.

Set BEHAVIOR_SYNTHESIS_GUI_SCREENSHOT=docs/gui-result.png to also write the result page
picture used by the documentation.
"""

import os
import shutil
from pathlib import Path

import pytest
import yaml

from gui_in_browser import choose_task, result_code

pytestmark = [pytest.mark.ros, pytest.mark.browser]

SCREENSHOT_ENV = 'BEHAVIOR_SYNTHESIS_GUI_SCREENSHOT'


def test_paper_task_shows_progress_draws_the_machine_and_downloads_yaml(page, tmp_path):
    assert page.is_checked('input[name="initial-mode"][value="stand_prep"]')  # the default
    choose_task(page, ['look_down', 'pickup_object'])
    assert page.locator('#goals li').evaluate_all('items => items.map(i => i.dataset.goal)') == [
        'look_down', 'pickup_object']
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    timeline = page.inner_text('#timeline')
    assert 'Compiling' in timeline and 'Synthesiz' in timeline and 'Generat' in timeline
    assert page.eval_on_selector('#progress', 'bar => bar.value') == 1

    page.wait_for_selector('#graph svg g.node')
    node_labels = page.locator('#graph svg g.node text').all_text_contents()
    # FlexBE-like boxes: the state's name and its outcomes (along the bottom) are in the node
    assert {'look_down', 'pickup_object', 'stand', 'manipulate', 'finished', 'failed', 'done', 'changed'} <= set(
        node_labels)
    edge_labels = page.locator('#graph svg g.edge text').all_text_contents()
    assert [label.strip() for label in edge_labels] == ['initial']
    assert 'Realizable\tyes' in page.inner_text('#summary')
    assert page.is_visible('#simulate') and page.is_hidden('#simulation-view')  # offered, not run
    page.click('details[data-section="sys_liveness"] summary')
    assert page.is_visible('details[data-section="sys_liveness"] pre')

    with page.expect_download() as download_info:
        page.click('a[data-artifact="state_machine.yaml"]')
    download = download_info.value
    assert download.suggested_filename.endswith('state_machine.yaml')
    states = yaml.safe_load(Path(download.path()).read_text())
    assert {s['state_path'] for s in states} >= {'/', '/look_down', '/pickup_object'}
    assert all(len(s) == 16 for s in states)
    with page.expect_download() as download_info:  # the behavior as FlexBE's editor saves it
        page.click('a[data-artifact="flexbe_behavior.zip"]')
    assert download_info.value.suggested_filename.endswith('flexbe_behavior.zip')
    assert 'FlexBE behavior package' in page.inner_text('a[data-artifact="flexbe_behavior.zip"]')
    assert page.locator('a[data-artifact="flexbe_behavior.zip"]').count() == 1  # offered once

    picture = tmp_path / 'gui-result.png'
    page.screenshot(path=str(picture), full_page=True)
    assert picture.read_bytes().startswith(b'\x89PNG') and picture.stat().st_size > 20_000
    if os.environ.get(SCREENSHOT_ENV):
        shutil.copyfile(picture, os.environ[SCREENSHOT_ENV])


def test_goals_can_be_reordered_and_removed(page):
    choose_task(page, ['pickup_object', 'look_down', 'walk'])
    page.click('#goals li[data-goal="look_down"] button[title="move up"]')
    page.click('#goals li[data-goal="walk"] button[title="remove"]')
    page.check('input[name="option"][value="ltl_compilation_only"]')
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    assert 'from stand_prep: look_down, then pickup_object' in page.inner_text('#result-message')
    assert 'Realizable\tnot checked' in page.inner_text('#summary')
    assert page.is_hidden('#graph-section')
    assert page.locator('a[data-artifact="specification.structuredslugs"]').count() == 1


def test_a_bad_request_shows_the_pipeline_message(page):
    # the banner gives the same sentence as the form's goal check, the CLI and the action result
    choose_task(page, ['look_down', 'stand_prep'], initial_conditions=('stand',))
    page.check('#unordered')  # in any order, so the pre-check does not stop it: the compiler does
    warning = page.locator('#goals li[data-goal="stand_prep"] .goal-warning')
    page.wait_for_function("document.querySelector('#goals li[data-goal=\"stand_prep\"] .goal-warning')"
                           ".textContent.includes('the robot starts in stand')")  # the check in any order
    page.click('#synthesize')
    assert result_code(page) == 'INVALID_GOALS'
    sentence = page.inner_text('#result-message')
    assert ('Goal 2 (stand_prep) can never be achieved: the robot starts in stand, and stand -> stand_prep is not a '
            'transition in config/atlas.yaml (from stand the robot can only change to manipulate, step, walk).'
            ) in sentence
    assert warning.inner_text() in sentence
    assert page.locator('#result-banner.bad').count() == 1


def test_one_initial_control_mode_only_radio_buttons(page):
    choose_task(page, ['look_down'], initial_conditions=('stand_prep',))
    assert page.get_attribute('input[name="initial-mode"][value="walk"]', 'type') == 'radio'
    page.check('input[name="initial-mode"][value="walk"]')
    assert not page.is_checked('input[name="initial-mode"][value="stand_prep"]')
    assert page.locator('input[name="initial-mode"]:checked').count() == 1


def test_a_request_without_goals_is_refused_in_the_page_without_asking_the_server(page):
    sent = []
    page.on('request', lambda request: sent.append(request.url) if request.url.endswith('/api/jobs') else None)
    choose_task(page, [])
    page.click('#synthesize')
    assert 'Add at least one goal' in page.inner_text('#form-problem')
    assert page.evaluate('document.activeElement.id') == 'goal-choice'
    assert page.is_hidden('#result') and sent == []
    assert page.is_enabled('#synthesize')


def test_cancel_a_queued_job(page, gui):
    _, backend = gui
    backend.jobs.gate.clear()  # jobs wait before being sent: cancel is deterministic
    try:
        choose_task(page, ['look_down'])
        page.click('#synthesize')
        page.wait_for_selector('#cancel:enabled')
        assert page.inner_text('#status') == 'waiting to be sent'
        page.click('#cancel')
        assert result_code(page) == 'CANCELLED'  # neutral, not an error
    finally:
        backend.jobs.gate.set()
    assert 'cancelled' in page.inner_text('#result-message')
    # one word for it on the whole page (ROS calls it PREEMPTED)
    page.wait_for_function("document.getElementById('status').textContent === 'CANCELLED'", timeout=10_000)
    assert 'PREEMPTED' not in page.inner_text('#result') + page.inner_text('#request-form')
    assert page.locator('#result-banner.neutral').count() == 1
    # The job's last event may reach the timeline a moment after the result banner.
    page.wait_for_function("document.querySelector('#timeline').innerText.includes('Cancelled')", timeout=10_000)
    assert 'Cancel requested' in page.inner_text('#timeline')
    assert page.is_enabled('#synthesize') and page.is_disabled('#cancel')


def test_a_cancel_reply_arriving_after_the_result_does_not_roll_the_timeline_back(page, gui):
    """The cancel request's reply is held until the job's last event is on the page."""
    _, backend = gui
    held = []
    page.route('**/api/jobs/*/cancel', lambda route: held.append((route, route.fetch())))
    backend.jobs.gate.clear()
    try:
        choose_task(page, ['look_down'])
        page.click('#synthesize')
        page.wait_for_selector('#cancel:enabled')
        page.click('#cancel')
        page.wait_for_function("document.querySelector('#timeline').innerText.includes('Cancelled')",
                               timeout=10_000)
    finally:
        backend.jobs.gate.set()
    assert len(held) == 1
    route, stale_reply = held[0]
    assert stale_reply.json()['state'] != 'finished'  # the reply really is older than the page
    route.fulfill(response=stale_reply)
    page.wait_for_timeout(300)  # the behaviour under test: the stale reply, handled, changes nothing
    assert 'Cancelled' in page.inner_text('#timeline')
    assert result_code(page) == 'CANCELLED'
    page.unroute('**/api/jobs/*/cancel')


def test_cancel_a_running_synthesis(page, runaway_synthesis):
    choose_task(page, ['look_down', 'pickup_object'])
    page.click('#synthesize')
    page.wait_for_function("document.getElementById('status').textContent.startsWith('Synthesizing')",
                           timeout=60_000)
    page.click('#cancel')
    assert result_code(page, timeout=30_000) == 'CANCELLED'
    assert page.locator('#result-banner.neutral').count() == 1
    page.wait_for_function("document.querySelector('#timeline').innerText.trimEnd().endsWith('Cancelled')",
                           timeout=10_000)


def test_simulate_with_a_fault_shows_steps_frames_and_timeline(page):
    choose_task(page, ['look_down', 'pickup_object'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.select_option('#fail-first', 'pickup_object')
    page.click('#simulate')
    page.wait_for_selector('#simulation-steps tr[data-state]', timeout=60_000)  # live, while running
    assert page.is_visible('#simulation-view')
    page.wait_for_selector('#simulation-timeline:not([hidden])', timeout=120_000)
    page.wait_for_function("document.getElementById('simulation-status').textContent.startsWith('Outcome')")
    assert page.inner_text('#simulation-status').startswith('Outcome: failed')
    rows = page.locator('#simulation-steps tr[data-state]')
    assert rows.last.get_attribute('data-state') == '/pickup_object'
    assert 'pickup_object failed' in rows.last.inner_text()
    assert 'ok' in page.inner_text('#simulation-check')
    page.wait_for_function("document.getElementById('simulation-timeline').naturalWidth > 0")
    page.wait_for_function("document.getElementById('simulation-frame').naturalWidth > 0")
    assert page.locator('#simulation-frames img').count() >= 2
