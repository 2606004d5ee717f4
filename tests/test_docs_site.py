"""The course's website (``make docs``, docs/site/): what a learner sees on it, and that it
stays on this machine.

The browser tests open the built site (``docs/_build/html``, which ``make test`` builds
first; built into a temporary folder when it is missing) in Debian's chromium, served by
Python's http.server on 127.0.0.1: the search finds what learners look for, the lessons'
pictures load, the exercise blocks show no solution, and no page asks for anything off the
machine.  Each protection also meets the failure it prevents: a learner page built with a
solution left in, and a page with an image from the network.  The tests without a marker
check the lesson pages and the link check as plain Python (``make check``).
"""

from __future__ import annotations

import functools
import importlib.util
import json
import os
import re
import shutil
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
    spec.loader.exec_module(module)
    return module


site_lessons = _load('lessons')
site_build = _load('build')


# ---- what a lesson's solution looks like, read here from the notebooks, not from lessons.py

SOLUTION = re.compile(r'### BEGIN SOLUTION\n(.*?)### END SOLUTION', re.S)


def _source(cell: dict) -> str:
    text = cell.get('source', '')
    return text if isinstance(text, str) else ''.join(text)


def _notebook(course: Path, folder: str, lesson: str) -> dict:
    return json.loads((course / folder / lesson).read_text())


def plain(text: str) -> str:
    """``text`` as a page shows it, near enough: Markdown's backticks gone, each run of white
    space one space (a line break in a notebook's Markdown is a space on the page)."""
    return ' '.join(text.replace('`', '').split())


@functools.lru_cache(maxsize=None)
def solution_text(lesson: str, course: Path = ROOT) -> frozenset[str]:
    """The lines between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` of ``lesson``'s
    solution notebook that its learner notebook does not show anyway (:func:`plain`; lines
    as short as ``pass`` or ``else:`` say nothing)."""
    given = plain('\n'.join(_source(cell) for cell in
                            _notebook(course, 'notebooks', lesson)['cells']))
    lines = {plain(line) for cell in _notebook(course, 'solutions', lesson)['cells']
             for region in SOLUTION.findall(_source(cell)) for line in region.splitlines()}
    return frozenset(line for line in lines if len(line) >= 8 and line not in given)


def solutions_shown(text: str, lesson: str, course: Path = ROOT) -> list[str]:
    """The lines of ``lesson``'s solutions that ``text`` (a page's text) shows."""
    text = plain(text)
    return sorted(line for line in solution_text(lesson, course) if line in text)


def notebook_text(notebook: dict) -> str:
    """Every cell's source and every output's text of ``notebook``."""
    parts = []
    for cell in notebook['cells']:
        parts.append(_source(cell))
        for output in cell.get('outputs', []):
            for value in [output.get('text', ''), *output.get('data', {}).values()]:
                parts.append(value if isinstance(value, str) else ''.join(map(str, value)))
    return '\n'.join(parts)


def answer_cells(lesson: str) -> int:
    return sum(1 for cell in _notebook(ROOT, 'solutions', lesson)['cells']
               if cell.get('metadata', {}).get('nbgrader', {}).get('solution'))


def page_name(lesson: str) -> str:
    return f'lessons/{lesson.removesuffix(".ipynb")}.html'


# ---- the check lane: the lesson pages and the link check, as plain Python

@pytest.mark.parametrize('lesson', LESSONS)
def test_lesson_page_holds_exercises_and_no_solution(lesson):
    solution = _notebook(ROOT, 'solutions', lesson)
    learner = _notebook(ROOT, 'notebooks', lesson)
    page = site_lessons.learner_page(solution, learner, lesson)
    text = notebook_text(page)
    assert solutions_shown(text, lesson) == []
    assert text.count('{exercise}') == answer_cells(lesson) > 0
    assert '### BEGIN HIDDEN TESTS' not in text
    assert site_lessons.WIDGET_VIEW not in text
    assert '{launch}' in text
    # The instructor's page keeps every solution: the learner's page left them out.
    instructor = site_lessons.learner_page(solution, learner, lesson, solutions=True)
    assert solutions_shown(notebook_text(instructor), lesson) == sorted(solution_text(lesson))


def test_an_answer_without_its_learner_cell_is_refused():
    lesson = '04-write-the-subscriber.ipynb'
    learner = _notebook(ROOT, 'notebooks', lesson)
    solution = _notebook(ROOT, 'solutions', lesson)
    answer = next(cell['id'] for cell in solution['cells']
                  if cell.get('metadata', {}).get('nbgrader', {}).get('solution'))
    learner['cells'] = [cell for cell in learner['cells'] if cell.get('id') != answer]
    with pytest.raises(ValueError, match=f'answer cell {answer} has no learner version'):
        site_lessons.learner_page(solution, learner, lesson)


def test_link_check_names_broken_links_and_network_loads(tmp_path):
    (tmp_path / 'docs').mkdir()
    (tmp_path / 'docs' / 'guide.html').write_text('<h1 id="top">Guide</h1>')
    (tmp_path / 'index.html').write_text(
        '<a href="docs/guide.html#top">fine</a> <a href="https://example.com/">a link out</a>'
        '<img src="data:image/png;base64,AAAA"> <a href="#here" id="here">here</a>'
        '<a href="docs/missing.html">gone</a> <a href="docs/guide.html#nowhere">no anchor</a>'
        '<script src="https://cdn.example.com/require.js"></script>'
        '<link rel="stylesheet" href="//fonts.example.com/font.css">')
    assert site_build.link_problems(tmp_path) == [
        'index.html: docs/missing.html names no file of the site',
        'index.html: docs/guide.html#nowhere: no id "nowhere" on that page',
        'index.html: <script src="https://cdn.example.com/require.js"> loads from the network',
        'index.html: <link href="//fonts.example.com/font.css"> loads from the network',
    ]


