"""Every learner can use the course: each figure says in words what it shows, the status
colours stay apart for colour-blind readers, the start page's schedule comes from the lessons,
and the website's colours and code hold up where axe-core cannot look.

The check lane reads the executed solutions and the site's tools as plain Python; the browser
lane opens the built site (tests/docs_site.py) in chromium: the theme's colour pairs, in light
and dark mode, hover included (axe never hovers).  tests/test_docs_site.py runs axe on every
page, and there checks that no code or text runs off the right of the page (a line that
cannot wrap is planted here).  Each protection meets the failure it prevents: matplotlib's
default palette, the theme's own hover colour, a line that cannot wrap, a figure without its
caption, a schedule whose points disagree.
"""

from __future__ import annotations

import copy
import json
import re

import numpy as np
import pytest
from colorspacious import cspace_convert, deltaE
from matplotlib.colors import to_rgb
from matplotlib.figure import Figure

import accessibility
from docs_site import (BUILD_LIMIT_S, LESSONS, ROOT, open_page, page_name, site_lessons,
                       site_schedule)
from ros2nb import course, figures
from ros2nb.terminal.graph import graph_caption

IMAGES = ('image/png', 'image/jpeg', 'image/svg+xml')
#: The lessons that draw figures, and how many each draws.
FIGURES = {'03-write-the-publisher.ipynb': 1, '04-write-the-subscriber.ipynb': 1,
           '06-five-promises.ipynb': 4, '07-live-plot.ipynb': 3,
           '10-record-and-replay.ipynb': 1}


def _notebook(folder: str, lesson: str) -> dict:
    return json.loads((ROOT / folder / lesson).read_text())


def _figure_cells(notebook: dict) -> list[dict]:
    return [cell for cell in notebook['cells'] if any(
        mime in output.get('data', {}) for output in cell.get('outputs', []) for mime in IMAGES)]


# ---- the check lane: figures, palette, schedule

@pytest.mark.parametrize('lesson', LESSONS)
def test_every_figure_of_the_solutions_says_what_it_shows(lesson):
    """Each figure the executed solution shows is followed by a caption line computed from its
    data (numbers in it), and the website gives that line to the picture as its alt text."""
    solution = _notebook('solutions', lesson)
    cells = _figure_cells(solution)
    assert len(cells) == FIGURES.get(lesson, 0)
    captions = [site_lessons.figure_caption(cell) for cell in cells]
    for caption in captions:
        # Numbers from the data (a live plot stored before its first reading says so).
        assert caption and len(caption) > 40, caption
        assert re.search(r'\d', caption) or 'no readings yet' in caption, caption
    page = site_lessons.learner_page(solution, _notebook('notebooks', lesson), lesson,
                                     solutions=True)
    alts = [cell['metadata']['mystnb']['image']['alt'] for cell in _figure_cells(page)]
    assert alts == captions
    # A live figure is shown by its stored picture, not by the widget's HTML (no alt there).
    assert not any('text/html' in output.get('data', {}) for cell in _figure_cells(page)
                   for output in cell['outputs'])


def test_a_figure_without_its_caption_fails_the_site():
    lesson = '04-write-the-subscriber.ipynb'
    solution = _notebook('solutions', lesson)
    for cell in _figure_cells(solution):
        cell['outputs'] = [output for output in cell['outputs']
                           if figures.CAPTION_START not in str(output.get('text', ''))]
    with pytest.raises(ValueError, match='shows a figure but no line "Figure: ..."'):
        site_lessons.learner_page(solution, _notebook('notebooks', lesson), lesson)


def test_a_temperature_caption_says_range_and_statuses():
    assert figures.temperature_caption('An hour', [0.0, 1800.0, 3600.0], [19.5, 22.0, 26.5]) == (
        'Figure: An hour: 3 readings over 60.0 min, 19.5–26.5 °C; Low 1, Normal 1, High 1 '
        '(Low below 20 °C, High above 26 °C).')
    assert figures.temperature_caption('Live', [1.0, 2.0], [20.0, 26.0]) == (
        'Figure: Live: 2 readings over 1 s, 20.0–26.0 °C, all inside the Normal band '
        '(20–26 °C).')
    assert figures.temperature_caption('Wall', [], []) == \
        'Figure: Wall: no readings yet; the plot fills as they arrive.'
    with pytest.raises(ValueError, match='got 1 times and 2 readings'):
        figures.temperature_caption('Bad', [1.0], [20.0, 21.0])


