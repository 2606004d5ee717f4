"""Due dates and the late policy: the course's settings file (``course.toml``), read and checked.

Runs on the instructor's host.  The instructor writes, per notebook, when it is due (a date and
time with its offset, or in a named zone: :mod:`.due_dates`) and what handing it in late costs;
a learner may have a later due date of their own (:mod:`.extensions`).  Grading compares that
with the time the submission itself says it was handed in (:mod:`.hand_in_times`: the hub's
hand-in record, nbgrader's ``timestamp.txt``, a platform zip's entry times), never with the
grader's clock.  The penalty is computed by a
plugin of nbgrader's own late-submission interface (:class:`LatePenalty`), and kept beside the
raw score: nbgrader's gradebook, ``grades.csv``, the feedback page and ``report.html`` show both.

The file is read by :mod:`.course_settings`: a mistake is one line each, saying what to write
instead (:exc:`SettingsProblem`); grading does not start with any.
"""

from __future__ import annotations

import datetime
import math
import dataclasses
from dataclasses import dataclass, replace
from typing import Mapping, Optional

from nbgrader.plugins import LateSubmissionPlugin
from traitlets import Enum, Float

from . import due_dates
from .mistakes import Mistakes

#: The penalties a policy may have: none, or a share of the score per day or hour begun.
PENALTIES = ('none', 'per-day', 'per-hour')
#: Seconds in the unit of each penalty.
UNIT_S = {'per-day': 86400.0, 'per-hour': 3600.0}
#: What a notebook without a hand-in time is graded as.
WITHOUT_TIME = ('on-time', 'zero')
#: The keys of a policy, with what each must be (for the one line of a mistake).
POLICY_KEYS = {'penalty': 'one of "none", "per-day", "per-hour"',
               'percent': 'a number from 0 to 100 (the share of the score lost per day or hour)',
               'cap_percent': 'a number from 0 to 100 (the most lateness may cost)',
               'grace_minutes': 'a number of minutes, 0 or more',
               'cutoff_hours': 'a number of hours, 0 or more (later than that: 0 points)',
               'without_time': 'one of "on-time", "zero"'}
#: Keys of a table that are not the policy's: the zone its due dates are in (any table),
#: and the zone of a zip entry's time that carries none ([late] only).
ZONE_KEYS = ('time_zone', 'zip_time_zone')


class SettingsProblem(Mistakes):
    """The settings file cannot be used: ``lines`` holds one line per mistake."""


@dataclass(frozen=True)
class Policy:
    """What handing a notebook in late costs.

    :ivar penalty: ``none``, ``per-day`` or ``per-hour``.
    :ivar percent: the share of the score (%) lost per day (or hour) begun after the due date.
    :ivar cap_percent: the most (%) lateness may cost, cutoff aside.
    :ivar grace_minutes: lateness up to this many minutes is on time.
    :ivar cutoff_hours: handed in more than this many hours late: 0 points, with a note
        (None: no cutoff).
    :ivar without_time: a notebook whose submission says no time is graded ``on-time`` (with
        a note) or scores ``zero``.
    """

    penalty: str = 'none'
    percent: float = 0.0
    cap_percent: float = 100.0
    grace_minutes: float = 0.0
    cutoff_hours: Optional[float] = None
    without_time: str = 'on-time'


@dataclass(frozen=True)
class CourseSettings:
    """The course's settings file, read: notebook -> its due date (aware) and policy.

    :ivar zip_time_zone: the zone of a zip entry's time that carries none (a zip stores local
        time unless its maker added the UTC time).
    :ivar zones: notebook -> the named zone its due dates are in (``time_zone``), where one
        is set; an extension's local time is read there.
    """

    due: Mapping[str, datetime.datetime]
    policies: Mapping[str, Policy]
    zip_time_zone: datetime.tzinfo = datetime.timezone.utc
    zones: Mapping[str, datetime.tzinfo] = dataclasses.field(default_factory=dict)

    def policy(self, notebook: str) -> Policy:
        return self.policies.get(notebook, Policy())


#: No settings file: nothing is due, nothing is late.
NO_DEADLINES = CourseSettings({}, {})


class LatePenalty(LateSubmissionPlugin):
    """nbgrader's late-submission plugin for one notebook's :class:`Policy`: the points a
    late notebook loses, as nbgrader's ``AssignLatePenalties`` asks its plugin."""

    per = Enum(('none', 'per-day', 'per-hour'), default_value='none').tag(config=True)
    percent = Float(0.0).tag(config=True)
    cap_percent = Float(100.0).tag(config=True)
    grace_s = Float(0.0).tag(config=True)

    def late_submission_penalty(self, student_id: str, score: float,
                                total_seconds_late: float) -> Optional[float]:
        """Points lost: ``percent`` of ``score`` per day (or hour) begun, at most
        ``cap_percent`` of it; None when the notebook is on time (grace included)."""
        if self.per == 'none' or total_seconds_late <= self.grace_s:
            return None
        units = math.ceil(total_seconds_late / UNIT_S[self.per])
        return round(score * min(self.cap_percent, units * self.percent) / 100, 4)


