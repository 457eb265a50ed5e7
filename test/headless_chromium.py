"""Headless Chromium (Debian's ``chromium``) for the browser tests, through Playwright."""

import tempfile
from contextlib import contextmanager

EXECUTABLE = '/usr/bin/chromium'
# Loopback only: no background, update or sync traffic from the browser.
ARGUMENTS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
             '--disable-background-networking', '--disable-component-update', '--disable-sync']


@contextmanager
def browser_context(**options):
    """A fresh-profile browser context (Playwright's ``launch_persistent_context`` options)."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright, tempfile.TemporaryDirectory() as profile:
        context = playwright.chromium.launch_persistent_context(
            profile, executable_path=EXECUTABLE, args=ARGUMENTS, headless=True, **options)
        try:
            yield context
        finally:
            context.close()
