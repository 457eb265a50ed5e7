"""The GUI served for headless Chromium and the steps the browser tests take on its page."""

import os
from contextlib import contextmanager
from pathlib import Path

import pytest

from synthesis_manager.programs.cli import build_parser
from synthesis_manager.programs.gui import background_server, ros_backend
from synthesis_manager.web.routes import create_app


#: Time limits for a GUI that synthesizes large machines (6 and 12 goals) on a shared machine.
LONG_LIMITS = {'synthesis_timeout': 300, 'goal_timeout': 400}
#: The tab the usability tests look at.
USABILITY_WINDOW = {'width': 1400, 'height': 900}


@contextmanager
def gui_server(byproducts_dir, synthesis_timeout=60, goal_timeout=120):
    """The GUI served over HTTP on 127.0.0.1, the suite in-process; yields (url, backend)."""
    args = build_parser(only='gui').parse_args(
        ['gui', '--byproducts-dir', str(byproducts_dir),
         '--synthesis-timeout', str(synthesis_timeout), '--goal-timeout', str(goal_timeout)])
    with ros_backend(args) as backend, background_server(create_app(backend)) as url:
        yield url, backend


@contextmanager
def open_page(browser_context, url, viewport=None):
    """A fresh tab on the page, once it is ready; JavaScript errors fail the test."""
    page = browser_context.new_page()
    if viewport:
        page.set_viewport_size(viewport)
    errors = []
    page.on('pageerror', lambda error: errors.append(str(error)))
    page.goto(url)
    page.wait_for_selector('body.ready')
    yield page
    page.close()
    assert errors == []


def choose_task(page, goals, initial_conditions=('stand_prep',)):
    page.select_option('#system', 'atlas')
    page.wait_for_selector('#initial-actions input[value="look_down"]')
    for box in page.locator('input[name="initial-condition"]').all():  # actions already completed
        box.set_checked(box.get_attribute('value') in initial_conditions)
    for mode in page.locator('input[name="initial-mode"]').all():  # the one control mode (radio buttons)
        if mode.get_attribute('value') in initial_conditions:
            mode.check()
    for goal in goals:
        page.select_option('#goal-choice', goal)
        page.click('#add-goal')


def result_code(page, timeout=120_000):
    page.wait_for_selector('#result:not([hidden]) #result-code:not(:empty)', timeout=timeout)
    return page.inner_text('#result-code')


def synthesize(page, goals, expected='SUCCESS'):
    """Choose ATLAS's task of ``goals`` from stand_prep, press Synthesize, check its code."""
    choose_task(page, goals)
    page.click('#synthesize')
    assert result_code(page) == expected


STATUS_DONE = "document.getElementById('simulation-status').textContent.match(/^(Outcome|Stopped)/)"


def stop_a_running_simulation(page) -> str:
    """Simulate the machine shown, stop the run as soon as a state is active; the status then."""
    page.click('#simulate')
    page.wait_for_selector('#runtime-control:not([hidden])', timeout=60_000)
    page.wait_for_selector('g.node.active', timeout=120_000)
    page.click('#stop-run')
    page.wait_for_function(STATUS_DONE, timeout=120_000)
    return page.inner_text('#simulation-status')


@contextmanager
def flexbe_gui_server(tmp_path_factory, flexbe, name):
    """``gui_server`` with the FlexBE workspace on AMENT_PREFIX_PATH (a capability robot's state classes)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv('AMENT_PREFIX_PATH', str(flexbe))
        with gui_server(tmp_path_factory.mktemp(name)) as served:
            yield served


TWELVE_GOALS = ['look_down', 'approach_object', 'pregrasp', 'grasp_object', 'pickup_object',
                'footstep_execution', 'object_template', 'pregrasp_pose', 'footstep_plan', 'target_pose',
                'pregrasp_plan', 'footstep_goal']
DOCS_SHOTS_ENV = 'BEHAVIOR_SYNTHESIS_DOCS_SHOTS'


def docs_shot(page, name):
    if os.environ.get(DOCS_SHOTS_ENV):
        Path(os.environ[DOCS_SHOTS_ENV]).mkdir(parents=True, exist_ok=True)
        page.screenshot(path=str(Path(os.environ[DOCS_SHOTS_ENV]) / name))
