"""Fixtures of the shell's tests: the GUI served with its suite in-process, a headless Chromium
and a tab on the GUI, the GUI's JSON API. Module-scoped: each module gets its own; a module
defining a fixture of the same name (a GUI with other settings, a tab of another size) uses its own.
A module may instead say ``GUI_LIMITS`` (gui_server's time limits) and ``WINDOW`` (the tab's size)."""

import pytest
from fastapi.testclient import TestClient

from gui_in_browser import gui_server, open_page
from gui_jobs import gui_args
from synthesis_manager.programs.gui import ros_backend
from synthesis_manager.web.routes import create_app

import headless_chromium


@pytest.fixture(scope='module')
def gui(request, tmp_path_factory):
    limits = getattr(request.module, 'GUI_LIMITS', {})
    with gui_server(tmp_path_factory.mktemp('gui-browser'), **limits) as served:
        yield served


@pytest.fixture(scope='module')
def browser_context():
    with headless_chromium.browser_context(accept_downloads=True, viewport={'width': 1400, 'height': 1000}) as context:
        yield context


@pytest.fixture
def page(request, gui, browser_context):
    with open_page(browser_context, gui[0], viewport=getattr(request.module, 'WINDOW', None)) as page:
        yield page


@pytest.fixture(scope='module')
def backend(tmp_path_factory):
    with ros_backend(gui_args(tmp_path_factory.mktemp('gui-api'))) as backend:
        yield backend


@pytest.fixture(scope='module')
def client(backend):
    with TestClient(create_app(backend)) as client:
        yield client
