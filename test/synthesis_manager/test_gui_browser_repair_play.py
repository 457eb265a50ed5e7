"""The page's "Suggest fixes" and plays in headless Chromium, against the real server and pipeline
(issue 33: "Suggest fixes" -> apply -> SUCCESS, and a play to the end in both directions).
With $BEHAVIOR_SYNTHESIS_DOCS_SHOTS set to a directory, the fixes and a play of the environment
are also written there (docs/gui-fixes.png, docs/gui-play.png)."""

import re

import pytest

from gui_in_browser import choose_task, docs_shot, flexbe_gui_server, open_page, result_code, synthesize

pytestmark = [pytest.mark.ros, pytest.mark.browser, pytest.mark.flexbe]


@pytest.fixture(scope='module')
def gui(tmp_path_factory, flexbe):
    with flexbe_gui_server(tmp_path_factory, flexbe, 'gui-repair-play') as served:  # the rover's state classes
        yield served


@pytest.fixture
def page(gui, browser_context):
    with open_page(browser_context, gui[0]) as page:
        yield page


def goals_in_form(page):
    return page.locator('#goals li').evaluate_all('items => items.map(i => i.dataset.goal)')


def test_suggest_fixes_then_apply_one_and_the_new_machine_is_drawn(page):
    choose_task(page, ['look_down', 'stand_prep'])
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    assert page.is_visible('#suggest-fixes') and page.is_visible('#play-robot')
    # proposals show as they are verified, while the search goes on (the problem's diagnosis comes
    # last): count those added while the section still says it is searching
    page.evaluate('''() => {
      window.shownWhileSearching = 0;
      new MutationObserver((changes) => {
        if (!document.querySelector('#repair-section').classList.contains('searching')) return;
        window.shownWhileSearching += changes.reduce((sum, change) => sum + change.addedNodes.length, 0);
      }).observe(document.querySelector('#proposals'), { childList: true });
    }''')
    page.click('#suggest-fixes')
    assert page.is_visible('#repair-section')
    page.wait_for_selector('#proposals li.proposal', timeout=60_000)
    page.wait_for_selector('#repair-section:not(.searching)', timeout=60_000)   # the search has ended
    assert page.evaluate('window.shownWhileSearching') >= 1
    page.locator('#repair-section').scroll_into_view_if_needed()
    docs_shot(page, 'gui-fixes.png')
    assert re.match(r'\d+ verified fix', page.inner_text('#repair-status'))
    assert page.inner_text('#repair-problem').startswith('The problem: SPEC_UNSYNTHESIZABLE: Goal 2 (stand_prep)')
    # a change of the robot is marked, shows its patch and cannot be applied from here
    robot = page.locator('li.proposal.changes-robot').first
    assert 'Changes the robot — not applied' in robot.inner_text()
    assert 'in config/atlas.yaml, set abstraction.control_modes.stand' in robot.locator('.config-patch').inner_text()
    assert robot.locator('button.apply-fix').count() == 0
    reorder = page.locator('li.proposal[data-kind="reorder_goals"]')
    assert 'goals: look_down, stand_prep → stand_prep, look_down' in reorder.inner_text()

    reorder.locator('button.apply-fix').click()
    page.wait_for_function("document.querySelector('#result-code').textContent === 'SUCCESS'", timeout=120_000)
    assert goals_in_form(page) == ['stand_prep', 'look_down']      # the form holds the applied request
    page.wait_for_selector('#graph svg g.node')
    assert page.is_hidden('#repair-section') and page.is_hidden('#suggest-fixes')


def test_custom_ltl_is_sent_and_a_weakened_guarantee_is_applied(page):
    choose_task(page, ['look_down'])
    page.click('#custom-ltl-box summary')
    page.fill('#custom-ltl', '{oops')
    page.click('#synthesize')
    assert page.inner_text('#form-problem').startswith('Custom LTL: not JSON')
    assert page.evaluate('document.activeElement.id') == 'custom-ltl'
    page.fill('#custom-ltl', '{"sys_trans": ["!look_down_a"]}')
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    page.click('#suggest-fixes')
    weakened = page.locator('li.proposal[data-kind="weaken_guarantee"]')
    weakened.wait_for(timeout=60_000)
    assert 'custom LTL becomes' in weakened.inner_text()
    weakened.locator('button.apply-fix').click()
    page.wait_for_function("document.querySelector('#result-code').textContent === 'SUCCESS'", timeout=120_000)
    assert '!look_down_a' not in page.input_value('#custom-ltl')


