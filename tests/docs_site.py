"""The course's website as the browser tests open it: built (``make docs``'s, else built
here), served on 127.0.0.1, and the site's own tools (docs/site/) loaded as modules.

Used by tests/test_docs_site.py and tests/test_site_accessibility.py; the ``site`` fixture
(the built site, served) is every module's (tests/conftest.py).
"""

from __future__ import annotations

import functools
import importlib.util
import os
import subprocess
import sys
import threading
from contextlib import contextmanager
from dataclasses import dataclass
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Iterator

import pytest

ROOT = Path(__file__).resolve().parents[1]
SITE_TOOLS = ROOT / 'docs' / 'site'
BUILT = ROOT / 'docs' / '_build' / 'html'
LESSONS = sorted(path.name for path in (ROOT / 'solutions').glob('[0-9][0-9]-*.ipynb'))
#: What a page may ask for besides its own server: pictures stored in the page itself.
IN_THE_PAGE = ('data:', 'blob:', 'about:')
#: Building under load (make test runs beside its other steps) is slow, never stuck.
BUILD_LIMIT_S = 900


def _load(name: str):
    spec = importlib.util.spec_from_file_location(f'docs_site_{name}', SITE_TOOLS / f'{name}.py')
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # as an import would: its dataclasses look themselves up
    spec.loader.exec_module(module)
    return module


site_lessons = _load('lessons')
site_build = _load('build')
site_schedule = _load('schedule')


def page_name(lesson: str) -> str:
    return f'lessons/{lesson.removesuffix(".ipynb")}.html'


def site_pages(html: Path) -> list[str]:
    """Every page of the built site ``html`` (its theme's files left out), relative to it."""
    return sorted(str(page.relative_to(html)) for page in html.rglob('*.html')
                  if page.relative_to(html).parts[0] != '_static')


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format, *args):  # noqa: A002 - http.server's own signature
        pass


@contextmanager
def served(folder: Path) -> Iterator[str]:
    """``folder`` served by http.server on 127.0.0.1 and a free port: its base URL."""
    handler = functools.partial(_QuietHandler, directory=str(folder))
    server = ThreadingHTTPServer(('127.0.0.1', 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f'http://127.0.0.1:{server.server_address[1]}/'
    finally:
        server.shutdown()
        server.server_close()
        thread.join()


def build_site(out: Path, course: Path = ROOT, *extra: str,
               env: dict | None = None) -> Path:
    """The site built by ``docs/site/build.py`` into ``out``: its html folder."""
    done = subprocess.run([sys.executable, str(SITE_TOOLS / 'build.py'), '--out', str(out),
                           '--course', str(course), *extra],
                          capture_output=True, text=True, timeout=BUILD_LIMIT_S,
                          env={**os.environ, **(env or {})})
    assert done.returncode == 0, done.stderr[-3000:]
    return out / 'html'


@dataclass(frozen=True)
class Site:
    html: Path  #: the built site's folder
    base: str   #: its URL on this machine's http.server


@pytest.fixture(scope='module')
def site(tmp_path_factory) -> Iterator[Site]:
    """The built site (``make docs``'s, else built here), served."""
    html = BUILT if (BUILT / 'index.html').exists() else \
        build_site(tmp_path_factory.mktemp('docs'))
    with served(html) as base:
        yield Site(html, base)


def watch_requests(page, base: str) -> list[str]:
    """Record every request of ``page``; the ones off this machine are listed (and stopped
    before they leave): the list returned, filled as the page loads."""
    off_machine: list[str] = []

    def route(route):
        url = route.request.url
        if url.startswith(base) or url.startswith(IN_THE_PAGE):
            route.continue_()
        else:
            route.abort()

    def request(request):
        if not (request.url.startswith(base) or request.url.startswith(IN_THE_PAGE)):
            off_machine.append(request.url)

    page.route('**/*', route)
    page.on('request', request)
    return off_machine


def open_page(page, url: str) -> None:
    """``url`` loaded: its scripts, styles and pictures (``load``) and its fonts."""
    page.goto(url, wait_until='load')
    page.evaluate('document.fonts.ready.then(() => true)')


def page_text(page) -> str:
    """All the text of the page, what a collapsed block holds included."""
    return page.evaluate('document.body.textContent')

