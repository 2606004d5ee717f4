"""``course.toml`` read and checked: each notebook's due date and late policy.

Runs on the instructor's host (grading, ``make export``) and on the classroom server (the
hand-in service tells each learner their due dates).  The file's keys are documented in
docs/instructors.md ("A term, step by step") and in the course's own ``course.toml``; its
values become a :class:`.deadlines.CourseSettings`.  Every mistake is one line saying what
to write instead, and all of them come together (:class:`.deadlines.SettingsProblem`):
nothing is graded with any.
"""

from __future__ import annotations

import datetime
import sys
from dataclasses import replace
from pathlib import Path
from typing import Any, Optional

from . import due_dates
from .deadlines import (NO_DEADLINES, PENALTIES, POLICY_KEYS, WITHOUT_TIME, ZONE_KEYS,
                        CourseSettings, Policy, SettingsProblem)
from .due_dates import EXAMPLE_DUE

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover - Python 3.10
    import tomli as tomllib


def read_toml(path: Path, problem: type[Exception] = SettingsProblem) -> dict[str, Any]:
    """The TOML file at ``path`` as a dict.

    :raises problem: (called with a list of one line) when it is not TOML or not UTF-8.
    """
    try:
        return tomllib.loads(path.read_text(encoding='utf-8'))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as error:
        raise problem([f'{path}: not TOML ({error}); see docs/instructors.md, '
                       '"A term, step by step", for an example']) from None


def read_settings(path: Path, notebooks: list[str]) -> CourseSettings:
    """The course's settings file at ``path`` (TOML), checked against the course's
    ``notebooks``; :data:`.deadlines.NO_DEADLINES` when there is no file.

    :raises SettingsProblem: with one line per mistake, each saying what to write instead.
    """
    if not path.is_file():
        return NO_DEADLINES
    data = read_toml(path)
    lines: list[str] = []
    late = data.get('late', {})
    default = _policy(late, Policy(), f'{path} [late]', lines)
    class_zone = _table_zone(late, f'{path} [late]', lines)
    due, policies, zones = {}, {}, {}
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
        zone = _table_zone(table, where, lines) or class_zone
        if zone is not None:
            zones[notebook] = zone
        when = due_dates.due_date(table.get('due'), zone, where, lines)
        if when is not None:
            due[notebook] = when
        policies[notebook] = _policy({k: v for k, v in table.items() if k != 'due'}, default,
                                     where, lines)
    zip_zone = due_dates.zone(late.get('zip_time_zone', 'UTC') if isinstance(late, dict) else
                              'UTC', f'{path} [late]', lines, 'zip_time_zone')
    if lines:
        raise SettingsProblem(lines)
    return CourseSettings(due, {n: policies.get(n, default) for n in notebooks},
                          zip_zone or datetime.timezone.utc, zones)


def _table_zone(table: Any, where: str, lines: list[str]) -> Optional[datetime.tzinfo]:
    """The named zone a table's ``time_zone`` sets (None when it sets none)."""
    if not isinstance(table, dict) or 'time_zone' not in table:
        return None
    return due_dates.zone(table['time_zone'], where, lines)


def _policy(table: Any, base: Policy, where: str, lines: list[str]) -> Policy:
    """``base`` with the policy keys ``table`` sets; one line per wrong key or value."""
    if not isinstance(table, dict):
        lines.append(f'{where}: write a table of the late policy\'s keys')
        return base
    allowed = [*POLICY_KEYS, *(ZONE_KEYS if where.endswith('[late]') else ZONE_KEYS[:1])]
    changes: dict[str, Any] = {}
    for key, value in table.items():
        if key in allowed and key in ZONE_KEYS:
            continue  # read by _table_zone and read_settings
        if key not in allowed:
            lines.append(f'{where}: unknown key {key!r}: write one of {", ".join(allowed)}')
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
