"""What the hand-in service tells a learner of a notebook: when due, when handed in, feedback.

Runs on the classroom server, in the hand-in service (:mod:`.hand_in_service`), as root.
Due dates are read from ``course.toml`` and ``extensions.toml`` at each request
(:mod:`ros2nb_instructor.grading.intake.course_settings`,
:mod:`ros2nb_instructor.grading.intake.extensions`), so a new extension shows at once; a
file with a mistake shows no due dates (the service's log says the mistake) and hand-ins go
on.  The answer is :class:`ros2nb.hand_ins.NotebookStatus`.
"""

from __future__ import annotations

import dataclasses
import datetime
import logging
from pathlib import Path
from typing import Optional

from ros2nb.hand_ins import NotebookStatus

from ..grading.intake.course_settings import read_settings
from ..grading.intake.deadlines import NO_DEADLINES, CourseSettings, SettingsProblem, late_by
from ..grading.intake.extensions import NONE, Extensions, ExtensionsProblem, read_extensions
from .hand_in_store import Store, course_notebooks

#: The service's log.
LOG = 'ros2nb.hand_in'
log = logging.getLogger(LOG)


@dataclasses.dataclass(frozen=True)
class Schedule:
    """Where the service reads due dates: ``course.toml`` and the extensions beside it."""

    settings: Path
    extensions: Path

    def read(self) -> tuple[CourseSettings, Extensions]:
        """The due dates as the files say now (none, and a line in the log, on a mistake)."""
        notebooks = course_notebooks()
        try:
            settings = read_settings(self.settings, notebooks)
        except SettingsProblem as problem:
            log.error('no due dates shown: %s', problem)
            return NO_DEADLINES, NONE
        try:
            return settings, read_extensions(self.extensions, settings, notebooks)
        except ExtensionsProblem as problem:
            log.error('no extensions shown: %s', problem)
            return settings, NONE


def status(store: Store, schedule: Schedule, learner: str, notebook: str,
           saved: Optional[datetime.datetime] = None) -> NotebookStatus:
    """What the service says of ``learner``'s ``notebook``."""
    settings, extensions = schedule.read()
    extension = extensions.of(learner, notebook)
    due = extension or settings.due.get(notebook)
    handed_in = store.handed_in(learner).get(notebook)
    late = ''
    if due is not None and handed_in is not None \
            and (handed_in - due).total_seconds() > settings.policy(notebook).grace_minutes * 60:
        late = late_by((handed_in - due).total_seconds())  # within the grace: on time
    return NotebookStatus(
        notebook, handed_in.isoformat() if handed_in else None,
        saved.isoformat() if saved else None, due.isoformat() if due else None,
        settings.due[notebook].isoformat() if extension and notebook in settings.due else None,
        late, notebook in store.feedback(learner))


