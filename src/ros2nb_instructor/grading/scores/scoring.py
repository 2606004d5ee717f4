"""nbgrader scores batches of learners, then writes their feedback, in one process.

``python -m ros2nb_instructor.grading.scores.scoring COURSE``, started by
:class:`.gradebook.Scoring` on the instructor's host (trusted: it executes nothing of the
learners').  Each line on its standard input is one batch: a JSON list of the ids nbgrader
leaves out (every learner not in the batch); it answers each with a line ``{"ok": BOOL}``
once scored, and ends at the end of its input.  nbgrader's own converters do the work its
``autograde`` and ``generate_feedback`` commands do, one after the other, as nbgrader's API
(the Formgrader's) runs them.  One process serves the whole class: nbgrader's start (its
imports, its templates) is paid once, and a batch then costs a fraction of it
(docs/decisions.md), so learners are scored as soon as each is done.  Autograde only
scores: every notebook was run in a sandbox and judged before, so its Execute and
ClearOutput steps are off.
"""

from __future__ import annotations

import json
import logging
import sys
from pathlib import Path

from nbgrader.converters import Autograde, GenerateFeedback, NbGraderException
from nbgrader.coursedir import CourseDirectory
from nbgrader.preprocessors import ClearOutput, Execute
from traitlets.config import Config

from ...paths import ASSIGNMENT, gradebook_url


def score_only_config(course: Path, excluded: str) -> Config:
    """nbgrader's settings for scoring ``course`` (all learners but the comma-separated
    ``excluded`` ids) without executing anything."""
    config = Config()
    config.CourseDirectory.root = str(course)
    config.CourseDirectory.db_url = gradebook_url(course)
    config.CourseDirectory.student_id_exclude = excluded
    config.CourseDirectory.assignment_id = ASSIGNMENT
    config.BaseConverter.force = True
    config.Autograde.create_student = True
    defaults = Autograde.class_traits()
    config.Autograde.sanitize_preprocessors = [
        p for p in defaults['sanitize_preprocessors'].default() if p is not ClearOutput]
    config.Autograde.autograde_preprocessors = [
        p for p in defaults['autograde_preprocessors'].default() if p is not Execute]
    return config


def score(course: Path, excluded: str) -> bool:
    """Score, then write the feedback of, every learner of ``course`` but the comma-separated
    ``excluded`` ids; True when both worked (nbgrader logs which notebook failed and why)."""
    config = score_only_config(course, excluded)
    coursedir = CourseDirectory(config=config)
    worked = True
    for step in (Autograde, GenerateFeedback):
        try:
            step(coursedir=coursedir, config=config, log=logging.getLogger(step.__name__)).start()
        except NbGraderException:
            worked = False
    return worked


def main(argv: list[str]) -> int:
    """Score each batch read on standard input (module docstring); nbgrader's log goes to
    standard error, which the grader appends to ``COURSE/grading.log``."""
    if len(argv) != 1:
        print('Usage: python -m ros2nb_instructor.grading.scores.scoring COURSE '
              '(batches on standard input: a JSON list of the ids to leave out, one per line)',
              file=sys.stderr)
        return 2
    logging.basicConfig(stream=sys.stderr, level=logging.INFO,
                        format='[%(name)s | %(levelname)s] %(message)s')
    answers, sys.stdout = sys.stdout, sys.stderr  # what nbgrader prints goes to the log
    for line in sys.stdin:
        excluded = json.loads(line)
        print(json.dumps({'ok': score(Path(argv[0]), ','.join(excluded))}), file=answers,
              flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
