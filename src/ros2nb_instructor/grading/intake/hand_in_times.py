"""When each notebook was handed in, as the submission says: strict times, per notebook.

Runs on the instructor's host (grading reads these files) and on the classroom server (the
hand-in service records times, ``make hub-collect`` writes them beside the notebooks).  A
learner's folder may say when its notebooks were handed in in two ways:

- ``handed-in.json`` (:data:`HANDED_IN`): the course's own record, one time per notebook,
  ``{"03-write-the-publisher": "2026-10-05T21:30:12.034121+00:00", ...}``, made from the
  hand-in service's clock (:mod:`ros2nb_instructor.hub.hand_in_store`);
- ``timestamp.txt`` (:data:`TIMESTAMP`): nbgrader's exchange's, one time for every notebook
  of the folder (nbgrader's exchange hands in an assignment as a whole).

A time is ISO 8601 with its offset (``Z`` or ``+02:00``), or what nbgrader's exchange writes
(its date, a space, its time, a space and ``UTC``); anything else (``+0200``, ``CEST``, a
day/month/year date) is refused with one line (:class:`TimeProblem`), never guessed: a
misread time moves a notebook across its due date.
"""

from __future__ import annotations

import datetime
import json
import re
from pathlib import Path
from typing import Mapping

#: The course's record of per-notebook hand-in times in a learner's folder.
HANDED_IN = 'handed-in.json'
#: The file nbgrader's exchange writes beside a submission: when it was handed in.
TIMESTAMP = 'timestamp.txt'
#: Where a hand-in time read from a platform zip's entry comes from.
ZIP_ENTRY = 'zip entry'
#: An example of a time the grader reads, for the line of a mistake.
EXAMPLE = '2026-10-05T23:30:00+02:00'
#: Largest record read (a class's record is a few hundred bytes per learner).
MAX_RECORD_BYTES = 100_000
_TIME = re.compile(r'(\d{4})-(\d{2})-(\d{2})[T ](\d{2}):(\d{2})(?::(\d{2})(?:\.(\d{1,6}))?)?'
                   r'(Z|[+-](?:[01]\d|2[0-3]):[0-5]\d| UTC)')


class TimeProblem(ValueError):
    """A hand-in time the grader does not read: the message is one line saying what to write."""


def parse_time(text: str, where: str) -> datetime.datetime:
    """``text`` as an aware time: ISO 8601 with its offset, or nbgrader's ``... UTC``.

    :param where: the file (and key) it comes from, for the line of a mistake.
    :raises TimeProblem: with one line naming ``where``, what it says and what to write.
    """
    found = _TIME.fullmatch(text.strip())
    if found:
        year, month, day, hour, minute, second, fraction, zone = found.groups()
        offset = datetime.timedelta(0)
        if zone not in ('Z', ' UTC'):
            sign = -1 if zone[0] == '-' else 1
            offset = sign * datetime.timedelta(hours=int(zone[1:3]), minutes=int(zone[4:6]))
        try:
            return datetime.datetime(int(year), int(month), int(day), int(hour), int(minute),
                                     int(second or 0), int((fraction or '0').ljust(6, '0')),
                                     tzinfo=datetime.timezone(offset))
        except ValueError:
            pass
    shown = text.strip()[:60]
    raise TimeProblem(f'{where}: {shown!r} is not a time with its offset: write ISO 8601, '
                      f'such as {EXAMPLE} (or Z for UTC)')


def read_timestamp(path: Path) -> datetime.datetime:
    """nbgrader's ``timestamp.txt`` at ``path``, read strictly (:func:`parse_time`).

    :raises TimeProblem: when it holds no time the grader reads (or cannot be read).
    """
    try:
        text = path.read_bytes()[:200].decode('utf-8')
    except (OSError, UnicodeDecodeError) as error:
        raise TimeProblem(f'{path}: cannot be read ({error}): write one time such as '
                          f'{EXAMPLE}') from None
    return parse_time(text, str(path))


def read_record(path: Path, notebooks: list[str]) -> dict[str, datetime.datetime]:
    """The course's ``handed-in.json`` at ``path``: notebook -> when it was handed in.

    :param notebooks: the course's notebooks (``NN-title``); another key is a mistake.
    :raises TimeProblem: one line for a file that is no JSON object of times, an unknown
        notebook or a time :func:`parse_time` refuses.
    """
    try:
        data = json.loads(path.read_bytes()[:MAX_RECORD_BYTES])
    except (OSError, ValueError) as error:
        raise TimeProblem(f'{path}: not JSON ({type(error).__name__}): write '
                          f'{{"03-write-the-publisher": "{EXAMPLE}"}}') from None
    if not isinstance(data, dict):
        raise TimeProblem(f'{path}: not a JSON object: write {{"NN-title": "{EXAMPLE}"}}')
    times = {}
    for notebook, text in data.items():
        if notebook not in notebooks:
            raise TimeProblem(f'{path}: {str(notebook)[:60]!r} is not a notebook of the course: '
                              f'write one of its names, such as {notebooks[0]!r}')
        if not isinstance(text, str):
            raise TimeProblem(f'{path}: {notebook} is not a time: write "{EXAMPLE}"')
        times[notebook] = parse_time(text, f'{path} {notebook}')
    return times


def record_text(times: Mapping[str, datetime.datetime]) -> str:
    """``handed-in.json``'s text for ``times`` (notebook -> aware time), as
    :func:`read_record` reads it back."""
    return json.dumps({n: t.isoformat() for n, t in sorted(times.items())}, indent=1) + '\n'