@dataclass(frozen=True)
class Lateness:
    """One notebook's raw score, what lateness cost it, and why.

    :ivar handed_in: when the submission says it was handed in (None: it says nothing).
    :ivar source: where that time comes from (``timestamp.txt``, ``zip entry``).
    :ivar late_s: seconds after the due date (0 when on time or nothing is due).
    :ivar raw: the score nbgrader gave; :ivar penalty: the points lateness cost.
    :ivar note: the sentence for notes.json and the feedback ('' when on time).
    :ivar class_due: the class's due date where the learner has an extension (``due`` is
        theirs), else None.
    """

    due: Optional[datetime.datetime]
    handed_in: Optional[datetime.datetime]
    source: str
    late_s: float
    raw: float
    penalty: float
    note: str = ''
    class_due: Optional[datetime.datetime] = None

    @property
    def final(self) -> float:
        return max(0.0, self.raw - self.penalty)

    def shown(self) -> tuple[str, str]:
        """The due date, and when the notebook was handed in with where that time comes from
        ('' when the submission says none), both in the due date's time zone, to the second:
        the two compare at a glance."""
        zone = self.due.tzinfo if self.due else None
        due = due_dates.shown(self.due) if self.due else ''
        if self.handed_in is None:
            return due, ''
        when = self.handed_in.astimezone(zone) if zone else self.handed_in
        return due, f'{when.isoformat(sep=" ", timespec="seconds")} ({self.source})'

    def extension(self) -> str:
        """The learner's extension in words ('' without one): ``to`` their due date, then
        the class's in brackets, each as :func:`.due_dates.shown` writes it."""
        if self.class_due is None or self.due is None:
            return ''
        return f'to {due_dates.shown(self.due)} (the class\'s: {due_dates.shown(self.class_due)})'


def late_by(seconds: float) -> str:
    """``seconds`` of lateness in words: ``1 day 2 h 5 min``."""
    minutes = math.ceil(seconds / 60)
    days, minutes = divmod(minutes, 1440)
    hours, minutes = divmod(minutes, 60)
    parts = [f'{days} day{"s" if days != 1 else ""}' if days else '',
             f'{hours} h' if hours else '', f'{minutes} min' if minutes else '']
    return ' '.join(p for p in parts if p) or 'under a minute'


def assess(settings: CourseSettings, notebook: str, raw: float,
           handed_in: Optional[tuple[datetime.datetime, str]],
           extension: Optional[datetime.datetime] = None) -> Lateness:
    """What lateness costs a notebook that scored ``raw`` (its final score is
    :attr:`Lateness.final`).

    :param handed_in: the time the submission says it was handed in, and where that came
        from; None when it says nothing.
    :param extension: the learner's own due date of ``notebook`` (:mod:`.extensions`), which
        replaces the class's; None for the class's.
    """
    class_due = settings.due.get(notebook)
    due = extension or class_due
    when, source = handed_in if handed_in else (None, '')
    if due is None:
        return Lateness(None, when, source, 0.0, raw, 0.0)
    late = Lateness(due, when, source, 0.0, raw, 0.0,
                    class_due=class_due if extension else None)
    policy = settings.policy(notebook)
    if when is None:
        if policy.without_time == 'zero':
            return replace(late, penalty=raw, note='no hand-in time in the submission (the '
                                                   'policy scores that 0)')
        return replace(late, note='no hand-in time in the submission: graded as on time')
    late_s = max(0.0, (when - due).total_seconds())
    if late_s <= policy.grace_minutes * 60:
        return late
    yours = ' (your extension\'s)' if extension else ''
    said = f'handed in {late_by(late_s)} after the due date{yours} ({source})'
    if policy.cutoff_hours is not None and late_s > policy.cutoff_hours * 3600:
        return replace(late, late_s=late_s, penalty=raw,
                       note=f'{said}, past the cutoff of {late_by(policy.cutoff_hours * 3600)}: '
                            f'0 points (it scored {raw:g})')
    plugin = LatePenalty(per=policy.penalty, percent=policy.percent,
                         cap_percent=policy.cap_percent, grace_s=policy.grace_minutes * 60)
    penalty = min(raw, plugin.late_submission_penalty('', raw, late_s) or 0.0)
    cost = f': {penalty:g} points off' if penalty else ': no penalty'
    return replace(late, late_s=late_s, penalty=penalty, note=said + cost)
