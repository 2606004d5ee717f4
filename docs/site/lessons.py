"""The lesson pages: each notebook of ``solutions/`` as the learner sees it, ready for MyST-NB.

``solutions/`` holds the stored outputs (the plots, the ROS graph pictures, the live plot's
snapshot) that nbval checks, so the pages are made from there; ``notebooks/`` holds what
nbgrader gives the learner.  Every answer cell (cell metadata ``nbgrader.solution``) becomes
an exercise block: the hint that precedes it in the notebook and the learner's version of
the cell (the same cell id in ``notebooks/``, with its placeholder), and no outputs.
nbgrader's hidden-test cells are dropped, the checks' stored verdicts too (they passed on
the solution, not on the learner's cell), and so is any other stored output that shows a
line of the lesson's solutions (a cell that prints the finished file).  With
``solutions=True`` (the instructor's site) each exercise block is followed by its solution,
run, with its outputs.  Every picture gets its text alternative from the caption line the
notebook prints with it (:func:`describe_figures`).

Nothing here executes a notebook or writes outside the folder it is given.
"""

from __future__ import annotations

import copy
import json
import re
from pathlib import Path
from typing import Iterable, Optional

SOLUTION_REGION = re.compile(r'### BEGIN SOLUTION\n(.*?)### END SOLUTION', re.S)
HIDDEN_TESTS = '### BEGIN HIDDEN TESTS'
#: A solution line shorter than this (``else:``, ``pass``) says nothing about the answer.
DISTINCTIVE_CHARS = 8
#: ipympl's live figure: its view needs the widget's JavaScript, which would load from the
#: network; the same output's text/html holds the snapshot the notebook stored.
WIDGET_VIEW = 'application/vnd.jupyter.widget-view+json'
HIDDEN_OUTPUT_NOTE = ('*This cell shows your finished work once you have written the parts '
                      'above: run it in the notebook.*')
#: The outputs that are pictures.
IMAGES = ('image/png', 'image/jpeg', 'image/gif', 'image/svg+xml')
#: How the line that says what a figure shows begins (``ros2nb.nbmeta.CAPTION_START``).
CAPTION_START = 'Figure: '


def source(cell: dict) -> str:
    """A cell's source as one string (nbformat stores it as a string or a list of lines)."""
    text = cell.get('source', '')
    return text if isinstance(text, str) else ''.join(text)


def is_answer(cell: dict) -> bool:
    """Whether nbgrader made this cell an answer the learner writes."""
    return bool(cell.get('metadata', {}).get('nbgrader', {}).get('solution'))


def is_graded_check(cell: dict) -> bool:
    """Whether this cell is one of nbgrader's graded cells that check an answer."""
    grading = cell.get('metadata', {}).get('nbgrader', {})
    return bool(grading.get('grade')) and not grading.get('solution')


def plain(text: str) -> str:
    """``text`` as a page shows it, near enough: Markdown's backticks gone, each run of white
    space one space (a line break in a notebook's Markdown is a space on the page)."""
    return ' '.join(text.replace('`', '').split())


def solution_lines(solution_nb: dict, learner_nb: dict) -> set[str]:
    """The lines of a lesson's solutions that its learner notebook does not show anywhere,
    each :func:`plain` and at least :data:`DISTINCTIVE_CHARS` long."""
    given = plain('\n'.join(source(cell) for cell in learner_nb['cells']))
    lines = set()
    for cell in solution_nb['cells']:
        for region in SOLUTION_REGION.findall(source(cell)):
            lines.update(plain(line) for line in region.splitlines())
    return {line for line in lines if len(line) >= DISTINCTIVE_CHARS and line not in given}


def _output_text(output: dict) -> str:
    text = output.get('text', '')
    parts = [text if isinstance(text, str) else ''.join(text)]
    for mime, value in output.get('data', {}).items():
        if mime.startswith('text/'):
            parts.append(value if isinstance(value, str) else ''.join(value))
    if 'traceback' in output:
        parts.extend(output['traceback'])
    return '\n'.join(parts)


