"""Grades a learning platform imports: Canvas's and Moodle's gradebook CSV, and a plain CSV.

Runs on the instructor's host (``make export``, or ``make grade ... EXPORT=canvas``).  This
module only lays out a :class:`Table` of marks (made by :mod:`.exporting` from nbgrader's
gradebook) in each platform's import format; every cell goes through
:func:`.spreadsheets.safe_cell`.  A blank cell is "no mark yet" on both platforms, never 0.

The layouts follow each importer's own source:

- **Canvas** (canvas-lms, ``lib/gradebook_importer.rb``): a header row that starts
  ``Student``, ``ID``, then ``SIS User ID``, ``SIS Login ID`` and ends its learner columns
  with ``Section``; then one column per assignment (a new one is made for an unknown
  title); a row whose first cell is ``Points Possible`` sets each new assignment's points; a
  learner is found by ``ID``, else by SIS User ID or SIS Login ID, else by name; a blank or
  ``-`` cell is no score.
- **Moodle** (``grade/import/csv/classes/load_data.php``; docs.moodle.org, "Grade import"):
  any columns, each mapped at import: a user column (``ID number`` to ``useridnumber``,
  ``Email address`` to ``useremail``, ``Username`` to ``username``), each notebook's column
  to a grade item and its ``Feedback for ...`` column to that item's feedback; a blank or
  ``-`` grade is no grade.  A CSV cannot carry a grade item's maximum: a column mapped to
  "new grade item" gets Moodle's default maximum of 100, so map each notebook's column to a
  grade item you made with that notebook's points (:func:`moodle_items` says them).
- **csv**: ``learner``, one column per notebook, ``total``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping, Optional, Sequence

from ..intake.roster import Roster, RosterRow
from .spreadsheets import Cell, write_csv

#: Canvas's gradebook import: the learner's columns, then one per assignment.
CANVAS_COLUMNS = ('Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section')
#: Moodle's grade import (CSV): the user's columns, then each notebook and its feedback.
MOODLE_COLUMNS = ('First name', 'Last name', 'ID number', 'Username', 'Email address')
#: Moodle's own name of an item's feedback column in its CSV export.
MOODLE_FEEDBACK = 'Feedback for {}'
#: What the file of the learners who are not in the roster is called, beside the export.
NOT_IN_ROSTER = 'not-in-roster.csv'


@dataclass(frozen=True)
class Mark:
    """One learner's mark of one notebook, as an export writes it.

    :ivar score: the points it counts (after lateness); None: blank, no mark yet (not
        handed in and not yet due for this learner).
    :ivar feedback: one line for a platform's feedback column.
    """

    score: Optional[float]
    feedback: str = ''


@dataclass(frozen=True)
class Table:
    """The marks an export writes, built once.

    :ivar notebooks: the notebooks exported (each a column), in course order.
    :ivar maxima: notebook -> its points.
    :ivar marks: learner -> notebook -> their mark, for every learner graded or on the roster.
    """

    notebooks: tuple[str, ...]
    maxima: Mapping[str, float]
    marks: Mapping[str, Mapping[str, Mark]] = field(default_factory=dict)

    def cells(self, learner: str) -> list[Cell]:
        """The learner's score cells, blank where they have no mark."""
        marks = self.marks.get(learner, {})
        return [_cell(marks.get(n, Mark(None))) for n in self.notebooks]

    def total(self, learner: str) -> float:
        """The learner's points in the exported notebooks."""
        return sum(m.score or 0.0 for m in self.marks.get(learner, {}).values())


def _cell(mark: Mark) -> Cell:
    return '' if mark.score is None else mark.score


def write(lms: str, table: Table, roster: Optional[Roster], path: Path) -> list[str]:
    """Write ``table`` for ``lms`` (:data:`.roster.PLATFORMS`) to ``path``, a row per roster learner
    (every learner of ``table`` without a roster); the learners not in ``roster`` go to
    :data:`NOT_IN_ROSTER` beside it, and with none that file is removed.

    :return: one line per learner who has marks and is not in the roster.
    """
    rows = roster if roster is not None else {name: RosterRow(name) for name in table.marks}
    header, body = _layout(lms, table, rows)
    write_csv(path, header, body)
    extra = [name for name in table.marks if name not in rows]
    apart = path.parent / NOT_IN_ROSTER
    if extra:
        write_csv(apart, ['learner', *table.notebooks, 'total'],
                  [[name, *table.cells(name), table.total(name)] for name in extra])
    else:  # an earlier export's would still name learners the roster now has
        apart.unlink(missing_ok=True)
    return [f'{name}: graded, not in the roster: written to {apart}' for name in extra]


def _layout(lms: str, table: Table, rows: Roster
            ) -> tuple[list[str], list[Sequence[Cell]]]:
    """The header and rows of ``lms``'s file."""
    if lms == 'canvas':
        points: list[Cell] = ['Points Possible', '', '', '', '',
                              *(table.maxima[n] for n in table.notebooks)]
        body: list[Sequence[Cell]] = [points]
        for name, row in rows.items():
            first, last = row.names()
            student = f'{last}, {first}' if last and first else (last or first)
            body.append([student, row.lms_id, row.sis_id, row.login, row.section,
                         *table.cells(name)])
        return [*CANVAS_COLUMNS, *table.notebooks], body
    if lms == 'moodle':
        header = [*MOODLE_COLUMNS]
        for notebook in table.notebooks:
            header += [notebook, MOODLE_FEEDBACK.format(notebook)]
        body = []
        for name, row in rows.items():
            marks = table.marks.get(name, {})
            cells: list[Cell] = [*row.names(), row.sis_id, row.login, row.email]
            for notebook in table.notebooks:
                mark = marks.get(notebook, Mark(None))
                cells += [_cell(mark), mark.feedback]
            body.append(cells)
        return header, body
    return (['learner', *table.notebooks, 'total'],
            [[name, *table.cells(name), table.total(name)] for name in rows])


def moodle_items(table: Table) -> str:
    """The grade items Moodle needs before the import, in one line: each notebook's column
    and the maximum grade its item must have (a CSV cannot say it)."""
    items = ', '.join(f'{n} {table.maxima[n]:g}' for n in table.notebooks)
    return ('Moodle: map each notebook\'s column to a grade item whose maximum grade is its '
            f'points ({items}); a new grade item would get Moodle\'s maximum of 100')
