"""Regenerate the GUI screenshots of README.md and docs/gui.md (headless Chromium, the real
server and pipeline, an in-process suite), so that the pictures show the page as it is.

    PYTHONPATH=. MUJOCO_GL=egl .venv/bin/python docs/screenshots.py [--out docs]

Writes gui-result.png (1400x900, README's first picture), gui-layout-1280x720.png,
gui-abstraction.png, gui-runtime-control.png (a High transition waiting for the operator) and
gui-simulation.png (a finished run). Uses the browser tests' helpers (test/synthesis_manager/gui_in_browser.py).
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / 'test'), str(ROOT / 'test' / 'synthesis_manager')]

import headless_chromium
from gui_in_browser import STATUS_DONE as DONE, choose_task, gui_server, result_code

PAPER_GOALS = ['look_down', 'pickup_object']
WIDE, SMALL = {'width': 1400, 'height': 900}, {'width': 1280, 'height': 720}


def fresh_page(context, url, size):
    page = context.new_page()
    page.set_viewport_size(size)
    page.goto(url)
    page.wait_for_selector('body.ready')
    return page


def synthesized(context, url, size):
    page = fresh_page(context, url, size)
    choose_task(page, PAPER_GOALS)
    page.click('#synthesize')
    assert result_code(page) == 'SUCCESS'
    page.wait_for_selector('.graph-viewport svg')
    return page


def take(out: Path) -> list[Path]:
    written = []

    def save(page, name):
        path = out / name
        page.screenshot(path=str(path))
        written.append(path)

    with gui_server(tempfile.mkdtemp(prefix='screenshots-')) as (url, _backend), \
            headless_chromium.browser_context() as context:
        page = fresh_page(context, url, WIDE)
        choose_task(page, PAPER_GOALS)
        page.wait_for_function("document.getElementById('abstraction-path').textContent.includes('pickup_object')")
        save(page, 'gui-abstraction.png')
        page.close()

        page = synthesized(context, url, WIDE)
        page.click('g[id="state:stand"] text')
        save(page, 'gui-result.png')
        page.close()

        page = synthesized(context, url, SMALL)
        save(page, 'gui-layout-1280x720.png')
        page.close()

        page = synthesized(context, url, WIDE)
        page.select_option('#autonomy', '2')
        page.click('#simulate')
        page.wait_for_function("document.getElementById('operator-question').textContent.startsWith('stand returned')",
                               timeout=120_000)
        page.wait_for_function("document.getElementById('simulation-frame').naturalWidth > 0", timeout=60_000)
        save(page, 'gui-runtime-control.png')
        page.select_option('#autonomy', '3')  # Full: the rest runs on its own
        page.wait_for_function(DONE, timeout=180_000)
        page.wait_for_function("document.getElementById('simulation-frame').naturalWidth > 0")
        save(page, 'gui-simulation.png')
        page.close()
    return written


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=ROOT / 'docs', help='folder for the PNG files (default docs/)')
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    for path in take(args.out):
        print(path)
    return 0


if __name__ == '__main__':
    sys.exit(main())