def _reveals(cell: dict, lines: set[str]) -> bool:
    """Whether an output of ``cell`` shows one of ``lines``."""
    texts = [plain(_output_text(output)) for output in cell.get('outputs', [])]
    return any(line in text for text in texts for line in lines)


def _split_at_last_heading(markdown: str) -> tuple[str, str]:
    """``markdown`` up to and including its last heading, and the text after it (the hint).
    Lines inside code fences are never headings."""
    lines = markdown.splitlines()
    fence, last = None, -1
    for number, line in enumerate(lines):
        stripped = line.lstrip()
        if fence is None and stripped.startswith(('```', '~~~')):
            fence = stripped[:3]
        elif fence is not None and stripped.startswith(fence):
            fence = None
        elif fence is None and re.match(r'#{1,6} ', line):
            last = number
    return '\n'.join(lines[:last + 1]), '\n'.join(lines[last + 1:]).strip()


def figure_caption(cell: dict) -> Optional[str]:
    """The words of the first line of ``cell``'s outputs that starts with
    :data:`CAPTION_START` (without it), or None."""
    for output in cell.get('outputs', []):
        for line in _output_text(output).splitlines():
            if line.startswith(CAPTION_START):
                return line[len(CAPTION_START):].strip()
    return None


def describe_figures(cell: dict, notebook: str) -> None:
    """Give each picture among ``cell``'s outputs its text alternative: the cell's caption
    line (:func:`figure_caption`) becomes the ``alt`` of its images (MyST-NB's cell option
    ``mystnb.image.alt``).  A live figure's stored snapshot is shown as its picture, not as
    the widget's HTML, whose ``<img>`` has no ``alt`` (and a malformed ``width``).

    :raises ValueError: when the cell shows a picture and no caption line: every figure says
        in words what it shows (``ros2nb.figures``).
    """
    pictures = [output for output in cell.get('outputs', [])
                if any(mime in output.get('data', {}) for mime in IMAGES)]
    if not pictures:
        return
    for output in pictures:
        if 'image/png' in output['data']:
            output['data'].pop('text/html', None)
    caption = figure_caption(cell)
    if not caption:
        raise ValueError(f'{notebook}: cell {cell.get("id")} shows a figure but no line '
                         f'"{CAPTION_START}..." that says what it shows (ros2nb.figures)')
    cell.setdefault('metadata', {}).setdefault('mystnb', {})['image'] = {'alt': caption}


def _markdown_cell(text: str, cell_id: str) -> dict:
    return {'cell_type': 'markdown', 'id': cell_id, 'metadata': {}, 'source': text}


def _exercise(label: str, hint: str, placeholder: str, language: str) -> str:
    body = [hint, ''] if hint else []
    body += ['The cell you complete in the notebook:', '', f'```{language}', placeholder.rstrip(),
             '```']
    return '\n'.join(['::::{exercise}', f':label: {label}', ':nonumber:', '', *body, '::::'])


def launch_directive(notebook: str) -> str:
    """The MyST that asks ``launch.py`` for the box saying how to open ``notebook``."""
    return f'```{{launch}} {notebook}\n```'


