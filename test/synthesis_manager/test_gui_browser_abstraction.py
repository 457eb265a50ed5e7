"""The robot's abstraction beside the form (headless Chromium): the control-mode graph and the
precondition graph of the chosen system, the task's path highlighted, following the form."""

import pytest

from gui_in_browser import choose_task, open_page, result_code

pytestmark = [pytest.mark.ros, pytest.mark.browser]


@pytest.fixture
def page(gui, browser_context):
    with open_page(browser_context, gui[0]) as page:
        yield page


def ids(page, selector, prefix):
    return sorted(page.eval_on_selector_all(selector, f"els => els.map(e => e.id.slice({len(prefix)}))"))


def test_modes_and_preconditions_drawn_with_the_task_path_following_the_form(page):
    choose_task(page, ['look_down', 'pickup_object'])
    page.wait_for_function("document.getElementById('abstraction-path').textContent.includes('pickup_object')")
    # every mode of config/atlas.yaml and every change between two of them
    assert ids(page, '#mode-graph g.node', 'mode:') == ['manipulate', 'stand', 'stand_prep', 'step', 'walk']
    assert len(ids(page, '#mode-graph path.edge', 'mode-edge:')) == 7  # 1 + 3 + 1 + 1 + 1
    # the path: stand_prep -> stand (look_down needs it) -> manipulate (pickup_object needs it)
    assert ids(page, '#mode-graph path.edge.on-path', 'mode-edge:') == ['stand->manipulate', 'stand_prep->stand']
    assert ids(page, '#mode-graph g.node.on-path', 'mode:') == ['manipulate', 'stand', 'stand_prep']
    assert page.inner_text('#abstraction-path').startswith('Task path: stand_prep → stand → manipulate')
    # preconditions: an arrow from each precondition to its action; the goals and what they need
    assert 'need:object_template->pickup_object' in ids(page, '#precondition-graph path.edge', '')
    assert ids(page, '#precondition-graph g.goal', 'need:') == ['look_down', 'pickup_object']
    assert ids(page, '#precondition-graph g.action.on-path', 'need:') == ['look_down', 'object_template',
                                                                          'pickup_object']
    # the form changes, the drawing follows: start in stand, object_template already done
    page.check('input[name="initial-mode"][value="stand"]')
    page.check('input[name="initial-condition"][value="object_template"]')
    page.wait_for_function("document.getElementById('abstraction-path').textContent.startsWith('Task path: stand →')")
    assert ids(page, '#mode-graph path.edge.on-path', 'mode-edge:') == ['stand->manipulate']
    assert ids(page, '#precondition-graph g.action.on-path', 'need:') == ['look_down', 'pickup_object']
    assert page.locator('g[id="need:object_template"].done').count() == 1
    # another robot: its own graph
    page.select_option('#system', 'mobile_manipulator')
    page.wait_for_function("document.getElementById('abstraction-system').textContent === 'mobile_manipulator'")
    page.wait_for_selector('#mode-graph g[id="mode:parked"]')
    assert ids(page, '#mode-graph g.node', 'mode:') == ['driving', 'manipulating', 'parked']


def test_a_capability_system_draws_its_capability_graph_instead_of_modes(page):
    page.select_option('#system', 'delivery_rover')
    page.wait_for_selector('#capability-graph')
    assert page.locator('#mode-graph').count() == 0
    # drive needs battery_ok, which the battery check (on completed) and the charge set
    for edge in ('prop:battery_ok->cap:drive:', 'cap:check_battery->prop:battery_ok:completed',
                 'cap:check_battery->prop:battery_ok:low: not', 'cap:charge->prop:battery_ok:completed',
                 'cap:check_battery->sensor:battery_low:reports'):
        assert page.locator(f'path[id="capability-edge:{edge}"]').count() == 1, edge


def test_the_abstraction_folds_to_one_line_once_a_result_is_shown(page):
    choose_task(page, ['look_down'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    assert page.get_attribute('#abstraction', 'open') is None
    page.click('#abstraction summary')
    assert page.is_visible('#mode-graph')
