"""Issue 16 in headless Chromium: impossible requests explained in plain words on the page."""

from test_gui_browser import browser_context, choose_task, gui, page, result_code  # noqa: F401 (fixtures)


def test_unrealizable_request_banner_names_the_missing_transition(page):  # noqa: F811
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


def test_control_mode_tooltips_name_the_modes_they_are_reached_from(page):  # noqa: F811
    choose_task(page, [])
    title = page.get_attribute('#goal-choice option[value="stand"]', 'title')
    assert title == 'reached from: stand_prep, manipulate, step, walk'
    assert page.get_attribute('#goal-choice option[value="stand_prep"]', 'title') == 'reached from: no other mode'