def test_playing_the_robot_of_an_unrealizable_task_until_it_loses(page):
    choose_task(page, ['look_down', 'stand_prep'])
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    page.click('#play-robot')
    panel = page.locator('#play-panel')
    page.wait_for_selector('#play-choices button.play-choice')
    assert panel.is_visible() and page.is_visible('#robot-play-section')
    assert page.inner_text('#play-position').startswith('Step 0 of at most 12: ')
    assert 'now in stand_prep' in page.inner_text('#play-position')
    assert 'Why it cannot win: the environment keeps goal 1 (the state machine ends finished or' in \
        page.inner_text('#play-verdict')
    first = page.locator('#play-choices button.play-choice').first.inner_text()
    assert first.endswith(' starts') and '_a' not in first  # progress first, in the task's words
    dead_ends = page.locator('#play-choices .play-choice.dead-end')
    assert dead_ends.count() >= 1 and not dead_ends.first.is_visible()   # folded: they lose at once
    page.click('#play-choices details.dead-ends summary')
    assert 'dead end: the environment can answer so that no response is allowed' in page.inner_text('#play-choices')

    # keyboard: "keep every output as it is" twice comes back to a position of this play
    def press_choice(words):
        buttons = page.locator('#play-choices button.play-choice')
        texts = [text.strip() for text in buttons.all_inner_texts()]
        number = next(i for i, text in enumerate(texts, start=1) if text.endswith(words))
        page.keyboard.press(str(number))

    page.focus('#play-panel')
    assert 'loop: it returns to a position of this play' in page.inner_text('#play-choices')
    press_choice('keep every output as it is')
    page.wait_for_function("document.querySelector('#play-position').textContent.startsWith('Step 1')")
    assert page.inner_text('#play-verdict').startswith(
        'Verdict: the environment wins: the robot came back to a position of this play')
    assert page.locator('#play-choices button').count() == 0   # the play is over
    page.keyboard.press('Backspace')                    # back
    page.wait_for_function("document.querySelector('#play-position').textContent.startsWith('Step 0')")

    page.click('#play-choices details.dead-ends summary')
    page.locator('#play-choices .play-choice.dead-end').first.click()   # the environment answers: stuck
    page.wait_for_function("document.querySelector('#play-verdict').textContent.startsWith("
                           "'Verdict: the environment wins')")
    assert 'deadlock' in page.inner_text('#play-verdict')
    assert page.locator('#play-choices button').count() == 0
    assert page.locator('#play-history li').count() == 1
    page.click('#play-reset')
    page.wait_for_function("document.querySelector('#play-position').textContent.startsWith('Step 0')")


def play_environment_to_the_end(page):
    page.wait_for_selector('#graph svg g.node')
    page.click('#play-environment')
    page.wait_for_selector('#play-choices button.play-choice')
    assert page.is_visible('#play-panel') and page.locator('#graph-layout.playing').count() == 1
    # the active state's outcome cell on the drawing reports that outcome
    first = page.inner_text('#play-choices button.play-choice >> nth=0').split(maxsplit=1)[1]
    page.locator('#graph svg g.node.active text', has_text=first).first.click()
    page.wait_for_function("document.querySelector('#play-position').textContent.startsWith('Step 1:')")
    assert page.inner_text('#play-history li >> nth=0').endswith(f'→ {first}')
    steps = 1
    while 'ended' not in page.inner_text('#play-position'):
        active = page.inner_text('#play-position').split(': ', 1)[1].removesuffix(' is active.')
        assert page.locator('#graph svg g.node.active').get_attribute('id') == f'state:{active}'
        page.keyboard.press('1')                          # its first outcome: the success one
        steps += 1
        page.wait_for_function(f"document.querySelector('#play-position').textContent.startsWith('Step {steps}:')")
        assert steps < 20
    assert page.inner_text('#play-position').endswith('the machine ended in finished.')
    assert page.locator('#graph svg g.node.active').count() == 0
    assert page.locator('#graph svg .ended').count() >= 1 and page.locator('#graph svg g.edge.taken').count() >= steps
    assert page.locator('#play-history li').count() == steps
    return steps


