"""nbgrader's scores of a class: scored batch by batch, then less lateness, into grades.csv.

Runs on the instructor's host.  nbgrader keeps the gradebook, scores the notebooks and
writes the feedback, in a process of its own (:class:`Scoring`, :mod:`.scoring`); it
executes nothing of the learners' here (its Execute step is off for the scoring run: every
notebook was run in a sandbox and judged before).  The course it scores in is
:mod:`.nbgrader_course`'s; the feedback pages are the reports' (:mod:`.pages`).
"""

from __future__ import annotations

import contextlib
import json
import subprocess
import sys
from pathlib import Path
from typing import Iterable, Optional

from nbgrader.api import Gradebook, MissingEntry

from ...paths import ASSIGNMENT, gradebook_url
from ..export.spreadsheets import write_csv
from ..intake.deadlines import NO_DEADLINES, CourseSettings, Lateness, assess
from ..intake.extensions import Extensions
from ..intake.extensions import NONE as NO_EXTENSIONS
from ..intake.submissions import Learner
from ..reports import feedback
from ..reports.pages import feedback_page, standing_table
from .nbgrader_course import course_env

#: grades.csv's columns: ``score`` is what the notebook counts (after lateness), ``raw_score``
#: what nbgrader gave it, ``late_penalty`` the difference (:mod:`.deadlines`).
CSV_COLUMNS = ['learner', 'notebook', 'score', 'max_score', 'raw_score', 'late_penalty',
               'handed_in', 'due']


def write_results(course: Path, out: Path, learners: list[Learner], notebooks: list[str],
                  deadlines: CourseSettings = NO_DEADLINES,
                  extensions: Extensions = NO_EXTENSIONS) -> list[list[str]]:
    """grades.csv from nbgrader's gradebook, and the feedback files; return the CSV rows
    (:data:`CSV_COLUMNS`; learner's name as shown, then a TOTAL row per learner).

    A handed-in notebook's lateness (:func:`.deadlines.assess`, with the learner's extension)
    goes into the learner's ``late`` and notes, and into nbgrader's gradebook as its late
    submission penalty (so ``nbgrader export`` and the formgrader show it too)."""
    rows = []
    with Gradebook(gradebook_url(course)) as gb:
        maxima = {nb.name: nb.max_score for nb in gb.find_assignment(ASSIGNMENT).notebooks}
        for learner in learners:
            total = raw_total = 0.0
            standing = feedback.standing_html(standing_table(learner))
            folder = out / 'feedback' / learner.name
            folder.mkdir(parents=True, exist_ok=True)
            for notebook in notebooks:
                try:
                    scored = gb.find_submission_notebook(notebook, ASSIGNMENT, learner.id)
                except MissingEntry:
                    scored = None
                raw = scored.score if scored is not None else 0.0
                late = None
                if notebook in learner.files:
                    late = assess(deadlines, notebook, raw, learner.handed_in.get(notebook),
                                  extensions.of(learner.name, notebook))
                    learner.late[notebook] = late
                    if late.note:
                        learner.note(notebook, late.note)
                    if scored is not None:
                        scored.late_submission_penalty = late.penalty or None
                score = late.final if late else raw
                total, raw_total = total + score, raw_total + raw
                rows.append([learner.shown, notebook, f'{score:g}', f'{maxima[notebook]:g}',
                             f'{raw:g}', f'{raw - score:g}', _time(late, 'handed_in'),
                             _time(late, 'due')])
                feedback_page(course, folder, learner, notebook, maxima[notebook], standing)
            rows.append([learner.shown, 'TOTAL', f'{total:g}', f'{sum(maxima.values()):g}',
                         f'{raw_total:g}', f'{raw_total - total:g}', '', ''])
        gb.db.commit()
    write_csv(out / 'grades.csv', CSV_COLUMNS, rows)
    return rows


def _time(late: Optional[Lateness], which: str) -> str:
    when = getattr(late, which, None) if late else None
    return when.isoformat() if when else ''


class Scoring:
    """nbgrader scoring a class batch by batch, in one process (:mod:`.scoring`), its log
    appended to ``course/grading.log``.  A context manager: the process ends with the block.

    Introduced for ``ros2nb-grade`` (:mod:`.cli`), which scores learners as they are done.
    """

    def __init__(self, course: Path) -> None:
        self._course = course
        self._process: Optional[subprocess.Popen[str]] = None

    def __enter__(self) -> 'Scoring':
        return self

    def __exit__(self, *_: object) -> None:
        self._end()

    def score(self, exclude: Iterable[str]) -> bool:
        """nbgrader scores what was filed for every learner but ``exclude`` (executing
        nothing), then writes their feedback; True when both worked.

        :param exclude: nbgrader ids of learners left out (not yet graded, or scored before).
        """
        for _attempt in range(2):  # a process that ended meanwhile: once more, in a new one
            process = self._started()
            try:
                assert process.stdin is not None and process.stdout is not None
                process.stdin.write(json.dumps(sorted(exclude)) + '\n')
                process.stdin.flush()
                answer = process.stdout.readline()
            except OSError:
                answer = ''
            if answer:
                with contextlib.suppress(ValueError, AttributeError):
                    return bool(json.loads(answer).get('ok'))
                return False
            self._end()
        return False

    def _started(self) -> subprocess.Popen[str]:
        if self._process is None:
            with open(self._course / 'grading.log', 'a') as log:
                self._process = subprocess.Popen(
                    [sys.executable, '-m', 'ros2nb_instructor.grading.scores.scoring',
                     str(self._course)], cwd=self._course, env=course_env(self._course),
                    stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, text=True)
        return self._process

    def _end(self) -> None:
        process, self._process = self._process, None
        if process is not None:
            with contextlib.suppress(OSError):
                process.stdin.close()  # type: ignore[union-attr]  # started with a pipe
            process.wait()
            process.stdout.close()  # type: ignore[union-attr]  # started with a pipe
