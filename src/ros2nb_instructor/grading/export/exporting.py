"""``make export``: a learning platform's grade file from an existing grading, nothing graded again.

Runs on the instructor's host, after ``make grade``.  The marks come from nbgrader's
gradebook in ``grading/nbgrader/`` as it is now (the formgrader's manual points included),
the hand-in times from what grading kept of each learner (``grading/learners.json``), and
lateness from ``course.toml`` and ``extensions.toml`` as they are now (:mod:`.deadlines`,
the one place that decides it).  ``DUE_BY=`` chooses the notebooks: those the class has due by
then.  A notebook a learner has not handed in is 0 once it is due for them and blank until
then (an extension moves that), and blank if it has no due date; a blank is "no mark yet" on
every platform, so an import in mid-term lowers nobody's grade.  The layout of each
platform's file is :mod:`.lms`'s.

The same export is an nbgrader export plugin (:class:`CanvasExport`, :class:`MoodleExport`,
:class:`CourseExport`: nbgrader's ``ExportPlugin``, ``export(gradebook)``), so
``cd grading/nbgrader && nbgrader export
--exporter=ros2nb_instructor.grading.export.exporting.CanvasExport
--CanvasExport.roster=../../roster.csv`` writes the same file.
"""

from __future__ import annotations

import argparse
import datetime
import sys
from pathlib import Path
from typing import Any, Optional

from nbgrader.api import Gradebook, MissingEntry
from nbgrader.plugins import ExportPlugin
from traitlets import List, Unicode

from ...paths import ASSIGNMENT, ROOT, SETTINGS, gradebook_url
from ..intake.course_settings import read_settings
from ..intake.deadlines import CourseSettings, SettingsProblem, assess
from ..intake.extensions import EXTENSIONS, Extensions, ExtensionsProblem, read_extensions
from ..intake.hand_in_times import TimeProblem, parse_time
from ..intake.roster import PLATFORMS, Roster, RosterProblem, read_roster
from ..intake.submissions import Learner
from ..intake.term import load_state
from .lms import Mark, Table, moodle_items, write

#: An example of DUE_BY=, for the line of a mistake.
EXAMPLE_DUE_BY = '2026-10-20T00:00:00+02:00'


def notebooks_due_by(settings: CourseSettings, notebooks: list[str],
                     due_by: Optional[datetime.datetime]) -> tuple[list[str], list[str]]:
    """The notebooks an export holds, and the line that names those left out ('' for none):
    every notebook without ``due_by``; with it, those the class has due by then."""
    if due_by is None:
        return notebooks, []
    kept = [n for n in notebooks if n in settings.due and settings.due[n] <= due_by]
    left = [n[:2] for n in notebooks if n not in kept]
    return kept, ([f'left out (not due by {due_by.isoformat()}): {", ".join(left)}']
                  if left else [])


def deciding_time(due_by: Optional[datetime.datetime]) -> datetime.datetime:
    """The time that decides what is due (aware): now, or ``due_by`` when it came earlier;
    a ``due_by`` still to come makes nothing due before its time."""
    now = datetime.datetime.now(datetime.timezone.utc)
    return min(due_by, now) if due_by else now


def mark(learner: Learner, notebook: str, raw: Optional[float], points: float,
         settings: CourseSettings, extensions: Extensions, now: datetime.datetime) -> Mark:
    """``learner``'s mark of ``notebook``: its score after lateness if they handed it in
    (``raw``: nbgrader's, manual points included), else 0 once it is due for them (their
    extension's due date, or the class's, by ``now``) and blank until then; a notebook
    without a due date is never due, so blank (a platform's final score counts a blank as 0
    at the end, its current score leaves it out)."""
    extension = extensions.of(learner.name, notebook)
    if notebook in learner.files:
        if raw is None:  # handed in, yet nbgrader's gradebook holds no score of it
            return Mark(None, 'handed in, no score in the gradebook: grade it, then export')
        late = assess(settings, notebook, raw, learner.handed_in.get(notebook), extension)
        said = [f'{late.final:g} of {points:g} points', late.note,
                f'extension {late.extension()}' if late.extension() else '']
        return Mark(late.final, '; '.join(s for s in said if s))
    due = extension or settings.due.get(notebook)
    if due is None:
        return Mark(None, 'not handed in, no due date')
    if due > now:
        return Mark(None, f'not due yet (due {due.isoformat(sep=" ", timespec="minutes")})')
    return Mark(0.0, f'not handed in: 0 of {points:g} points')


def build_table(gradebook: Gradebook, learners: list[Learner], notebooks: list[str],
                settings: CourseSettings, extensions: Extensions,
                now: datetime.datetime) -> Table:
    """The marks of ``learners`` in ``notebooks`` (:func:`mark`), from ``gradebook``."""
    maxima = {nb.name: nb.max_score for nb in gradebook.find_assignment(ASSIGNMENT).notebooks}
    marks = {}
    for learner in learners:
        marks[learner.shown] = {n: mark(learner, n, _raw(gradebook, n, learner.id), maxima[n],
                                        settings, extensions, now) for n in notebooks}
    return Table(tuple(notebooks), {n: maxima[n] for n in notebooks}, marks)


def _raw(gradebook: Gradebook, notebook: str, student: str) -> Optional[float]:
    try:
        scored: Any = gradebook.find_submission_notebook(notebook, ASSIGNMENT, student)
    except MissingEntry:
        return None
    return float(scored.score)


