"""Due dates and the late policy: the course's settings file (``course.toml``), read and checked.

Runs on the instructor's host.  The instructor writes, per notebook, when it is due (a date and
time with its time zone) and what handing it in late costs; grading compares that with the time
the submission itself says it was handed in (:mod:`.submissions`: nbgrader's ``timestamp.txt``,
or a platform zip's entry times), never with the grader's clock.  The penalty is computed by a
plugin of nbgrader's own late-submission interface (:class:`LatePenalty`), and kept beside the
raw score: nbgrader's gradebook, ``grades.csv``, the feedback page and ``report.html`` show both.

A mistake in the file is one line each, saying what to write instead
(:exc:`SettingsProblem`); grading does not start with any.
"""

from __future__ import annotations

import datetime
import math
import sys
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Mapping, Optional

from nbgrader.plugins import LateSubmissionPlugin
from traitlets import Enum, Float

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib

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
               'without_time': 'one of "on-time", "zero"',
               'zip_time_zone': 'a time zone name such as "Europe/Berlin" or "UTC"'}
#: An example of a due date, for the line of a mistake.
EXAMPLE_DUE = '2026-10-05T23:59:00+02:00'


class SettingsProblem(Exception):
    """The settings file cannot be used: ``lines`` holds one line per mistake."""

    def __init__(self, lines: list[str]) -> None:
        super().__init__('\n'.join(lines))
        self.lines = lines


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
    """

    due: Mapping[str, datetime.datetime]
    policies: Mapping[str, Policy]
    zip_time_zone: datetime.tzinfo = datetime.timezone.utc

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
    """

    due: Optional[datetime.datetime]
    handed_in: Optional[datetime.datetime]
    source: str
    late_s: float
    raw: float
    penalty: float
    note: str = ''

    @property
    def final(self) -> float:
        return max(0.0, self.raw - self.penalty)

    def shown(self) -> tuple[str, str]:
        """The due date, and when the notebook was handed in with where that time comes from
        ('' when the submission says none), both in the due date's time zone, to the second:
        the two compare at a glance."""
        zone = self.due.tzinfo if self.due else None
        due = self.due.isoformat(sep=' ', timespec='seconds') if self.due else ''
        if self.handed_in is None:
            return due, ''
        when = self.handed_in.astimezone(zone) if zone else self.handed_in
        return due, f'{when.isoformat(sep=" ", timespec="seconds")} ({self.source})'


def late_by(seconds: float) -> str:
    """``seconds`` of lateness in words: ``1 day 2 h 5 min``."""
    minutes = math.ceil(seconds / 60)
    days, minutes = divmod(minutes, 1440)
    hours, minutes = divmod(minutes, 60)
    parts = [f'{days} day{"s" if days != 1 else ""}' if days else '',
             f'{hours} h' if hours else '', f'{minutes} min' if minutes else '']
    return ' '.join(p for p in parts if p) or 'under a minute'


def assess(settings: CourseSettings, notebook: str, raw: float,
           handed_in: Optional[tuple[datetime.datetime, str]]) -> Lateness:
    """What lateness costs a notebook that scored ``raw`` (its final score is
    :attr:`Lateness.final`).

    :param handed_in: the time the submission says it was handed in, and where that came
        from; None when it says nothing.
    """
    due = settings.due.get(notebook)
    when, source = handed_in if handed_in else (None, '')
    if due is None:
        return Lateness(None, when, source, 0.0, raw, 0.0)
    policy = settings.policy(notebook)
    if when is None:
        if policy.without_time == 'zero':
            return Lateness(due, None, '', 0.0, raw, raw, 'no hand-in time in the submission '
                                                          '(the policy scores that 0)')
        return Lateness(due, None, '', 0.0, raw, 0.0, 'no hand-in time in the submission: '
                                                      'graded as on time')
    late_s = max(0.0, (when - due).total_seconds())
    if late_s <= policy.grace_minutes * 60:
        return Lateness(due, when, source, 0.0, raw, 0.0)
    said = f'handed in {late_by(late_s)} after the due date ({source})'
    if policy.cutoff_hours is not None and late_s > policy.cutoff_hours * 3600:
        return Lateness(due, when, source, late_s, raw, raw,
                        f'{said}, past the cutoff of {late_by(policy.cutoff_hours * 3600)}: '
                        f'0 points (it scored {raw:g})')
    plugin = LatePenalty(per=policy.penalty, percent=policy.percent,
                         cap_percent=policy.cap_percent, grace_s=policy.grace_minutes * 60)
    penalty = min(raw, plugin.late_submission_penalty('', raw, late_s) or 0.0)
    cost = f': {penalty:g} points off' if penalty else ': no penalty'
    return Lateness(due, when, source, late_s, raw, penalty, said + cost)


