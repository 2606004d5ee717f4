"""A due date as the instructor writes it: a date and time, with its offset or in a named zone.

Runs on the instructor's host (``course.toml``, ``extensions.toml``) and on the classroom
server (the hand-in service says each learner's due dates).  A due date is kept aware: in a
named zone (``time_zone = "Europe/Berlin"``, Python's :mod:`zoneinfo`, the IANA database)
its offset is that zone's on that day, so ``2026-10-05T23:59`` is +02:00 (summer time) and
``2026-10-26T23:59`` is +01:00; a time summer time skips or repeats is refused, and an
offset the zone did not have that day too.  Each mistake is one line, appended to the
caller's list, saying what to write.
"""

from __future__ import annotations

import datetime
import zoneinfo
from typing import Any, Optional

#: An example of a due date, for the line of a mistake.
EXAMPLE_DUE = '2026-10-05T23:59:00+02:00'
#: An example of a time zone, for the line of a mistake.
EXAMPLE_ZONE = 'Europe/Berlin'


def zone(name: Any, where: str, lines: list[str], key: str = 'time_zone'
         ) -> Optional[datetime.tzinfo]:
    """The named time zone ``name`` (IANA, through :mod:`zoneinfo`), or None with one line
    in ``lines`` when there is no such zone."""
    try:
        return zoneinfo.ZoneInfo(str(name))
    except (zoneinfo.ZoneInfoNotFoundError, ValueError):
        lines.append(f'{where}: {key} = {name!r} is no time zone: write {key} = '
                     f'"{EXAMPLE_ZONE}" or "UTC" (a name of the IANA time zone database)')
        return None


def due_date(value: Any, named: Optional[datetime.tzinfo], where: str, lines: list[str],
             key: str = 'due') -> Optional[datetime.datetime]:
    """``value`` (a TOML date-time, or its text) as an aware due date, or None with one
    line in ``lines``.

    :param named: the time zone it is in (``time_zone``), or None: then it must carry its
        offset.  A local time is read in ``named``; a time with an offset must have the
        offset ``named`` has at that moment; the result is in ``named`` (its offset that day).
    """
    if isinstance(value, str):
        try:
            value = datetime.datetime.fromisoformat(value.replace('Z', '+00:00'))
        except ValueError:
            lines.append(f'{where}: {key} = {value!r} is not a date and time: write {key} = '
                         f'{EXAMPLE_DUE} (with its offset, or set time_zone)')
            return None
    if not isinstance(value, datetime.datetime):
        lines.append(f'{where}: {key} is missing or not a date and time: write {key} = '
                     f'{EXAMPLE_DUE} (with its offset, or set time_zone)')
        return None
    if value.tzinfo is None or value.utcoffset() is None:
        if named is None:
            lines.append(f'{where}: {key} = {value.isoformat()} has no time zone: write it with '
                         f'its offset, such as {key} = {value.isoformat()}+02:00 (or Z for UTC), '
                         f'or set time_zone = "{EXAMPLE_ZONE}"')
            return None
        return _local(value, named, where, lines, key)
    if named is None:
        return value
    there = value.astimezone(named)
    if there.utcoffset() != value.utcoffset():
        lines.append(f'{where}: {key} = {value.isoformat()} has an offset {named} did not have '
                     f'then ({_offset(there)}): write {key} = {there.isoformat()}, or leave the '
                     'offset out')
        return None
    return there


def _local(value: datetime.datetime, named: datetime.tzinfo, where: str, lines: list[str],
           key: str) -> Optional[datetime.datetime]:
    """A local time in ``named``; None (one line) where summer time skips or repeats it."""
    first, second = value.replace(tzinfo=named, fold=0), value.replace(tzinfo=named, fold=1)
    back = first.astimezone(datetime.timezone.utc).astimezone(named)
    if back.replace(tzinfo=None) != value:
        lines.append(f'{where}: {key} = {value.isoformat()} does not happen in {named} (summer '
                     f'time skips it): write a time outside the hour that is skipped')
        return None
    if first.utcoffset() != second.utcoffset():
        lines.append(f'{where}: {key} = {value.isoformat()} happens twice in {named} (summer '
                     f'time ends then): write it with its offset, {first.isoformat()} or '
                     f'{second.isoformat()}')
        return None
    return first


def _offset(when: datetime.datetime) -> str:
    """``when``'s offset as ``+01:00``."""
    return when.isoformat()[-6:]


def shown(due: datetime.datetime) -> str:
    """A due date as the pages show it, to the second, with its offset and, in a named
    zone, the zone's name in brackets after it (``... 23:59:00+01:00 (Europe/Berlin)``)."""
    text = due.isoformat(sep=' ', timespec='seconds')
    key = getattr(due.tzinfo, 'key', None)
    return f'{text} ({key})' if key else text
