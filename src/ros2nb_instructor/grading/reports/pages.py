"""Each learner's feedback pages, one per notebook: nbgrader's page made safe, or one saying
the notebook was not handed in, each headed by the learner's standing in every notebook.

Runs on the instructor's host, once nbgrader scored the learner
(:func:`ros2nb_instructor.grading.scores.gradebook.write_results` writes them as it reads the
scores).  The standing
comes from this grading's own results (the judge's), never from the learner's record of
their lab; the page itself is :mod:`.feedback`'s (sanitised, under a strict CSP).
"""

from __future__ import annotations

from pathlib import Path

from ros2nb import graded_parts

from ...paths import ASSIGNMENT, SOLUTIONS
from ..intake.submissions import Learner
from . import feedback


def _not_submitted_page(learner: Learner, notebook: str, points: float, standing: str) -> str:
    return feedback.page(notebook, feedback.render('above.html.j2', boxes=[standing]) +
                         feedback.render('not_submitted.html.j2', learner=learner.shown,
                                         notebook=notebook, points=f'{points:g}'))


def standing_table(learner: Learner) -> str:
    """The learner's table of every graded part of the course (:mod:`ros2nb.graded_parts`),
    from this grading's own results (the judge's, never the learner's record of their lab):
    passed, failed, or not handed in, with its points."""
    parts = graded_parts.parts(SOLUTIONS)
    states = {}
    for part in parts:
        result = learner.results.get(part.notebook, {}).get(part.grade_id)
        states[part.grade_id] = (graded_parts.NOT_HANDED_IN if part.notebook not in learner.files
                                 else graded_parts.PASSED if result and result.passed
                                 else graded_parts.FAILED)
    return graded_parts.table_html(graded_parts.rows(parts, states),
                                   'Every notebook, as the grader found it')


def feedback_page(course: Path, folder: Path, learner: Learner, notebook: str,
                  points: float, standing: str) -> None:
    """The learner's feedback page of ``notebook`` (nbgrader's, made safe, headed by the
    learner's ``standing`` in every notebook, its lateness and the judge's flags), or one
    saying it was not submitted (headed by ``standing`` too)."""
    made = course / 'feedback' / learner.id / ASSIGNMENT / f'{notebook}.html'
    page = folder / f'{notebook}.html'
    try:
        if notebook in learner.files and made.is_file():
            page.write_text(feedback.safe_feedback(made.read_text(), notebook,
                                                   learner.flags.get(notebook, ()),
                                                   learner.late.get(notebook), standing))
        else:
            page.write_text(_not_submitted_page(learner, notebook, points, standing))
    except Exception as error:  # noqa: BLE001 - that page's problem, in a note
        why = (f'its feedback page could not be written ({type(error).__name__}: '
               f'{str(error)[:200]}); the score stands')
        learner.note(notebook, why)
        page.write_text(feedback.page(notebook, feedback.render('paragraph.html.j2', text=why)))
