"""The course's website (``make docs``, docs/site/): what a learner sees on it, and that it
stays on this machine.

The browser tests open the built site (``docs/_build/html``, which ``make test`` builds
first; built into a temporary folder when it is missing) in Debian's chromium, served by
Python's http.server on 127.0.0.1: the search finds what learners look for, the lessons'
pictures load, the exercise blocks show no solution, and no page asks for anything off the
machine, and axe-core (tests/accessibility.py) finds no violation of critical, serious or
moderate impact and the console no error on any page, in light and dark mode.  Each
protection also meets the failure it prevents: a learner page built with a solution left in,
a page with an image from the network, and one with an image without alt and a console
error.  The tests without a marker check the lesson pages and the link check as plain Python
(``make check``).
"""

from __future__ import annotations

import functools
import json
import re
import shutil
from pathlib import Path
from typing import Iterator

import pytest

import accessibility
from docs_site import (BUILD_LIMIT_S, LESSONS, ROOT, build_site, open_page, page_name,
                       page_text, served, site_build, site_lessons, site_pages,
                       watch_requests)

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


# ---- the browser lane: axe-core on every page (tests/accessibility.py)

#: axe's colour-contrast rule takes about a CPU-second on a long page: the pages are checked
#: in this many tests, so that each stays well inside its time limit on a busy machine.
AXE_PARTS = 3


@pytest.fixture(scope='module')
def axe_installed() -> None:
    why = accessibility.problem()
    if why:
        pytest.skip(why)


def page_problems(page, name: str, console: list[str]) -> tuple[str, list[str]]:
    """axe's findings on the page ``page`` shows (``name``): its row of the table (rules and
    elements per impact) and its problems, one line each: a violation of critical, serious
    or moderate impact, too little contrast where axe left it for review, a console error."""
    results = accessibility.run(page)
    counts = accessibility.counts(results)
    row = f'{name}: ' + ', '.join(f'{impact} {rules} ({nodes})'
                                  for impact, (rules, nodes) in counts.items())
    problems = [*accessibility.failures(results), *accessibility.reviewed(page, results),
                *console, *accessibility.sticking_out(page)]
    console.clear()
    return row, [f'{name}: {problem}' for problem in problems]


def console_errors(page) -> list[str]:
    """The page's console errors and uncaught exceptions, filled as they come."""
    errors: list[str] = []
    page.on('console', lambda message: errors.append(f'console error: {message.text}')
            if message.type == 'error' else None)
    page.on('pageerror', lambda error: errors.append(f'page error: {error}'))
    return errors


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
@pytest.mark.parametrize('part', range(AXE_PARTS))
@pytest.mark.parametrize('mode, width', [('light', 1280), ('dark', 400)])
def test_axe_finds_no_violation_on_any_page(site, module_chromium, axe_installed, mode, width,
                                            part):
    """Every page, in the theme's light and dark modes (the reader's system setting picks
    one), the one at a desktop's width and the other at a phone's: no violation of critical,
    serious or moderate impact, no console error, and nothing running off the right of the
    page.  The pages come in :data:`AXE_PARTS` parts, a test each; the table of the pages each
    ran is printed (pytest -s shows it)."""
    context = module_chromium.new_context(color_scheme=mode,
                                          viewport={'width': width, 'height': 900})
    page = context.new_page()
    console = console_errors(page)
    rows, problems = [], []
    for name in site_pages(site.html)[part::AXE_PARTS]:
        open_page(page, site.base + name)
        assert page.evaluate('document.documentElement.dataset.theme') == mode
        row, found = page_problems(page, name, console)
        rows.append(row)
        problems += found
    context.close()
    print(f'\naxe {accessibility.version()}, {mode} mode, {width} px wide, {len(rows)} pages:\n'
          + '\n'.join(rows))
    assert len(rows) >= len(LESSONS) // AXE_PARTS
    assert problems == []


#: A picture of one pixel, with no text alternative.
PIXEL = ('data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mNk'
         '+M9QDwADhgGAWjR9awAAAABJRU5ErkJggg==')


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_an_image_without_alt_and_a_console_error_are_caught(site, page, axe_installed):
    lesson = page_name('07-live-plot.ipynb')
    built = page.context.request.get(site.base + lesson).text()
    planted = built.replace('<article class="bd-article">',
                            f'<article class="bd-article"><img src="{PIXEL}">'
                            '<script>console.error("planted")</script>', 1)
    assert planted != built
    page.route('**/lessons/planted.html', lambda route: route.fulfill(
        status=200, content_type='text/html', body=planted))
    console = console_errors(page)
    open_page(page, site.base + 'lessons/planted.html')
    _, problems = page_problems(page, 'planted', console)
    assert [problem.split(':')[1].strip().split(' (')[0] for problem in problems] == \
        ['image-alt', 'console error'], problems