def export(grading: Path, platform: str, roster: Optional[Roster], settings: CourseSettings,
           extensions: Extensions, due_by: Optional[datetime.datetime] = None,
           learners: Optional[list[Learner]] = None) -> list[str]:
    """Write ``grading/export/<platform>.csv`` from the grading in ``grading``; return the
    lines to print (notebooks left out, learners not in the roster, Moodle's grade items).

    :param due_by: choose the notebooks due by then, and decide what is due; None: every
        notebook, due by now.
    :param learners: the class as graded (default: ``grading/learners.json``).
    """
    course = grading / 'nbgrader'
    notebooks = sorted(p.stem for p in (course / 'source' / ASSIGNMENT).glob('*.ipynb'))
    chosen, said = notebooks_due_by(settings, notebooks, due_by)
    now = deciding_time(due_by)
    folder = grading / 'export'
    folder.mkdir(exist_ok=True)
    with Gradebook(gradebook_url(course)) as gradebook:
        table = build_table(gradebook, learners if learners is not None else load_state(grading),
                            chosen, settings, extensions, now)
    said += write(platform, table, roster, folder / f'{platform}.csv')
    if roster is not None:
        said += [f'{name}: in the roster, nothing graded' for name in roster
                 if name not in table.marks]
    if platform == 'moodle':
        said.append(moodle_items(table))
    return said + [f'wrote {folder / f"{platform}.csv"}']


class CourseExport(ExportPlugin):
    """nbgrader's export plugin for one platform (``--exporter=...CourseExport``: plain CSV),
    reading the grading around nbgrader's course folder (:func:`export`)."""

    lms = Unicode('csv').tag(config=True)
    grading = Unicode('..', help='the grading folder (with learners.json)').tag(config=True)
    roster = Unicode('', help='the roster CSV (learner, lms_id, sis_id, ...)').tag(config=True)
    settings = Unicode(str(SETTINGS), help='course.toml').tag(config=True)
    extensions = Unicode('', help='extensions.toml (default: beside settings)').tag(config=True)
    due_by = Unicode('', help=f'export the notebooks due by then ({EXAMPLE_DUE_BY})'
                     ).tag(config=True)
    said: List[str] = List()

    def export(self, gradebook: Gradebook) -> None:
        """Write the export (``said``: its lines); ``to`` is ignored: the file is
        ``<grading>/export/<lms>.csv``.

        :raises SettingsProblem, ExtensionsProblem, RosterProblem, TimeProblem: their lines.
        """
        grading = Path(self.grading).resolve()
        learners = load_state(grading)
        notebooks = sorted(p.stem for p in (grading / 'nbgrader' / 'source' / ASSIGNMENT)
                           .glob('*.ipynb'))
        settings = read_settings(Path(self.settings), notebooks)
        roster = read_roster(Path(self.roster), self.lms) if self.roster else None
        names = {lr.name for lr in learners} | set(roster or ())
        extensions = read_extensions(Path(self.extensions) if self.extensions
                                     else Path(self.settings).parent / EXTENSIONS,
                                     settings, notebooks, names)
        due_by = parse_time(self.due_by, 'DUE_BY') if self.due_by else None
        self.said = export(grading, self.lms, roster, settings, extensions, due_by, learners)


class CanvasExport(CourseExport):
    """Canvas's gradebook import (``EXPORT=canvas``)."""

    lms = Unicode('canvas').tag(config=True)


class MoodleExport(CourseExport):
    """Moodle's CSV grade import (``EXPORT=moodle``)."""

    lms = Unicode('moodle').tag(config=True)


#: ``EXPORT=``'s choices and their plugins.
EXPORTS = {'canvas': CanvasExport, 'moodle': MoodleExport, 'csv': CourseExport}


def main(argv: Optional[list[str]] = None) -> int:
    """``ros2nb-export`` (``make export EXPORT=canvas ROSTER=roster.csv [DUE_BY=...]``): the
    platform's file from the grading in ``--grading``; 0 when it was written, 2 (and one
    line per mistake) when an input is wrong or there is no grading."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('platform', choices=PLATFORMS)
    parser.add_argument('--grading', type=Path, default=ROOT / 'grading')
    parser.add_argument('--roster', type=Path)
    parser.add_argument('--settings', type=Path, default=SETTINGS)
    parser.add_argument('--extensions', type=Path)
    parser.add_argument('--due-by', metavar='TIME', help=f'such as {EXAMPLE_DUE_BY}')
    args = parser.parse_args(argv)
    grading = args.grading.resolve()
    try:
        if args.due_by:
            parse_time(args.due_by, 'DUE_BY')
    except TimeProblem as problem:
        print(problem)
        return 2
    if not (grading / 'learners.json').is_file():
        print(f'{grading} holds no grading to export: run make grade first '
              '(or name the grading with GRADING=folder)')
        return 2
    if args.platform in ('canvas', 'moodle') and args.roster is None:
        print(f'EXPORT={args.platform} needs a roster of the platform\'s ids: ROSTER=roster.csv '
              '(docs/instructors.md, "A term, step by step")')
        return 2
    plugin = EXPORTS[args.platform](
        grading=str(grading), roster=str(args.roster or ''), settings=str(args.settings),
        extensions=str(args.extensions or ''), due_by=args.due_by or '')
    try:
        with Gradebook(gradebook_url(grading / 'nbgrader')) as gradebook:
            plugin.export(gradebook)
    except (SettingsProblem, ExtensionsProblem, RosterProblem, TimeProblem) as problem:
        print(problem)
        return 2
    for line in plugin.said:
        print(line)
    return 0


if __name__ == '__main__':
    sys.exit(main())
