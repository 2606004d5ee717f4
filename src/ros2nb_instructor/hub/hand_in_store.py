"""The hand-in store of the classroom server: what each learner handed in, when, and their feedback.

Runs on the classroom server, as root: the hand-in service writes it
(:mod:`.hand_in_service`), ``make hub-collect`` reads it (:mod:`.collect`), ``make
hub-feedback`` releases feedback into it (:mod:`.release`).  Learners never reach it: the
folder is root's alone (mode 700), and the service takes a learner's name from the hub,
never from the request.  Layout::

    <store>/<learner>/<NN-title>.ipynb          the notebook as last handed in
    <store>/<learner>/handed-in.json            notebook -> the service's time of that hand-in
    <store>/<learner>/feedback/<NN-title>.html  the feedback pages released to the learner
    <store>/hand-ins.log                        one line per hand-in, for the instructor

The time of a hand-in is the service's clock when the notebook was stored, in UTC; the
record is the grader's ``handed-in.json`` (:mod:`ros2nb_instructor.grading.intake.hand_in_times`).
Every file is written whole, then renamed into place: a reader never sees half of one.
"""

from __future__ import annotations

import datetime
import json
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from ..grading.intake.hand_in_times import HANDED_IN, read_record, record_text
from ..paths import NOTEBOOKS

#: A hub user name the store keeps a folder for (the names ``make grade`` takes as folders).
LEARNER = re.compile(r'[A-Za-z0-9][A-Za-z0-9_.-]*')
#: A notebook's size limit: a course notebook with its outputs is well under 1 MB.
MAX_NOTEBOOK_BYTES = 20 * 1024 * 1024
#: The folder of a learner's released feedback pages.
FEEDBACK = 'feedback'
#: The instructor's log of every hand-in.
LOG = 'hand-ins.log'


class Refused(ValueError):
    """A hand-in or page the store will not keep; the message says why, in one line."""


@dataclass(frozen=True)
class Stored:
    """One hand-in, as the store keeps it.

    :ivar at: the service's time of it (UTC).
    :ivar saved: the handed-in file's own modification time, as the learner's server said.
    """

    learner: str
    notebook: str
    at: datetime.datetime
    saved: Optional[datetime.datetime] = None


def course_notebooks() -> list[str]:
    """The course's notebooks (``NN-title``), in order."""
    return sorted(p.stem for p in NOTEBOOKS.glob('[0-9][0-9]-*.ipynb'))


def _write(path: Path, data: bytes) -> None:
    """``data`` at ``path``, whole or not at all (a temporary file renamed into place)."""
    path.parent.mkdir(mode=0o700, parents=True, exist_ok=True)
    fd, temporary = tempfile.mkstemp(dir=path.parent, prefix='.incoming-')
    try:
        with os.fdopen(fd, 'wb') as stream:
            stream.write(data)
        os.replace(temporary, path)
    except BaseException:
        os.unlink(temporary)
        raise


class Store:
    """The store under ``root`` (created root's alone, mode 700)."""

    def __init__(self, root: Path) -> None:
        self.root = root
        root.mkdir(mode=0o700, parents=True, exist_ok=True)
        root.chmod(0o700)
        self.notebooks = course_notebooks()

    def folder(self, learner: str) -> Path:
        """The learner's folder in the store.

        :raises Refused: for a name ``make grade`` cannot take as a folder.
        """
        if not LEARNER.fullmatch(learner):
            raise Refused(f'{learner!r} is not a user name the store keeps')
        return self.root / learner

    def learners(self) -> list[str]:
        """Every learner who handed something in."""
        return sorted(p.name for p in self.root.iterdir()
                      if p.is_dir() and LEARNER.fullmatch(p.name))

    def hand_in(self, learner: str, notebook: str, data: bytes,
                saved: Optional[datetime.datetime] = None) -> Stored:
        """Keep ``data`` as ``learner``'s ``notebook``, with the time now (the service's
        clock), replacing an earlier hand-in of it.

        :raises Refused: for a notebook the course does not have, a file too large, or one
            that is not a notebook's JSON.
        """
        if notebook not in self.notebooks:
            raise Refused(f'{notebook!r} is no notebook of the course')
        if len(data) > MAX_NOTEBOOK_BYTES:
            raise Refused(f'the notebook is {len(data) >> 20} MB, more than '
                          f'{MAX_NOTEBOOK_BYTES >> 20} MB: clear large outputs, hand it in again')
        try:
            cells = json.loads(data).get('cells')
        except (ValueError, AttributeError):
            cells = None
        if not isinstance(cells, list):
            raise Refused('that is not a notebook (no JSON with cells): save the notebook '
                          'and hand it in again')
        at = datetime.datetime.now(datetime.timezone.utc)
        folder = self.folder(learner)
        _write(folder / f'{notebook}.ipynb', data)
        times = self.handed_in(learner)
        times[notebook] = at
        _write(folder / HANDED_IN, record_text(times).encode())
        with open(self.root / LOG, 'a', encoding='utf-8') as log:
            log.write(f'{at.isoformat()} {learner} {notebook} {len(data)} bytes'
                      f'{f" saved {saved.isoformat()}" if saved else ""}\n')
        return Stored(learner, notebook, at, saved)

    def handed_in(self, learner: str) -> dict[str, datetime.datetime]:
        """``learner``'s notebooks and when each was last handed in (by the service)."""
        record = self.folder(learner) / HANDED_IN
        return read_record(record, self.notebooks) if record.is_file() else {}

    def release(self, learner: str, notebook: str, page: bytes) -> None:
        """Make ``page`` the feedback ``learner`` sees for ``notebook``.

        :raises Refused: for a notebook the course does not have.
        """
        if notebook not in self.notebooks:
            raise Refused(f'{notebook!r} is no notebook of the course')
        _write(self.folder(learner) / FEEDBACK / f'{notebook}.html', page)

    def feedback(self, learner: str) -> list[str]:
        """The notebooks whose feedback was released to ``learner``."""
        folder = self.folder(learner) / FEEDBACK
        return [n for n in self.notebooks if (folder / f'{n}.html').is_file()]

    def page(self, learner: str, notebook: str) -> Optional[bytes]:
        """``learner``'s feedback page of ``notebook`` (None: none released, or no such
        notebook: the name is checked against the course's, never joined as given)."""
        if notebook not in self.notebooks:
            return None
        path = self.folder(learner) / FEEDBACK / f'{notebook}.html'
        return path.read_bytes() if path.is_file() else None
