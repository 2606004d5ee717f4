"""Grades a learning platform imports: Canvas's and Moodle's gradebook CSV, and a plain CSV.

Runs on the instructor's host, after nbgrader scored the class (``make grade ... EXPORT=canvas``).
Each format is an nbgrader export plugin (:class:`nbgrader.plugins.ExportPlugin`: ``to``, and
``export(gradebook)``), given the roster and the learners' names by :mod:`.term`. A score is
nbgrader's, less the late penalty grading stored beside it (:mod:`.deadlines`). A roster (CSV,
:func:`read_roster`) maps the course's learner names (their folders) to the platform's ids: a
learner of the roster with nothing handed in gets 0 on every notebook, with a note; a learner who
handed in and is not in the roster is written to ``not-in-roster.csv`` beside the export, with their
scores, and named on the console.

The columns follow the platforms' documented imports (docs/instructors.md cites the pages):
Canvas matches a row by ``ID``, ``SIS User ID`` or ``SIS Login ID`` and reads one column per
assignment, with the points of each in a ``Points Possible`` row; Moodle maps a column of its
choice (``ID number``, ``Username`` or ``Email address``) to its users, and one column per
grade item.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from nbgrader.api import Gradebook, MissingEntry
from nbgrader.plugins import ExportPlugin
from traitlets import Dict, List, Unicode

from ..paths import ASSIGNMENT

#: The roster's columns: ``learner`` (the folder's name) and the platform's ids.
ROSTER_COLUMNS = ('learner', 'name', 'first_name', 'last_name', 'lms_id', 'sis_id', 'login',
                  'email', 'section')
#: Canvas's gradebook import: the learner's columns, then one per assignment.
CANVAS_COLUMNS = ('Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section')
#: Moodle's grade import (CSV): the user's columns, then one per grade item.
MOODLE_COLUMNS = ('First name', 'Last name', 'ID number', 'Username', 'Email address')
#: The roster ids each platform can match a row by.
MATCHED_BY = {'canvas': ('lms_id', 'sis_id', 'login'), 'moodle': ('sis_id', 'login', 'email'),
              'csv': ()}


class RosterProblem(Exception):
    """The roster cannot be used: ``lines`` holds one line per mistake."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__('\n'.join(lines))
        self.lines = lines


@dataclass
class Table:
    """The class's final scores, as an export writes them.

    :ivar scores: learner's name -> notebook -> score (after lateness).
    :ivar maxima: notebook -> its points.
    :ivar notes: learner's name -> what the export says of them.
    """

    notebooks: list[str]
    maxima: dict[str, float]
    scores: dict[str, dict[str, float]] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)


def read_roster(path: Path, lms: str) -> dict[str, dict[str, str]]:
    """The roster at ``path`` (CSV, a header row of :data:`ROSTER_COLUMNS`): learner -> row.

    :raises RosterProblem: one line per mistake: no ``learner`` column, a column the roster
        does not have, a learner twice, a row with none of the ids ``lms`` matches by.
    """
    try:
        with open(path, newline='', encoding='utf-8-sig') as stream:
            rows = list(csv.DictReader(stream))
            header = list(rows[0]) if rows else []
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise RosterProblem([f'{path}: cannot be read as CSV ({error}): write a CSV file with '
                             f'a header row of {", ".join(ROSTER_COLUMNS)}']) from None
    lines = []
    if 'learner' not in header:
        raise RosterProblem([f'{path}: no "learner" column: write a header row such as '
                             'learner,name,sis_id,login,email (learner: the folder\'s name)'])
    lines += [f'{path}: unknown column {c!r}: write one of {", ".join(ROSTER_COLUMNS)}'
              for c in header if c not in ROSTER_COLUMNS]
    roster: dict[str, dict[str, str]] = {}
    for number, row in enumerate(rows, start=2):
        name = (row.get('learner') or '').strip()
        if not name:
            lines.append(f'{path} line {number}: no learner: write the learner\'s folder name')
        elif name in roster:
            lines.append(f'{path} line {number}: {name} is in the roster twice: keep one row')
        elif MATCHED_BY[lms] and not any((row.get(k) or '').strip() for k in MATCHED_BY[lms]):
            lines.append(f'{path} line {number}: {name} has none of the ids {lms} matches by: '
                         f'write one of {", ".join(MATCHED_BY[lms])}')
        else:
            roster[name] = {k: (v or '').strip() for k, v in row.items() if k}
    if lines:
        raise RosterProblem(lines)
    return roster


