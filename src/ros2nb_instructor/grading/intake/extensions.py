"""Extensions: a learner's own, later due date for a notebook (``extensions.toml``).

Runs on the instructor's host (grading, ``make export``) and on the classroom server (the
hand-in service tells each learner their own due dates, and nobody else's).  The file sits
beside ``course.toml`` (``EXTENSIONS=`` names another); one table per learner (their folder
name, the hub's user name), one key per notebook (its name or its number), and as value
either the learner's due date (a date and time, read as ``course.toml``'s are:
:mod:`.due_dates`, in the notebook's ``time_zone`` when it has none) or how much later than
the class's it is (``{ days = 3 }``, ``{ hours = 12 }``):

.. code-block:: toml

    [ada]
    03-write-the-publisher = 2026-10-08T23:59:00+02:00
    "05" = { days = 2 }

An extension replaces the class's due date for that learner and notebook only; the late
policy is the notebook's.  It reaches a grade when that learner is graded again
(``make grade LEARNER=ada``) or the grades are exported (``make export``).  Each mistake is
one line (:class:`ExtensionsProblem`): a notebook the course does not have or that has no
due date, a date before the class's, a learner no submission or roster names.  Keep the
file readable by you alone: on the hub the course folder is open to every learner.
"""

from __future__ import annotations

import datetime
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable, Mapping, Optional

from ...paths import EXTENSIONS
from . import due_dates
from .course_settings import read_toml
from .deadlines import CourseSettings
from .mistakes import Mistakes

__all__ = ['EXTENSIONS', 'Extensions', 'ExtensionsProblem', 'NONE', 'read_extensions']
#: The units a relative extension may be given in.
UNITS = ('days', 'hours')


class ExtensionsProblem(Mistakes):
    """The extensions file cannot be used: ``lines`` holds one line per mistake."""


@dataclass(frozen=True)
class Extensions:
    """Each learner's own due dates.

    :ivar due: (learner, notebook) -> the learner's due date of that notebook (aware).
    """

    due: Mapping[tuple[str, str], datetime.datetime] = field(default_factory=dict)

    def of(self, learner: str, notebook: str) -> Optional[datetime.datetime]:
        """``learner``'s own due date of ``notebook``, or None (the class's applies)."""
        return self.due.get((learner, notebook))


#: No extensions file: every learner has the class's due dates.
NONE = Extensions()


def read_extensions(path: Path, settings: CourseSettings, notebooks: list[str],
                    learners: Optional[Iterable[str]] = None) -> Extensions:
    """The extensions file at ``path``, checked against the class's due dates; :data:`NONE`
    when there is no file.

    :param learners: the names a learner may have (folders, the roster); None: any name.
    :raises ExtensionsProblem: one line per mistake, each saying what to write instead.
    """
    if not path.is_file():
        return NONE
    data = read_toml(path, ExtensionsProblem)
    known = None if learners is None else set(learners)
    lines: list[str] = []
    due = {}
    for learner, table in data.items():
        where = f'{path} [{learner}]'
        if known is not None and learner not in known:
            lines.append(f'{where}: no learner {learner!r} in the submissions or the roster: '
                         'write the learner\'s folder name (the hub\'s user name)')
            continue
        if not isinstance(table, dict):
            lines.append(f'{where}: write a table of notebooks, such as '
                         f'{notebooks[-1]} = {due_dates.EXAMPLE_DUE}')
            continue
        for key, value in table.items():
            notebook = _notebook(key, notebooks, where, lines)
            if notebook is not None:
                when = _extended(value, notebook, settings, f'{where} {key}', lines)
                if when is not None:
                    due[learner, notebook] = when
    if lines:
        raise ExtensionsProblem(lines)
    return Extensions(due)


def _notebook(key: str, notebooks: list[str], where: str, lines: list[str]) -> Optional[str]:
    """The course notebook ``key`` names (its name, or its number ``"03"``)."""
    found = [n for n in notebooks if key in (n, n[:2])]
    if len(found) == 1:
        return found[0]
    lines.append(f'{where}: {key!r} is no notebook of the course: write its name or number, '
                 f'such as {notebooks[-1]!r} or "{notebooks[-1][:2]}"')
    return None


def _extended(value: Any, notebook: str, settings: CourseSettings, where: str,
              lines: list[str]) -> Optional[datetime.datetime]:
    """The learner's due date of ``notebook`` an extension's ``value`` gives."""
    class_due = settings.due.get(notebook)
    if class_due is None:
        lines.append(f'{where}: {notebook} has no due date in course.toml: an extension '
                     'moves a due date, so give the notebook one first')
        return None
    if isinstance(value, dict):
        wrong = [k for k, v in value.items() if k not in UNITS or isinstance(v, bool)
                 or not isinstance(v, (int, float)) or v <= 0]
        if wrong or not value:
            lines.append(f'{where}: write {{ days = 3 }} or {{ hours = 12 }} (more time than '
                         'the class has), or the learner\'s due date')
            return None
        return class_due + datetime.timedelta(days=value.get('days', 0),
                                              hours=value.get('hours', 0))
    when = due_dates.due_date(value, settings.zones.get(notebook), where, lines, key='due')
    if when is not None and when < class_due:
        lines.append(f'{where}: {when.isoformat()} is before the class\'s due date '
                     f'({class_due.isoformat()}): an extension gives more time, not less')
        return None
    return when
