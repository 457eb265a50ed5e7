"""Runtime Control in the page (headless Chromium): confirm a High transition on the drawing,
answer InputState with the system's default offered, force an outcome while paused, stop."""

import pytest

from gui_in_browser import STATUS_DONE, choose_task, open_page, result_code, stop_a_running_simulation

pytestmark = [pytest.mark.ros, pytest.mark.browser]



@pytest.fixture
def page(gui, browser_context):
    with open_page(browser_context, gui[0]) as page:
        choose_task(page, ['look_down', 'pickup_object'])
        page.click('#synthesize')
        assert result_code(page) == 'SUCCESS'
        page.wait_for_selector('.graph-viewport svg')
        yield page


def wait_for_question(page, start):
    """Wait until the page asks the operator a question starting with ``start``."""
    page.wait_for_function("start => !document.getElementById('operator-request').hidden && "
                           "document.getElementById('operator-question').textContent.startsWith(start)",
                           arg=start, timeout=120_000)


def test_high_autonomy_waits_on_the_drawing_and_input_state_asks_with_the_default(page):
    page.select_option('#autonomy', '2')  # High: mode changes (High) wait, Low successes do not
    page.click('#simulate')
    wait_for_question(page, 'stand returned')
    assert page.is_visible('#operator-confirm') and page.is_hidden('#operator-input-form')
    assert 'stand returned “changed”, a transition of High autonomy' in page.inner_text('#operator-question')
    assert page.inner_text('#simulation-status').endswith('(waiting for you)')
    pending = page.locator('g.node.active text.pending')
    assert pending.count() == 1 and 'changed' in pending.text_content()
    pending.click()  # confirm on the drawing
    wait_for_question(page, 'manipulate returned')  # manipulate's mode change
    page.click('#operator-confirm')
    wait_for_question(page, 'object_template asks: Specify desired object template')
    assert page.is_hidden('#operator-confirm')
    assert page.input_value('#operator-input') == '1'  # the system's default answer
    page.click('#operator-input-form button[type="submit"]')
    page.wait_for_function(STATUS_DONE, timeout=180_000)
    assert page.inner_text('#simulation-status').startswith('Outcome: finished')
    assert page.is_hidden('#operator-request') and page.is_hidden('#runtime-control')
    assert page.locator('text.pending').count() == 0


def test_force_an_outcome_while_paused_then_stop_a_run(page):
    page.click('#simulate')  # Full autonomy: nothing waits
    page.wait_for_selector('g.node.active', timeout=120_000)
    page.click('#pause-run')
    page.wait_for_function("document.getElementById('simulation-status').textContent.endsWith('(paused)')",
                           timeout=60_000)
    assert page.inner_text('#pause-run') == '▶ Resume'
    active = page.get_attribute('g.node.active', 'id').split(':', 1)[1]
    page.locator('g.node.active text').filter(has_text='failed').first.click()  # fault injection
    page.click('#pause-run')
    page.wait_for_function(STATUS_DONE, timeout=180_000)
    assert page.inner_text('#simulation-status').startswith('Outcome: failed')
    row = page.locator(f'#simulation-steps tr[data-state="/{active}"] td.outcome')
    assert row.inner_text().startswith('failed')

    assert 'the operator stopped the run' in stop_a_running_simulation(page)
