"""Layout at 1280x720 and 1400x900 (headless Chromium, bounding boxes): Simulate and the state
details in view without scrolling; the Synthesize panel never covers the form, a goal flagged
red included."""

import pytest

from test_gui_browser import browser_context, choose_task, gui, open_page, result_code  # noqa: F401

SIZES = [{'width': 1280, 'height': 720}, {'width': 1400, 'height': 900}]


def in_view(page, selector, size):
    box = page.locator(selector).bounding_box()
    assert box is not None, f'{selector} is not shown'
    assert box['x'] >= 0 and box['y'] >= 0, (selector, box)
    assert box['x'] + box['width'] <= size['width'] and box['y'] + box['height'] <= size['height'], (selector, box)
    return box


def below(upper, lower):
    return upper['y'] + upper['height'] <= lower['y'] + 0.5


def assert_panel_covers_nothing(page, size):
    fields, controls = (page.locator(s).bounding_box() for s in ('#form-fields', 'form section.controls'))
    assert below(fields, controls), (fields, controls)
    in_view(page, 'form section.controls', size)


@pytest.mark.parametrize('size', SIZES, ids=lambda s: f"{s['width']}x{s['height']}")
def test_simulate_and_state_details_in_view_and_the_panel_covers_no_field(gui, browser_context, size):  # noqa: F811
    with open_page(browser_context, gui[0], viewport=size) as page:
        choose_task(page, ['look_down', 'pickup_object'])
        assert_panel_covers_nothing(page, size)
        goal = page.locator('#goals li').last  # the goal just added is shown above the panel
        assert below(goal.bounding_box(), page.locator('form section.controls').bounding_box())
        page.click('#synthesize')
        assert result_code(page) == 'SUCCESS'
        page.wait_for_selector('.graph-viewport svg g[id="state:stand"]')
        assert page.evaluate('window.scrollY') == 0
        in_view(page, '#simulate', size)
        in_view(page, '#autonomy', size)
        assert_panel_covers_nothing(page, size)
        name = page.locator('g[id="state:stand"] text').first
        in_view(page, 'g[id="state:stand"]', size)
        name.click()
        details = in_view(page, '#state-details', size)
        assert 'ChangeControlModeActionState' in page.inner_text('#state-details')
        assert details['y'] >= page.locator('#graph').bounding_box()['y']  # beside the click, over the drawing
        page.click('#state-details button.close')
        assert page.is_hidden('#state-details')


@pytest.mark.parametrize('size', SIZES, ids=lambda s: f"{s['width']}x{s['height']}")
def test_a_goal_flagged_red_after_an_error_stays_in_view_above_the_panel(gui, browser_context, size):  # noqa: F811
    with open_page(browser_context, gui[0], viewport=size) as page:
        choose_task(page, ['look_down', 'stand_prep'])
        page.click('#synthesize')
        assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
        page.wait_for_selector('#goals li.impossible')
        flagged = in_view(page, '#goals li.impossible', size)
        controls = page.locator('form section.controls').bounding_box()
        fields = page.locator('#form-fields').bounding_box()
        assert below(flagged, controls) and flagged['y'] >= fields['y'] - 0.5
        centre = page.evaluate("([x, y]) => document.elementFromPoint(x, y).closest('li') !== null",
                               [flagged['x'] + 20, flagged['y'] + flagged['height'] / 2])
        assert centre  # nothing lies over the flagged goal
        assert_panel_covers_nothing(page, size)