def test_a_graph_caption_names_each_topic_with_its_ends():
    edges = [('/sensor', 'publisher', '/temperature'), ('/monitor', 'subscription', '/temperature'),
             ('/fan', 'publisher', '/fan_speed')]
    assert graph_caption(edges, 'Three nodes') == (
        'Figure: the ROS graph, Three nodes: 3 nodes, 2 topics. /fan_speed: published by /fan; '
        'subscribed by nobody. /temperature: published by /sensor; subscribed by /monitor.')


#: The least colour difference (CIECAM02-UCS ΔE) between two status bands, in every vision
#: simulated: about ten times what a viewer just notices (docs/decisions.md).
MIN_DELTA_E = 10.0
#: Colour vision simulated with Machado, Oliveira & Fernandes (2009) at full severity.
VISIONS = (None, 'deuteranomaly', 'protanomaly')


def least_difference(colours: list[str], alpha: float) -> tuple[float, str]:
    """The smallest ΔE between any two of ``colours`` drawn at ``alpha`` over white, in any
    vision of :data:`VISIONS`, and that vision's name."""
    drawn = [alpha * np.array(to_rgb(colour)) + (1 - alpha) for colour in colours]
    worst = (float('inf'), '')
    for vision in VISIONS:
        seen = [np.clip(cspace_convert(rgb, {'name': 'sRGB1+CVD', 'cvd_type': vision,
                                             'severity': 100}, 'sRGB1'), 0, 1)
                if vision else rgb for rgb in drawn]
        for i in range(len(seen)):
            for j in range(i + 1, len(seen)):
                worst = min(worst, (float(deltaE(seen[i], seen[j], input_space='sRGB1')),
                                    vision or 'normal vision'))
    return worst


def test_status_bands_stay_apart_in_deuteranopia_and_protanopia():
    palette = [figures.STATUS_STYLES[status].colour for status in course.STATUSES]
    difference, vision = least_difference(palette, figures.BAND_ALPHA)
    assert difference >= MIN_DELTA_E, (difference, vision)
    # matplotlib's default blue, green and red, as the notebooks drew them before, do not:
    # green and red fall together for a deuteranope.
    difference, vision = least_difference(['tab:blue', 'tab:green', 'tab:red'], 0.15)
    assert difference < MIN_DELTA_E and vision == 'deuteranomaly'


def test_status_bands_carry_more_than_colour():
    """Each band also has a hatching of its own and its status written on it."""
    ax = Figure().add_subplot()
    figures.status_bands(ax)
    assert [patch.get_label() for patch in ax.patches] == list(course.STATUSES)
    assert len({patch.get_hatch() or '' for patch in ax.patches}) == len(course.STATUSES)
    assert [text.get_text() for text in ax.texts] == list(course.STATUSES)


def test_the_schedule_comes_from_the_notebooks():
    schedule = site_schedule
    rows = schedule.lessons(ROOT)
    assert [row.page for row in rows] == [f'lessons/{lesson}' for lesson in LESSONS]
    for row, lesson in zip(rows, LESSONS):
        graded = [cell['metadata']['nbgrader'] for cell in _notebook('solutions', lesson)['cells']
                  if cell.get('metadata', {}).get('nbgrader', {}).get('grade')]
        assert row.points == sum(grading.get('points', 0) for grading in graded) > 0
        assert row.teaching_min > 0 and row.exercises_min > 0 and row.writes
    table = schedule.schedule_markdown(rows)
    total_min = sum(row.teaching_min + row.exercises_min for row in rows)
    assert f'**{total_min // 60} h {total_min % 60:02d} min**' in table
    assert f'**{sum(row.points for row in rows):g}**' in table
    # The instructors' page states the same totals in its opening.
    opening = ' '.join((ROOT / 'docs' / 'instructors.md').read_text().split('\n## ')[1].split())
    assert opening.startswith('Teach this course in one page')
    assert f'{total_min // 60} h {total_min % 60:02d} min' in opening
    assert f'{sum(row.points for row in rows):g} points' in opening