def test_playing_the_environment_of_a_machine_until_it_ends(page):
    choose_task(page, ['look_down', 'pickup_object'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    steps = play_environment_to_the_end(page)
    page.click('#play-back')
    page.wait_for_function(f"document.querySelector('#play-position').textContent.startsWith('Step {steps - 1}:')")
    assert page.locator('#graph svg g.node.active').count() == 1
    page.locator('#graph-section').scroll_into_view_if_needed()
    docs_shot(page, 'gui-play.png')
    page.focus('#play-back')
    page.keyboard.press('Escape')                       # closes the play
    assert page.is_hidden('#play-panel') and page.locator('#graph svg .active, #graph svg .taken').count() == 0
    page.click('#play-environment')                     # a new play starts at the initial state
    page.wait_for_function("document.querySelector('#play-position').textContent.startsWith('Step 0:')")
    page.click('#play-close')
    assert page.is_hidden('#play-panel')


def choose_rover_goals(page, goals):
    page.select_option('#system', 'delivery_rover')
    page.wait_for_selector('#goal-choice option[value="hand_over"]', state='attached')
    assert page.locator('#initial-control-modes input').count() == 0   # capabilities, no control modes
    for goal in goals:
        page.select_option('#goal-choice', goal)
        page.click('#add-goal')


def test_a_capability_robot_is_played_as_well(page):
    choose_rover_goals(page, ['drive', 'hand_over'])
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    assert play_environment_to_the_end(page) >= 2


def test_a_capability_robot_asked_to_drive_and_not_to_drive_is_played_and_fixed(page):
    choose_rover_goals(page, ['drive', '!drive'])          # "must not hold at the end": a goal CNU allows
    page.click('#synthesize')
    assert result_code(page) == 'SPEC_UNSYNTHESIZABLE'
    page.click('#play-robot')
    page.wait_for_selector('#play-choices button.play-choice')
    assert 'Why it cannot win: the environment keeps goal 1 (the state machine ends finished or the state ' \
        'machine ends failed)' in page.inner_text('#play-verdict')
    steps = 0
    while not page.inner_text('#play-verdict').startswith('Verdict: '):   # progress first, until the play ends
        page.locator('#play-choices button.play-choice').first.click()
        steps += 1
        page.wait_for_function(f"document.querySelector('#play-position').textContent.startsWith('Step {steps} ')")
        assert steps <= 12
    assert page.inner_text('#play-verdict').startswith('Verdict: the environment wins: ')

    page.click('#suggest-fixes')
    dropped = page.locator('li.proposal[data-kind="drop_goal"]').first
    dropped.wait_for(timeout=60_000)
    dropped.locator('button.apply-fix').click()
    page.wait_for_function("document.querySelector('#result-code').textContent === 'SUCCESS'", timeout=120_000)
    assert len(goals_in_form(page)) == 1


@pytest.mark.parametrize('size', [{'width': 1280, 'height': 720}, {'width': 1920, 'height': 1080}],
                         ids=lambda s: f"{s['width']}x{s['height']}")
def test_playing_the_robot_progress_first_ends_with_a_verdict_in_view_and_readable(gui, browser_context, size):
    with open_page(browser_context, gui[0], viewport=size) as page:
        synthesize(page, ['look_down', 'stand_prep'], 'SPEC_UNSYNTHESIZABLE')
        page.click('#play-robot')
        page.wait_for_selector('#play-choices button.play-choice')
        assert 'a play ends within 12 moves' in page.inner_text('#play-prompt')
        said = set()
        for step in range(13):
            page.wait_for_function("n => document.querySelector('#play-position').textContent.startsWith(`Step ${n} `)",
                                   arg=step)
            verdict = page.inner_text('#play-verdict')
            assert verdict not in said or not verdict  # no line said at every step
            said.add(verdict)
            if verdict.startswith('Verdict: '):
                break
            # the first offered move is progress, in the task's words, readable, in view
            first = page.locator('#play-choices button.play-choice').first
            words = first.inner_text()
            assert '_a off' not in words and 'dead-end' not in (first.get_attribute('class') or '')
            box = first.bounding_box()
            assert box['y'] >= 0 and box['y'] + box['height'] <= size['height'], box
            assert page.evaluate("e => parseFloat(getComputedStyle(e).fontSize)", first.element_handle()) >= 11
            first.click()
        verdict = page.inner_text('#play-verdict')
        assert verdict.startswith('Verdict: the environment wins: ') or verdict == 'Verdict: you reached every goal.'
        box = page.locator('#play-verdict').bounding_box()
        assert box['y'] >= 0 and box['y'] + box['height'] <= size['height'], box
        assert page.locator('#play-choices button').count() == 0
        assert page.locator('#play-history li').count() <= 12
