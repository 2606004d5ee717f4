"""The roster: the course's learner names (their folders) mapped to a learning platform's ids.

Runs on the instructor's host (``ROSTER=roster.csv`` for an export, or to take in Canvas's
submissions zip).  A CSV with a header row of :data:`ROSTER_COLUMNS`; read strictly, each
mistake one line saying what to fix (:class:`RosterProblem`), all at once, and nothing is
graded or exported with any: a row whose number of fields differs from the header's (an
unquoted comma shifts every value after it), a learner twice, an id two learners share (the
platform would give one person two rows), a row with none of the ids the platform matches by.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from .mistakes import Mistakes

#: The roster's columns: ``learner`` (the folder's name) and the platform's ids.
ROSTER_COLUMNS = ('learner', 'name', 'first_name', 'last_name', 'lms_id', 'sis_id', 'login',
                  'email', 'section')
#: The platforms an export is written for (:mod:`ros2nb_instructor.grading.export.lms`), each
#: with the roster ids it can match a row by.
MATCHED_BY = {'canvas': ('lms_id', 'sis_id', 'login'), 'moodle': ('sis_id', 'login', 'email'),
              'csv': ()}
PLATFORMS = tuple(MATCHED_BY)
#: Ids that name one person: two learners may not share one.
UNIQUE = ('lms_id', 'sis_id', 'login', 'email')


class RosterProblem(Mistakes):
    """The roster cannot be used: ``lines`` holds one line per mistake."""


@dataclass(frozen=True)
class RosterRow:
    """One learner of the roster; an id the roster leaves out is ''."""

    learner: str
    name: str = ''
    first_name: str = ''
    last_name: str = ''
    lms_id: str = ''
    sis_id: str = ''
    login: str = ''
    email: str = ''
    section: str = ''

    def names(self) -> tuple[str, str]:
        """First and last name: ``first_name`` and ``last_name``, else ``name`` (``Last,
        First`` split at its comma, ``First Last`` at its last space), else the learner's
        folder name."""
        if self.first_name or self.last_name:
            return self.first_name, self.last_name
        name = self.name or self.learner
        if ',' in name:
            last, _, first = name.partition(',')
            return first.strip(), last.strip()
        first, _, last = name.rpartition(' ')
        return (first, last) if first else (last, '')


#: learner (folder name) -> their row.
Roster = Mapping[str, RosterRow]


def read_roster(path: Path, lms: str) -> dict[str, RosterRow]:
    """The roster at ``path`` (CSV with a header row of :data:`ROSTER_COLUMNS`): learner ->
    row, in the file's order.

    :param lms: ``canvas``, ``moodle`` or ``csv``: which ids a row needs (:data:`MATCHED_BY`).
    :raises RosterProblem: one line per mistake: no ``learner`` column, a column the roster
        does not have, a row with too many or too few fields, a learner twice, an id two
        learners share, a row with none of the ids ``lms`` matches by.
    """
    try:
        with open(path, newline='', encoding='utf-8-sig') as stream:
            reader = csv.reader(stream, strict=True)
            header = next(reader, [])
            records = [(reader.line_num, fields) for fields in reader if fields]
    except (OSError, UnicodeDecodeError, csv.Error) as error:
        raise RosterProblem([f'{path}: cannot be read as CSV ({error}): write a UTF-8 CSV '
                             f'file with a header row of {", ".join(ROSTER_COLUMNS)}']) from None
    header = [column.strip() for column in header]
    if 'learner' not in header:
        raise RosterProblem([f'{path}: no "learner" column: write a header row such as '
                             'learner,name,sis_id,login,email (learner: the folder\'s name)'])
    lines = [f'{path}: unknown column {c!r}: write one of {", ".join(ROSTER_COLUMNS)}'
             for c in header if c not in ROSTER_COLUMNS]
    roster: dict[str, RosterRow] = {}
    taken: dict[tuple[str, str], str] = {}
    for number, fields in records:
        if len(fields) != len(header):
            lines.append(f'{path} line {number}: {len(fields)} fields where the header has '
                         f'{len(header)}: put a value that holds a comma in double quotes '
                         '("Lovelace, Ada"), and leave an empty field for an id you lack')
            continue
        row = RosterRow(**{k: v.strip() for k, v in zip(header, fields) if k in ROSTER_COLUMNS})
        lines += _row_mistakes(path, number, row, lms, roster, taken)
        if row.learner and row.learner not in roster:
            roster[row.learner] = row
    if lines:
        raise RosterProblem(lines)
    return roster


def _row_mistakes(path: Path, number: int, row: RosterRow, lms: str,
                  roster: Mapping[str, RosterRow], taken: dict[tuple[str, str], str]
                  ) -> list[str]:
    """What is wrong with one row (nothing: [])."""
    where = f'{path} line {number}'
    if not row.learner:
        return [f'{where}: no learner: write the learner\'s folder name']
    if row.learner in roster:
        return [f'{where}: {row.learner} is in the roster twice: keep one row']
    lines = []
    for key in UNIQUE:
        value = getattr(row, key)
        if value and (key, value.casefold()) in taken:
            lines.append(f'{where}: {key} {value} is also {taken[key, value.casefold()]}\'s: '
                         'each learner needs ids of their own (the platform would give one '
                         'person two rows)')
        elif value:
            taken[key, value.casefold()] = row.learner
    if MATCHED_BY[lms] and not any(getattr(row, k) for k in MATCHED_BY[lms]):
        lines.append(f'{where}: {row.learner} has none of the ids {lms} matches by: write '
                     f'one of {", ".join(MATCHED_BY[lms])}')
    return lines