def read_settings(path: Path, notebooks: list[str]) -> CourseSettings:
    """The course's settings file at ``path`` (TOML), checked against the course's
    ``notebooks``; :data:`NO_DEADLINES` when there is no file.

    :raises SettingsProblem: with one line per mistake, each saying what to write instead.
    """
    if not path.is_file():
        return NO_DEADLINES
    try:
        data = tomllib.loads(path.read_text())
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise SettingsProblem([f'{path}: not TOML ({error}); see docs/instructors.md, '
                               '"A term, step by step", for an example']) from None
    lines: list[str] = []
    default = _policy(data.get('late', {}), Policy(), f'{path} [late]', lines)
    due, policies = {}, {}
    notebooks_table = data.get('notebooks', {})
    for key in sorted(set(data) - {'late', 'notebooks'}):
        lines.append(f'{path}: unknown section [{key}]: write [late] or [notebooks.NN-title]')
    for notebook, table in notebooks_table.items() if isinstance(notebooks_table, dict) else ():
        where = f'{path} [notebooks.{notebook}]'
        if notebook not in notebooks:
            near = [n for n in notebooks if n[:2] == notebook[:2]]
            lines.append(f'{where}: no notebook {notebook!r} in the course: write one of its '
                         f'names, such as {(near or notebooks)[0]!r}')
            continue
        if not isinstance(table, dict):
            lines.append(f'{where}: write a table with due = {EXAMPLE_DUE}')
            continue
        when = _due(table.get('due'), where, lines)
        if when is not None:
            due[notebook] = when
        policies[notebook] = _policy({k: v for k, v in table.items() if k != 'due'}, default,
                                     where, lines)
    zone = _zone(data.get('late', {}).get('zip_time_zone', 'UTC'), f'{path} [late]', lines)
    if lines:
        raise SettingsProblem(lines)
    return CourseSettings(due, {n: policies.get(n, default) for n in notebooks}, zone)


def _due(value: Any, where: str, lines: list[str]) -> Optional[datetime.datetime]:
    """A due date: a TOML date-time with its offset (or a string of one)."""
    if isinstance(value, str):
        try:
            value = datetime.datetime.fromisoformat(value)
        except ValueError:
            lines.append(f'{where}: due = {value!r} is not a date and time: write due = '
                         f'{EXAMPLE_DUE} (with its time zone)')
            return None
    if not isinstance(value, datetime.datetime):
        lines.append(f'{where}: due is missing or not a date and time: write due = '
                     f'{EXAMPLE_DUE} (with its time zone)')
        return None
    if value.tzinfo is None or value.utcoffset() is None:
        lines.append(f'{where}: due = {value.isoformat()} has no time zone: write it with its '
                     f'offset, such as due = {value.isoformat()}+02:00 (or Z for UTC)')
        return None
    return value


def _policy(table: Any, base: Policy, where: str, lines: list[str]) -> Policy:
    """``base`` with the policy keys ``table`` sets; one line per wrong key or value."""
    if not isinstance(table, dict):
        lines.append(f'{where}: write a table of the late policy\'s keys')
        return base
    changes: dict[str, Any] = {}
    for key, value in table.items():
        if key == 'zip_time_zone' and where.endswith('[late]'):
            continue
        if key not in POLICY_KEYS or key == 'zip_time_zone':
            lines.append(f'{where}: unknown key {key!r}: write one of '
                         f'{", ".join(k for k in POLICY_KEYS if k != "zip_time_zone")}')
            continue
        wrong = _wrong(key, value)
        if wrong:
            lines.append(f'{where}: {key} = {value!r} {wrong}: write {key} = '
                         f'{POLICY_KEYS[key]}')
            continue
        changes[key] = float(value) if key not in ('penalty', 'without_time') else value
    return replace(base, **changes)


def _wrong(key: str, value: Any) -> str:
    """Why ``value`` cannot be ``key``'s ('' when it can)."""
    if key == 'penalty':
        return '' if value in PENALTIES else 'is not a penalty'
    if key == 'without_time':
        return '' if value in WITHOUT_TIME else 'is not a choice'
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return 'is not a number'
    if value < 0:
        return 'is negative'
    if key in ('percent', 'cap_percent') and value > 100:
        return 'is more than 100'
    return ''


def _zone(name: Any, where: str, lines: list[str]) -> datetime.tzinfo:
    import zoneinfo
    try:
        return zoneinfo.ZoneInfo(str(name))
    except (zoneinfo.ZoneInfoNotFoundError, ValueError):
        lines.append(f'{where}: zip_time_zone = {name!r} is no time zone: write '
                     f'zip_time_zone = {POLICY_KEYS["zip_time_zone"].split(" such as ")[1]}')
        return datetime.timezone.utc
