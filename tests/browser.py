"""Browser tests' one way into a real browser: Playwright driving Debian's chromium.

Playwright's own browser download is not reachable from our machines, so the browser is
Debian's ``chromium`` (``make test`` installs it through the Makefile's ``browser-tool``).
Where it is missing, browser tests skip with the one line :func:`problem` gives.

Use the ``page`` fixture (``from browser import module_chromium, page`` in a test module:
each test's page in a context of its own, of one chromium per module), or :func:`chromium`
for a browser of your own.
"""

from __future__ import annotations

import os
import shutil
from contextlib import contextmanager
from typing import Iterator, Optional

import pytest

CHROMIUM = shutil.which('chromium') or '/usr/bin/chromium'


def problem() -> Optional[str]:
    """Why browser tests cannot run here, in one line (None when they can)."""
    if not os.path.exists(CHROMIUM):
        return 'chromium is not installed (make browser-tool, or sudo apt-get install chromium)'
    try:
        import playwright.sync_api  # noqa: F401
    except ImportError:
        return 'playwright is not installed (make setup installs environment/requirements.txt)'
    return None


@contextmanager
def chromium() -> Iterator:
    """A headless Debian chromium under Playwright; closed (and its processes gone) on exit."""
    from playwright.sync_api import sync_playwright
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM, headless=True,
            # As root (containers, CI) chromium refuses to start with its own sandbox.
            args=['--no-sandbox'] if os.geteuid() == 0 else [])
        try:
            yield browser
        finally:
            browser.close()


@pytest.fixture(scope='module')
def module_chromium():
    """One headless chromium for a test module's pages (a launch is costly: docs/decisions.md);
    skips the tests where there is no browser."""
    why = problem()
    if why:
        pytest.skip(why)
    with chromium() as browser:
        yield browser


@pytest.fixture
def page(module_chromium):
    """A fresh page, in a browser context of its own (its own cookies and storage), of the
    module's chromium."""
    context = module_chromium.new_context()
    yield context.new_page()
    context.close()
