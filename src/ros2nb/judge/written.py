"""What a graded notebook's ``%%part`` cells wrote, and the files something else changed.

Part of the judge (:mod:`ros2nb.judge`); grading only.  A notebook's package files are what
its ``%%part`` cells write (:func:`ros2nb.terminal.files.write_part`): the learner's answer
cells and the course's given parts, joined in number order.  Any other cell runs in the same
kernel, where the course's own code is at hand, and could write a file of the package itself
(the course's rule copied into the monitor's callback, say): what the judge would then grade
is not what the notebook shows.  So before grading, the judge compares each file with what
the submission's ``%%part`` cells say it holds, through the workspace's record of the parts
(``.ros2nb-parts.json``, which ``write_part`` keeps): a part a cell wrote must be there as the
cell wrote it, and the file must be its parts joined.  A file that is not is graded as the
cells write it: the judge grades a copy of the workspace with that file written so
(:meth:`ros2nb.judge.session.Session.grade_as_written`), and flags it for the instructor.

A part whose cell still holds the placeholder keeps the working version written before it
(``write_part`` never replaces one with the placeholder): by an earlier ``%%part`` cell of the
notebook, or, in a file an earlier notebook wrote (``ros2nb.course.STEPS``), by that notebook,
which the judge cannot see: such a part is not compared.
"""

from __future__ import annotations

import json
import os
import re
import shlex
import stat
from pathlib import Path
from typing import Any, Optional

from .. import course, nbmeta
from ..terminal.files import AUTHOR_MARKERS, PARTS_RECORD, PLACEHOLDER

#: The flag of a file the notebook's cells did not write as it is (graded as they write it).
REWRITTEN = ("{name}: not what the notebook's %%part cells write (another cell changed it); "
             'graded as they write it')
#: Bytes read of one file at most (the package's files are small), and files of a workspace.
MAX_BYTES, MAX_FILES = 1_000_000, 2000


def _read(path: Path) -> Optional[str]:
    """A file's text, never through a link; None when it cannot be read."""
    data = _read_bytes(path)
    return None if data is None else data.decode('utf-8', 'replace')


#: The package files an earlier notebook wrote, by what a notebook needs before it starts.
EARLIER = {'package': (course.SETUP_PY_FILE, course.SETUP_CFG_FILE),
           'publisher': (course.PUBLISHER_FILE,), 'subscriber': (course.SUBSCRIBER_FILE,)}
#: A part that may hold what an earlier notebook wrote (not compared).
UNKNOWN = None


def _earlier_files(submission: dict[str, Any]) -> set[str]:
    """The package files notebooks before this one wrote (its number read off a grade id)."""
    ids = [nbmeta.nbgrader_metadata(cell).get('grade_id') for cell in nbmeta.cells(submission)]
    numbers = [int(i[:2]) for i in ids if isinstance(i, str) and i[:2].isdigit()]
    steps = course.STEPS.get(numbers[0], ()) if numbers else ()
    return {file for step in steps for file in EARLIER.get(step, ())}


def cell_parts(submission: dict[str, Any]) -> dict[str, dict[int, Optional[str]]]:
    """What the notebook's ``%%part`` cells write, run in order as ``write_part`` saves each
    part: file (relative to the workspace) -> part number -> its text, or :data:`UNKNOWN`
    where a placeholder kept what an earlier notebook wrote."""
    names: dict[str, str] = {}
    earlier = _earlier_files(submission)
    written: dict[str, dict[int, Optional[str]]] = {}
    for cell in nbmeta.cells(submission):
        text = nbmeta.text(cell)
        if cell.get('cell_type') != 'code':
            continue
        for name, constant in re.findall(r'^(\w+) = ros2nb\.course\.(\w+)', text, re.M):
            value = getattr(course, constant, None)
            if isinstance(value, str):
                names[name] = value
        first, _, body = text.partition('\n')
        if not first.startswith('%%part'):
            continue
        try:
            words = shlex.split(first)[1:]
            relative, number = names[words[0].strip('{}')], int(words[1])
        except (ValueError, IndexError, KeyError):
            continue  # the kernel's magic refused it too
        body = '\n'.join(line for line in body.split('\n') if line.strip() not in AUTHOR_MARKERS)
        body = body.rstrip('\n') + '\n'
        parts = written.setdefault(relative, {})
        before = parts.get(number, UNKNOWN if relative in earlier else '')
        kept = PLACEHOLDER in body and '--overwrite' not in words and \
            (before is UNKNOWN or (before and PLACEHOLDER not in before))
        parts[number] = before if kept else body
    return written


def _record(workspace: Path) -> dict[str, dict[str, str]]:
    """The workspace's record of the parts ``write_part`` saved (empty when unreadable)."""
    try:
        record = json.loads(_read(workspace / PARTS_RECORD) or '{}')
    except ValueError:
        return {}
    return {k: {n: str(t) for n, t in v.items()} for k, v in record.items()
            if isinstance(v, dict)} if isinstance(record, dict) else {}


def _joined(parts: dict[str, str]) -> str:
    """A file's text from its parts, as ``write_part`` joins them."""
    return '\n\n'.join(parts[n].rstrip('\n') for n in
                        sorted(parts, key=lambda n: int(n) if n.isdigit() else 0)) + '\n'


def as_written(submission: dict[str, Any], workspace: Path) -> dict[str, str]:
    """The package files of ``workspace`` that are not what ``submission``'s ``%%part`` cells
    write: relative path -> the text those cells write (the record's parts where a
    placeholder kept an earlier notebook's)."""
    record, rewritten = _record(workspace), {}
    for relative, parts in cell_parts(submission).items():
        saved = record.get(relative, {})
        text = _read(workspace / relative)
        if text is None:
            continue  # a file never written: each check says what is missing
        written = {**saved, **{str(n): body for n, body in parts.items() if body is not UNKNOWN}}
        if text != _joined(saved) or written != saved:
            rewritten[relative] = _joined(written)
    return rewritten


def workspace_files(workspace: Path) -> Optional[dict[str, bytes]]:
    """Every file of ``workspace`` (a graded snapshot: sources, the parts' record, no build),
    read without following a link; None when there are more than :data:`MAX_BYTES` times
    :data:`MAX_FILES` bytes or files."""
    found: dict[str, bytes] = {}
    total = 0
    for folder, _dirs, names in os.walk(workspace):
        for name in names:
            path = Path(folder) / name
            data = _read_bytes(path)
            if data is None:
                continue
            total += len(data)
            found[str(path.relative_to(workspace))] = data
            if total > MAX_BYTES * 8 or len(found) > MAX_FILES:
                return None
    return found


def _read_bytes(path: Path) -> Optional[bytes]:
    """A regular file's bytes, never through a link (None: not one, or too large)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(fd, 'rb') as file:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        data = file.read(MAX_BYTES + 1)
    return None if len(data) > MAX_BYTES else data