# ---- the browser lane: the built site in chromium

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


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
@pytest.mark.parametrize('query, expected', [('QoS', '09 · Quality of service (QoS)'),
                                             ('Ctrl+C', '05 · Entry points and ros2 run')])
def test_search_finds(site, page, query, expected):
    off_machine = watch_requests(page, site.base)
    open_page(page, site.base + 'index.html')
    page.keyboard.press('Control+KeyK')  # the theme's search dialog, as the page says
    search = page.locator('#pst-search-dialog input[type="search"]')
    search.fill(query)
    search.press('Enter')
    page.wait_for_url('**/search.html?q=*')
    # Sphinx lists the results one by one, then says how many it found.
    page.locator('#search-results .search-summary', has_text='Search finished').wait_for()
    titles = page.locator('#search-results ul.search li > a').all_inner_texts()
    assert expected in titles
    assert off_machine == []


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
@pytest.mark.parametrize('lesson, pictures', [('04-write-the-subscriber.ipynb', 1),
                                              ('06-five-promises.ipynb', 4),
                                              ('07-live-plot.ipynb', 3)])
def test_lesson_shows_its_pictures(site, page, lesson, pictures):
    open_page(page, site.base + page_name(lesson))
    images = page.locator('.cell_output img')
    assert images.count() == pictures
    for image in images.all():
        source = image.get_attribute('src')
        assert source.startswith('data:') or '://' not in source, source
    # Every picture loaded (a broken one has no natural width) once the page has.
    assert page.evaluate('[...document.querySelectorAll(".cell_output img")]'
                         '.every(img => img.complete && img.naturalWidth > 0)')


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
@pytest.mark.parametrize('lesson', LESSONS)
def test_exercises_show_no_solution(site, page, lesson):
    open_page(page, site.base + page_name(lesson))
    assert page.locator('.exercise').count() == answer_cells(lesson)
    assert 'Exercise' in page.locator('.exercise').first.inner_text()
    assert solutions_shown(page_text(page), lesson) == []
    assert 'Open this lesson' in page_text(page)
    assert 'hub' not in page.locator('.launch').first.inner_text().lower()


@pytest.fixture(scope='module')
def planted_site(tmp_path_factory) -> Iterator[str]:
    """Lesson 04 built from a copy of the course whose learner notebook kept the solution
    of one answer cell, with a hub's URL template set: served, its base URL."""
    course = tmp_path_factory.mktemp('planted-course')
    lesson = '04-write-the-subscriber.ipynb'
    for folder in ('solutions', 'notebooks'):
        (course / folder).mkdir()
        shutil.copy(ROOT / folder / lesson, course / folder / lesson)
    solution = _notebook(course, 'solutions', lesson)
    answer = next(cell for cell in solution['cells']
                  if cell.get('metadata', {}).get('nbgrader', {}).get('solution'))
    learner = _notebook(course, 'notebooks', lesson)
    for cell in learner['cells']:
        if cell.get('id') == answer['id']:
            cell['source'] = answer['source']
    (course / 'notebooks' / lesson).write_text(json.dumps(learner, indent=1))
    html = build_site(tmp_path_factory.mktemp('planted-docs'), course, '--lessons', '04',
                      env={'DOCS_HUB_URL': 'http://127.0.0.1:1/hub/lab/tree/{notebook}'})
    with served(html) as base:
        yield base


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_a_solution_left_in_a_learner_page_is_caught(planted_site, page):
    lesson = '04-write-the-subscriber.ipynb'
    open_page(page, planted_site + page_name(lesson))
    shown = solutions_shown(page_text(page), lesson)
    assert 'self.get_logger().info(\'Temperature Monitor Node Started\')' in shown


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_hub_link_only_where_a_hub_is_set(planted_site, page):
    open_page(page, planted_site + page_name('04-write-the-subscriber.ipynb'))
    link = page.locator('.launch a', has_text='open 04-write-the-subscriber.ipynb')
    assert link.get_attribute('href') == \
        'http://127.0.0.1:1/hub/lab/tree/04-write-the-subscriber.ipynb'


def site_pages(html: Path) -> list[str]:
    return sorted(str(page.relative_to(html)) for page in html.rglob('*.html')
                  if page.relative_to(html).parts[0] != '_static')


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_no_page_asks_for_anything_off_the_machine(site, page):
    off_machine = watch_requests(page, site.base)
    names = site_pages(site.html)
    for name in names:
        open_page(page, site.base + name)
    assert len(names) > len(LESSONS)
    assert off_machine == []


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_a_page_asking_the_network_is_caught(site, page, tmp_path):
    built = page.context.request.get(site.base + page_name('04-write-the-subscriber.ipynb')).text()
    planted = built.replace('</body>', '<img src="https://example.com/x.png"></body>')
    (tmp_path / 'lessons').mkdir()
    (tmp_path / 'lessons' / 'planted.html').write_text(planted)
    with served(tmp_path) as base:
        off_machine = watch_requests(page, base)
        open_page(page, base + 'lessons/planted.html')
    assert off_machine == ['https://example.com/x.png']