def learner_page(solution_nb: dict, learner_nb: dict, notebook: str, *,
                 solutions: bool = False) -> dict:
    """The page of one lesson, as a notebook for MyST-NB (see the module's docstring).

    :param solution_nb: the lesson's notebook from ``solutions/``, with its outputs.
    :param learner_nb: the same lesson from ``notebooks/`` (nbgrader's learner version).
    :param notebook: the lesson's file name (``04-write-the-subscriber.ipynb``), for the
        launch box.
    :param solutions: show each solution, run, after its exercise block (the instructor's
        site) instead of hiding it.
    :raises ValueError: when an answer cell has no learner version with its id in
        ``learner_nb`` (``make learner-notebooks`` regenerates them), or a figure has no
        caption line (:func:`describe_figures`).
    """
    page = copy.deepcopy(solution_nb)
    page['metadata'].pop('widgets', None)
    learner_cells = {cell.get('id'): cell for cell in learner_nb['cells']}
    revealing = set() if solutions else solution_lines(solution_nb, learner_nb)
    cells: list[dict] = []
    for cell in page['cells']:
        for output in cell.get('outputs', []):
            output.get('data', {}).pop(WIDGET_VIEW, None)
        if HIDDEN_TESTS in source(cell):
            continue
        if is_answer(cell):
            learner = learner_cells.get(cell.get('id'))
            if learner is None:
                raise ValueError(f'{notebook}: answer cell {cell.get("id")} has no learner '
                                 'version in notebooks/ (make learner-notebooks)')
            cells.extend(_exercise_cells(cell, learner, cells, notebook, solutions))
            continue
        if not solutions and is_graded_check(cell):
            cell['outputs'] = []
        elif revealing and _reveals(cell, revealing):
            cell['outputs'] = []
            cells.append(cell)
            cell = _markdown_cell(HIDDEN_OUTPUT_NOTE, f'{cell.get("id")}-hidden-output')
        cells.append(cell)
    for cell in cells:
        describe_figures(cell, notebook)
    _add_launch(cells, notebook)
    page['cells'] = cells
    return page


def _exercise_cells(answer: dict, learner: dict, before: list[dict], notebook: str,
                    solutions: bool) -> list[dict]:
    """The exercise block for ``answer`` (taking the hint out of the markdown cell just
    before it, which ``before`` ends with), and in the instructor's site the solution."""
    label = f'ex-{notebook[:2]}-{answer.get("id")}'
    hint = ''
    if before and before[-1]['cell_type'] == 'markdown':
        kept, hint = _split_at_last_heading(source(before[-1]))
        if kept:
            before[-1] = {**before[-1], 'source': kept}
        else:
            before.pop()
    language = 'markdown' if answer['cell_type'] == 'markdown' else 'ipython3'
    block = [_markdown_cell(_exercise(label, hint, source(learner), language),
                            f'{label}-exercise')]
    if solutions:
        block += [_markdown_cell(f'```{{solution-start}} {label}\n```', f'{label}-solution'),
                  answer, _markdown_cell('```{solution-end}\n```', f'{label}-solution-end')]
    return block


def _add_launch(cells: list[dict], notebook: str) -> None:
    """The launch box right under the lesson's title (its first heading)."""
    for number, cell in enumerate(cells):
        if cell['cell_type'] == 'markdown':
            title, _, rest = source(cell).partition('\n')
            cells[number] = {**cell, 'source': f'{title}\n\n{launch_directive(notebook)}\n{rest}'}
            return


def prepare(course: Path, into: Path, *, solutions: bool = False,
            only: Optional[Iterable[str]] = None) -> list[Path]:
    """Write the lesson pages of ``course`` (its ``solutions/`` and ``notebooks/``) into the
    folder ``into`` (a page whose text is unchanged keeps its file), and remove the pages
    of lessons it no longer has.

    :param only: the lessons' numbers to prepare (``['04']``); None for all of them.
    :return: the pages written or kept, in the course's order.
    """
    into.mkdir(parents=True, exist_ok=True)
    wanted = set(only) if only is not None else None
    pages = []
    for solution in sorted((course / 'solutions').glob('[0-9][0-9]-*.ipynb')):
        if wanted is not None and solution.name[:2] not in wanted:
            continue
        learner = course / 'notebooks' / solution.name
        page = learner_page(json.loads(solution.read_text()), json.loads(learner.read_text()),
                            solution.name, solutions=solutions)
        text = json.dumps(page, indent=1, ensure_ascii=False) + '\n'
        target = into / solution.name
        if not target.exists() or target.read_text() != text:
            target.write_text(text)
        pages.append(target)
    for stale in set(into.glob('*.ipynb')) - set(pages):
        stale.unlink()
    return pages
