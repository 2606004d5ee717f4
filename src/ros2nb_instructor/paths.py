"""Where the course's files are, as the instructor's tools see them, and what nbgrader calls them.

Runs on the instructor's host.  The course is the repository this package lies in (the
course's venv installs it in place).
"""

from __future__ import annotations

from pathlib import Path

#: The course repository (this file is src/ros2nb_instructor/paths.py inside it).
ROOT = Path(__file__).resolve().parent.parent.parent
#: The complete notebooks, hidden tests included: the single source of the learner's.
SOLUTIONS = ROOT / 'solutions'
#: The learner notebooks, generated from solutions/ by nbgrader (never edited by hand).
NOTEBOOKS = ROOT / 'notebooks'
#: nbgrader's name for the set of notebooks a learner submits.
ASSIGNMENT = 'ros2-pubsub'
#: The course's settings for a term: due dates and the late policy
#: (grading.intake.course_settings).
SETTINGS = ROOT / 'course.toml'
#: Each learner's extensions, beside the settings (grading.intake.extensions): the
#: instructor's alone.
EXTENSIONS = 'extensions.toml'


def gradebook_url(course: Path) -> str:
    """The database URL of the nbgrader gradebook of the course folder ``course``."""
    return f'sqlite:///{course / "gradebook.db"}'
