"""What a graded notebook's ``%%part`` cells wrote, and the files something else changed.

Part of the judge (:mod:`ros2nb.judge`); grading only.  A notebook's package files are what
its ``%%part`` cells write (:func:`ros2nb.terminal.files.write_part`): the learner's answer
cells and the course's given parts, joined in number order.  Any other cell runs in the same
kernel, where the course's own code is at hand, and could write a file of the package itself
(the course's rule copied into the monitor's callback, say): what the judge would then grade
is not what the notebook shows.  So before grading, the judge compares each file with what
the submission's ``%%part`` cells say it holds, through the workspace's record of the parts
(``.ros2nb-parts.json``, which ``write_part`` keeps): a part a cell wrote must be there as the
cell wrote it, and the file must be its parts joined.  A file that is not is refused to every
check that would load, run or build it, with one line (:meth:`Session.file_subject`).

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
from pathlib import Path
from typing import Optional

from .. import course, nbmeta
from ..terminal.files import AUTHOR_MARKERS, PARTS_RECORD, PLACEHOLDER

#: The line of a check that would use a file the notebook's cells did not write as it is.
ALTERED = ('{name} is not what your notebook\'s %%part cells write (another cell changed it): '
           'the grader grades what the %%part cells write; run them in order and let no other '
           'cell write the file.')
#: Bytes read of one file at most (the package's files are small).
MAX_BYTES = 1_000_000


def _read(path: Path) -> Optional[str]:
    """A file's text, never through a link; None when it cannot be read."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW)
    except OSError:
        return None
    with os.fdopen(fd, 'rb') as file:
        data = file.read(MAX_BYTES + 1)
    return None if len(data) > MAX_BYTES else data.decode('utf-8', 'replace')


#: The package files an earlier notebook wrote, by what a notebook needs before it starts.
EARLIER = {'package': (course.SETUP_PY_FILE, course.SETUP_CFG_FILE),
           'publisher': (course.PUBLISHER_FILE,), 'subscriber': (course.SUBSCRIBER_FILE,)}
#: A part that may hold what an earlier notebook wrote (not compared).
UNKNOWN = None


def _earlier_files(submission: dict) -> set[str]:
    """The package files notebooks before this one wrote (its number read off a grade id)."""
    ids = [nbmeta.nbgrader_metadata(cell).get('grade_id') for cell in nbmeta.cells(submission)]
    numbers = [int(i[:2]) for i in ids if isinstance(i, str) and i[:2].isdigit()]
    steps = course.STEPS.get(numbers[0], ()) if numbers else ()
    return {file for step in steps for file in EARLIER.get(step, ())}


def cell_parts(submission: dict) -> dict[str, dict[int, Optional[str]]]:
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


def altered_files(submission: dict, workspace: Path) -> dict[str, str]:
    """The package files of ``workspace`` that are not what ``submission``'s ``%%part`` cells
    write: relative path -> the line a check that uses it fails with."""
    try:
        record = json.loads(_read(workspace / PARTS_RECORD) or '{}')
    except ValueError:
        record = {}
    altered = {}
    for relative, parts in cell_parts(submission).items():
        saved = record.get(relative, {}) if isinstance(record, dict) else {}
        saved = saved if isinstance(saved, dict) else {}
        text = _read(workspace / relative)
        joined = '\n\n'.join(str(saved[n]).rstrip('\n') for n in
                             sorted(saved, key=lambda n: int(n) if n.isdigit() else 0)) + '\n'
        if text is None:
            continue  # a file never written: each check says what is missing
        if text != joined or any(body is not UNKNOWN and saved.get(str(n)) != body
                                 for n, body in parts.items()):
            altered[relative] = ALTERED.format(name=Path(relative).name)
    return altered
