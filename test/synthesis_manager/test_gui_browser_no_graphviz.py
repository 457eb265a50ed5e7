"""The GUI on a machine without Graphviz' `dot` (a PATH without it): the WebAssembly Graphviz
that `make setup` installs from npm draws the machine, and the picture downloads still work
(the SVG from the server, the PNG made by the page), at 1280x720 and 1920x1080."""

import json
import os
import shutil
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from synthesis_manager.web import picture
from gui_in_browser import TWELVE_GOALS, choose_task, gui_server, open_page, result_code

pytestmark = [pytest.mark.ros, pytest.mark.browser]

SIZES = [{'width': 1280, 'height': 720}, {'width': 1920, 'height': 1080}]


@pytest.fixture(scope='module')
def gui_without_dot(tmp_path_factory):
    """The GUI served with PATH holding only `node` and the venv's programs: no `dot`."""
    programs = tmp_path_factory.mktemp('programs-without-dot')
    (programs / 'node').symlink_to(shutil.which('node'))
    saved = os.environ['PATH']
    os.environ['PATH'] = f'{programs}{os.pathsep}{Path(os.sys.executable).parent}'
    try:
        assert shutil.which('dot') is None and picture.png_in_page()
        with gui_server(tmp_path_factory.mktemp('gui-no-dot')) as served:
            yield served
    finally:
        os.environ['PATH'] = saved


@pytest.mark.parametrize('size', SIZES, ids=lambda s: f"{s['width']}x{s['height']}")
def test_without_dot_the_machine_is_drawn_and_the_pictures_download(gui_without_dot, browser_context, size,
                                                                      tmp_path):
    url = gui_without_dot[0]
    with open_page(browser_context, url, viewport=size) as page:
        choose_task(page, ['look_down', 'pickup_object'])
        page.click('#synthesize')
        assert result_code(page) == 'SUCCESS'
        page.wait_for_selector('.graph-viewport svg g[id="state:pickup_object"]')
        job_id = page.eval_on_selector('a[data-artifact="state_machine.svg"]', 'a => a.href.split("/")[5]')
        with urllib.request.urlopen(f'{url}api/jobs/{job_id}/state-machine') as response:
            machine = json.load(response)
        states = [state['name'] for state in machine['children'] if state['name'] not in machine['outcomes']]
        drawn = page.eval_on_selector_all('.graph-viewport svg g.node[id^="state:"]',
                                          'nodes => nodes.map(n => n.id.slice(6))')
        assert sorted(drawn) == sorted(states) and len(states) >= 4, (drawn, states)
        for name in states:  # each state a box with its name, of a real size on the screen
            box = page.locator(f'.graph-viewport svg g[id="state:{name}"]').bounding_box()
            assert box['width'] > 20 and box['height'] > 10, (name, box)
        assert page.locator('.graph-viewport svg g.node[id^="outcome:"]').count() >= 2  # finished, failed

        with page.expect_download() as download_info:
            page.click('a[data-artifact="state_machine.svg"]')
        svg = Path(download_info.value.path()).read_text()
        assert svg.startswith('<?xml') and 'id="state:look_down"' in svg and 'id="state:pickup_object"' in svg
        with page.expect_download() as download_info:
            page.click('a[data-artifact="state_machine.png"]')
        png_download = download_info.value
        png = Path(png_download.path()).read_bytes()
        assert png_download.suggested_filename.endswith('state_machine.png')
        assert png.startswith(b'\x89PNG') and len(png) > 10_000
        width, height = int.from_bytes(png[16:20], 'big'), int.from_bytes(png[20:24], 'big')
        assert width > 300 and height > 300, (width, height)


def test_without_dot_the_job_says_the_page_makes_the_png_and_the_server_says_why_it_cannot(gui_without_dot):
    url, backend = gui_without_dot
    request = urllib.request.Request(f'{url}api/jobs', method='POST', headers={'Content-Type': 'application/json'},
                                     data=json.dumps({'system': 'atlas', 'initial_conditions': ['stand_prep'],
                                                      'goals': ['look_down']}).encode())
    with urllib.request.urlopen(request) as response:
        job_id = json.load(response)['id']
    deadline = time.monotonic() + 120
    while True:
        with urllib.request.urlopen(f'{url}api/jobs/{job_id}') as response:
            job = json.load(response)
        if job['state'] == 'finished' or time.monotonic() > deadline:
            break
        time.sleep(0.2)
    assert job['made_in_page'] == ['state_machine.png'] and 'state_machine.svg' in job['artifacts']
    with pytest.raises(urllib.error.HTTPError) as refused:
        urllib.request.urlopen(f'{url}api/jobs/{job_id}/artifacts/state_machine.png')
    message = json.load(refused.value)['message']
    assert "Graphviz' 'dot' is not installed: the page makes the PNG from its drawing" in message


def test_without_dot_the_twelve_goal_machine_is_drawn_whole_at_1920x1080(gui_without_dot, browser_context):

    size = {'width': 1920, 'height': 1080}
    with open_page(browser_context, gui_without_dot[0], viewport=size) as page:
        choose_task(page, TWELVE_GOALS)
        page.click('#synthesize')
        assert result_code(page, timeout=200_000) == 'SUCCESS'
        page.wait_for_selector('.graph-viewport svg g.node')
        drawing = page.evaluate("""() => {
          const box = (e) => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
          const svg = document.querySelector('.graph-viewport svg');
          return {viewport: box(document.querySelector('.graph-viewport')),
                  nodes: [...svg.querySelectorAll('g.node')].map((n) => [n.id, box(n)]),
                  smallest: Math.min(...[...svg.querySelectorAll('text')].map((t) =>
                    parseFloat(getComputedStyle(t).fontSize) * svg.getScreenCTM().a))}; }""")
        left, top, right, bottom = drawing['viewport']
        assert bottom <= size['height'] and right <= size['width']
        states = [node for node, _ in drawing['nodes'] if node.startswith('state:')]
        assert len(states) >= 20
        for node, (x0, y0, x1, y1) in drawing['nodes']:  # fitted: every box in view
            assert left - 1 <= x0 and x1 <= right + 1 and top - 1 <= y0 and y1 <= bottom + 1, node
        assert drawing['smallest'] >= 11