def test_a_schedule_whose_points_disagree_fails_the_build():
    schedule = site_schedule
    notebook = copy.deepcopy(_notebook('solutions', '03-write-the-publisher.ipynb'))
    for cell in notebook['cells']:
        if cell.get('metadata', {}).get('nbgrader', {}).get('points'):
            cell['metadata']['nbgrader']['points'] += 1
            break
    with pytest.raises(ValueError, match=r'Points:\*\* line says 6, its graded cells give 7'):
        schedule.lesson(notebook, '03-write-the-publisher.ipynb')


# ---- the browser lane: the theme's colours, and nothing running off the page

#: (text colour, background) pairs the theme draws text with, as its CSS variables
#: (--pst-color-NAME); link-hover is what a link turns to under the pointer.
THEME_PAIRS = [('text-base', 'background'), ('text-muted', 'background'),
               ('heading', 'background'), ('link', 'background'), ('link-hover', 'background'),
               ('inline-code', 'surface'), ('text-base', 'on-background'),
               ('link', 'on-background'), ('table', 'table-row-zebra-low-bg'),
               ('table', 'table-row-zebra-high-bg')]


def theme_contrast(page) -> dict[tuple[str, str], float]:
    """Each pair of :data:`THEME_PAIRS` drawn on the page in a span of its own: its contrast."""
    for number, (text, background) in enumerate(THEME_PAIRS):
        page.evaluate(f"""() => {{ const span = document.createElement('span');
            span.id = 'pair-{number}'; span.textContent = 'Sample';
            span.style.color = 'var(--pst-color-{text})';
            span.style.background = 'var(--pst-color-{background})';
            document.querySelector('.bd-article').appendChild(span); }}""")
    found = accessibility.contrast(page, [f'#pair-{n}' for n in range(len(THEME_PAIRS))])
    return {pair: ratio for pair, (_, ratio, _) in zip(THEME_PAIRS, found)}


@pytest.fixture(scope='module')
def axe_installed() -> None:
    why = accessibility.problem()
    if why:
        pytest.skip(why)


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
@pytest.mark.parametrize('mode', ['light', 'dark'])
def test_the_themes_colours_keep_their_contrast(site, module_chromium, axe_installed, mode):
    page = module_chromium.new_context(color_scheme=mode).new_page()
    open_page(page, site.base + 'index.html')
    low = {pair: round(ratio, 2) for pair, ratio in theme_contrast(page).items()
           if ratio < accessibility.NORMAL_TEXT}
    page.context.close()
    assert low == {}


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_the_themes_own_hover_colour_is_caught(site, page, axe_installed):
    open_page(page, site.base + 'index.html')
    page.evaluate("document.querySelector('link[href*=\"course.css\"]').disabled = true")
    assert theme_contrast(page)[('link-hover', 'background')] < accessibility.NORMAL_TEXT


@pytest.mark.browser
@pytest.mark.timeout(BUILD_LIMIT_S)
def test_a_line_that_cannot_wrap_is_caught(site, page):
    long_line = 'x' * 400
    built = page.context.request.get(site.base + page_name('04-write-the-subscriber.ipynb')).text()
    planted = built.replace('<article class="bd-article">', '<article class="bd-article">'
                            f'<pre style="overflow: visible">{long_line}</pre>', 1)
    page.route('**/lessons/planted.html', lambda route: route.fulfill(
        status=200, content_type='text/html', body=planted))
    open_page(page, site.base + 'lessons/planted.html')
    assert [line.split(' ')[0] for line in accessibility.sticking_out(page)] == ['<pre']
