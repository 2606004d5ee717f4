"""nbgrader scores a batch of learners, then writes their feedback, in one process.

``python -m ros2nb_instructor.grading.scoring COURSE [EXCLUDED_IDS]``, started by
:func:`.gradebook.score_and_feedback` on the instructor's host (trusted: it executes
nothing of the learners').  nbgrader's own converters do the work its ``autograde`` and
``generate_feedback`` commands do, one after the other, as nbgrader's API (the
Formgrader's) runs them: one start of nbgrader per batch instead of two (1.1 CPU-s each).
Autograde only scores: every notebook was run in a sandbox and judged before, so its
Execute and ClearOutput steps are off.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path

from nbgrader.converters import Autograde, GenerateFeedback, NbGraderException
from nbgrader.coursedir import CourseDirectory
from nbgrader.preprocessors import ClearOutput, Execute
from traitlets.config import Config

from ..paths import ASSIGNMENT, gradebook_url


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


def main(argv: list[str]) -> int:
    """Score, then write the feedback; 0 when both worked.  nbgrader's log goes to standard
    error, which the grader appends to ``COURSE/grading.log`` (as its command lines' did)."""
    if len(argv) not in (1, 2):
        print('Usage: python -m ros2nb_instructor.grading.scoring COURSE [EXCLUDED_IDS]',
              file=sys.stderr)
        return 2
    course = Path(argv[0])
    config = score_only_config(course, argv[1] if len(argv) == 2 else '')
    logging.basicConfig(stream=sys.stderr, level=logging.INFO,
                        format='[%(name)s | %(levelname)s] %(message)s')
    coursedir = CourseDirectory(config=config)
    failed = False
    for step in (Autograde, GenerateFeedback):
        try:
            step(coursedir=coursedir, config=config, log=logging.getLogger(step.__name__)).start()
        except NbGraderException:  # nbgrader logged which notebook and why
            failed = True
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
