"""The answer cells of ``solutions/`` and the checks that grade them, for the mutation tests.

:func:`answers` reads every cell the learner writes (nbgrader ``solution: true``: the 22
``-answer`` cells of notebooks 03-10 and the Challenges of 00-02), each with the graded cell
that checks it, the lines the learner writes (between nbgrader's markers) and the cells a
kernel runs before it (:func:`setup_cells`).  Nothing here runs anything.
"""

from __future__ import annotations

import ast
import json
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parent.parent
SOLUTIONS = ROOT / 'solutions'
MARKERS = ('### BEGIN SOLUTION', '### END SOLUTION')


def _text(cell: dict) -> str:
    source = cell['source']
    return ''.join(source) if isinstance(source, list) else source


def _meta(cell: dict) -> dict:
    return cell.get('metadata', {}).get('nbgrader', {})


def _tags(cell: dict) -> list[str]:
    return cell.get('metadata', {}).get('tags', [])


@dataclass(frozen=True)
class Answer:
    """One answer cell of a solution notebook.

    :ivar notebook: its number, e.g. ``'03'``.
    :ivar index: the cell's index in the notebook.
    :ivar grade_id: nbgrader's id, e.g. ``'03-sensor-constructor-answer'``.
    :ivar source: the cell as the learner writes it (nbgrader's markers left out).
    :ivar regions: the lines the learner writes (0-based, of ``source``): each the first and
        one-past-last line of what stood between a pair of markers.
    :ivar check_index: the graded cell that checks it (the next graded cell).
    :ivar check_id: its grade id.
    :ivar check_source: its text (``ros2nb.checks.NAME(...)``).
    """

    notebook: str
    index: int
    grade_id: str
    source: str
    regions: tuple[tuple[int, int], ...]
    check_index: int
    check_id: str
    check_source: str

    @property
    def key(self) -> str:
        """A short name, e.g. ``03-sensor-constructor``."""
        return self.grade_id.removesuffix('-answer')

    def written(self, line: int) -> bool:
        """Whether ``line`` (0-based, of ``source``) is one the learner writes."""
        return any(begin <= line < end for begin, end in self.regions)

    @property
    def is_part(self) -> bool:
        """A ``%%part`` cell (its text goes into a file of the workspace)."""
        return self.source.startswith('%%part')

    @property
    def is_ini(self) -> bool:
        """05's setup.cfg: an INI file, not Python."""
        return self.is_part and 'SETUP_CFG' in self.source.splitlines()[0]

    @property
    def check_name(self) -> str:
        """The ``ros2nb.checks`` function its graded cell calls."""
        call = ast.parse(self.check_source).body[0].value
        return call.func.attr

    @property
    def judged(self) -> bool:
        """Whether the check runs in a judge (its call takes no argument: the learner's
        files are read there), rather than on the learner's objects in the kernel."""
        call = ast.parse(self.check_source).body[0].value
        return not call.args and not call.keywords


def _strip_markers(text: str) -> tuple[str, tuple[tuple[int, int], ...]]:
    kept: list[str] = []
    regions, begin = [], 0
    for line in text.split('\n'):
        if line.strip() == MARKERS[0]:
            begin = len(kept)
        elif line.strip() == MARKERS[1]:
            regions.append((begin, len(kept)))
        else:
            kept.append(line)
    return '\n'.join(kept), tuple(regions)


@lru_cache(maxsize=None)
def notebook(number: str) -> dict:
    """The solution notebook ``number`` as JSON."""
    path = next(SOLUTIONS.glob(f'{number}-*.ipynb'))
    return json.loads(path.read_text())


def notebook_path(number: str) -> Path:
    return next(SOLUTIONS.glob(f'{number}-*.ipynb'))


def answers(number: Optional[str] = None) -> list[Answer]:
    """Every answer cell (of notebook ``number``, or of all), in notebook order."""
    numbers = [number] if number else sorted(p.name[:2] for p in SOLUTIONS.glob('*.ipynb'))
    found = []
    for nb_number in numbers:
        cells = notebook(nb_number)['cells']
        for index, cell in enumerate(cells):
            if not _meta(cell).get('solution') or cell['cell_type'] != 'code':
                continue
            check_index = next(i for i in range(index + 1, len(cells))
                               if _meta(cells[i]).get('grade'))
            source, regions = _strip_markers(_text(cell))
            found.append(Answer(nb_number, index, _meta(cell)['grade_id'], source, regions,
                                check_index, _meta(cells[check_index])['grade_id'],
                                _text(cells[check_index]).strip()))
    return found


def _cheap(source: str) -> bool:
    """Cells of imports and names only (``FAN = ros2nb.course.FAN_FILE``): set-up, no demo."""
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return False
    for statement in tree.body:
        if isinstance(statement, (ast.Import, ast.ImportFrom)):
            continue
        if isinstance(statement, ast.Assign) and isinstance(
                statement.value, (ast.Attribute, ast.Constant, ast.Name)):
            continue
        return False
    return True


def setup_cells(number: str) -> dict[int, str]:
    """The cells a kernel runs before the answers, by index: every code cell before the first
    answer, and after it the given ``%%part`` cells, the grading context and cells that only
    import or name things (the notebook's demos and checks are left out)."""
    cells = notebook(number)['cells']
    first = min(a.index for a in answers(number))
    chosen = {}
    for index, cell in enumerate(cells):
        if cell['cell_type'] != 'code' or _meta(cell).get('solution') or _meta(cell).get('grade'):
            continue
        text = _strip_markers(_text(cell))[0]
        if (index < first or text.startswith('%%part') or 'grading-context' in _tags(cell)
                or _cheap(text)):
            chosen[index] = text
    return chosen


def given_cells(number: str) -> dict[int, str]:
    """The notebook's ``%%part`` cells the course gives (no answer), by index."""
    return {i: t for i, t in setup_cells(number).items() if t.startswith('%%part')}


def context_sources(number: str) -> list[str]:
    """The course's grading-context cells of notebook ``number`` (what a graded answer of a
    function or class runs after)."""
    return [_text(c) for c in notebook(number)['cells'] if 'grading-context' in _tags(c)]


def bound_names(source: str) -> set[str]:
    """The names a cell binds at its top level: imports, functions, classes, assignments."""
    if source.startswith('%%'):
        return set()
    try:
        tree = ast.parse('\n'.join('' if line.lstrip().startswith(('%', '!')) else line
                                   for line in source.split('\n')))
    except SyntaxError:
        return set()
    names: set[str] = set()
    for statement in tree.body:
        if isinstance(statement, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
            names.add(statement.name)
        elif isinstance(statement, (ast.Import, ast.ImportFrom)):
            names.update((a.asname or a.name).split('.')[0] for a in statement.names)
        elif isinstance(statement, ast.Assign):
            names.update(n.id for t in statement.targets for n in ast.walk(t)
                         if isinstance(n, ast.Name))
    return names


def own_names(answer: Answer) -> set[str]:
    """The names only ``answer`` binds, of those the kernel has when it runs: what a mutant
    run after the answer itself would otherwise still find there."""
    if answer.is_part:
        return set()
    before = set().union(*(bound_names(text) for index, text in setup_cells(answer.notebook)
                           .items() if index < answer.index))
    return bound_names(answer.source) - before