def _name(row: dict[str, str], learner: str) -> tuple[str, str]:
    """A learner's first and last name from the roster (its ``name`` split at the last space
    when it has no first_name/last_name)."""
    first, last = row.get('first_name', ''), row.get('last_name', '')
    if not (first or last):
        first, _, last = (row.get('name') or learner).rpartition(' ')
        first, last = (first, last) if first else (last, '')
    return first, last


def write(lms: str, table: Table, roster: Optional[dict[str, dict[str, str]]],
          path: Path) -> list[str]:
    """Write ``table`` for ``lms`` (``canvas``, ``moodle``, ``csv``) to ``path``; the learners
    not in ``roster`` go to ``not-in-roster.csv`` beside it.  Return one line per learner
    who was handed in but is not in the roster, and per roster learner with nothing handed in."""
    roster = roster if roster is not None else {name: {'learner': name} for name in table.scores}
    lines = [f'{name}: handed in, not in the roster: written to {path.parent}/not-in-roster.csv'
             for name in table.scores if name not in roster]
    for name in roster:
        if name not in table.scores:
            table.notes[name] = 'in the roster, nothing handed in: 0 points'
            lines.append(f'{name}: {table.notes[name]}')
    score = {name: {n: table.scores.get(name, {}).get(n, 0.0) for n in table.notebooks}
             for name in roster}
    cells = [[f'{score[name][n]:g}' for n in table.notebooks] for name in roster]
    with open(path, 'w', newline='', encoding='utf-8') as stream:
        out = csv.writer(stream)
        if lms == 'canvas':
            out.writerow([*CANVAS_COLUMNS, *table.notebooks])
            out.writerow(['Points Possible', '', '', '', '',
                          *(f'{table.maxima[n]:g}' for n in table.notebooks)])
            for (name, row), got in zip(roster.items(), cells):
                first, last = _name(row, name)
                student = f'{last}, {first}' if last and first else (last or first)
                out.writerow([student, row.get('lms_id', ''), row.get('sis_id', ''),
                              row.get('login', ''), row.get('section', ''), *got])
        elif lms == 'moodle':
            out.writerow([*MOODLE_COLUMNS, *table.notebooks])
            for (name, row), got in zip(roster.items(), cells):
                out.writerow([*_name(row, name), row.get('sis_id', ''), row.get('login', ''),
                              row.get('email', ''), *got])
        else:
            out.writerow(['learner', *table.notebooks, 'total'])
            for name, got in zip(roster, cells):
                out.writerow([name, *got, f'{sum(score[name].values()):g}'])
    extra = [name for name in table.scores if name not in roster]
    if extra:
        with open(path.parent / 'not-in-roster.csv', 'w', newline='', encoding='utf-8') as stream:
            out = csv.writer(stream)
            out.writerow(['learner', *table.notebooks, 'total'])
            for name in extra:
                points = [table.scores[name].get(n, 0.0) for n in table.notebooks]
                out.writerow([name, *(f'{g:g}' for g in points), f'{sum(points):g}'])
    return lines


class CourseExport(ExportPlugin):
    """An nbgrader export plugin for one platform: nbgrader's scores less the late penalties,
    one column per notebook, for the roster's learners.

    :ivar names: nbgrader's student id -> the learner's name (their folder).
    """

    lms = Unicode('csv').tag(config=True)
    roster = Dict(allow_none=True, default_value=None).tag(config=True)
    names = Dict().tag(config=True)
    notebooks: List[str] = List().tag(config=True)
    said: List[str] = List()

    def export(self, gradebook: Gradebook) -> None:
        """Write the export to ``to`` (``said``: the lines about missing and extra learners)."""
        assignment = gradebook.find_assignment(ASSIGNMENT)
        maxima = {nb.name: nb.max_score for nb in assignment.notebooks}
        table = Table(list(self.notebooks) or sorted(maxima), maxima)
        for student_id, name in self.names.items():
            table.scores[name] = {n: _final(gradebook, n, student_id) for n in table.notebooks}
        self.said = write(self.lms, table, self.roster, Path(self.to))


def _final(gradebook: Gradebook, notebook: str, student_id: str) -> float:
    try:
        scored: Any = gradebook.find_submission_notebook(notebook, ASSIGNMENT, student_id)
    except MissingEntry:
        return 0.0
    return max(0.0, scored.score - (scored.late_submission_penalty or 0.0))


class CanvasExport(CourseExport):
    """Canvas's gradebook import (``EXPORT=canvas``)."""

    lms = Unicode('canvas').tag(config=True)


class MoodleExport(CourseExport):
    """Moodle's CSV grade import (``EXPORT=moodle``)."""

    lms = Unicode('moodle').tag(config=True)


#: ``EXPORT=``'s choices and their plugins.
EXPORTS = {'canvas': CanvasExport, 'moodle': MoodleExport, 'csv': CourseExport}
