"""Who handed in what, and when: learner folders, their notebook files, their hand-in times.

Part of the grading (:mod:`ros2nb_instructor.grading`), on the instructor's host.  Every
learner folder with a legal name is graded or listed with the reason; every file is
graded or named in a note; nothing is skipped without a word.  A platform's .zip becomes
such folders first (:mod:`.zips`).
"""

from __future__ import annotations

import datetime
import os
import re
import stat
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import nbformat
from ros2nb.outcomes import CheckOutcome

from .hand_in_times import HANDED_IN, TIMESTAMP, TimeProblem, read_record, read_timestamp
from .mistakes import Mistakes

#: Characters nbgrader cannot have in a student id: it builds glob patterns from ids, and
#: reads a list of ids to leave out as one comma-separated string.
_GLOB = re.compile(r'[*?\[\]{}\\,]')
#: What browsers and file managers add to a name they save twice (and Canvas to a file
#: handed in again: ``NN-title-1.ipynb``).
_COPY = re.compile(r'^(?P<stem>.+?)'
                   r'(?: ?\(\d+\)| - Copy(?: \(\d+\))?| copy(?: \d+)?|-Copy\d*|-\d+)$')


@dataclass
class Learner:
    """One learner's submission and what happened to it.

    :ivar name: the folder's name, as the instructor knows the learner (CSV, feedback).
    :ivar id: the id nbgrader knows the learner by (the name, unless nbgrader cannot take it).
    :ivar files: notebook (e.g. ``03-write-the-publisher``) -> the file graded for it.
    :ivar notes: notebook (or ``_folder``) -> what happened, in a sentence.
    :ivar results: notebook -> the judge's outcomes (grade id ->
        :class:`~ros2nb.outcomes.CheckOutcome`).
    :ivar flags: notebook -> the judge's flags (code that reaches into the course,
        :mod:`ros2nb.judge.flags`), shown on the feedback page and in the report's notes.
    :ivar handed_in: notebook -> when the submission says it was handed in (aware), and
        where that comes from (:mod:`.hand_in_times`).
    :ivar late: notebook -> its raw score, late penalty and why (:mod:`.deadlines`), once
        nbgrader scored it.
    """

    name: str
    id: str
    files: dict[str, Path] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)
    results: dict[str, dict[str, CheckOutcome]] = field(default_factory=dict)
    flags: dict[str, list[str]] = field(default_factory=dict)
    handed_in: dict[str, tuple[datetime.datetime, str]] = field(default_factory=dict)
    late: dict[str, Any] = field(default_factory=dict)

    @property
    def shown(self) -> str:
        """The folder's name as text (:func:`shown`): what the CSV, notes and pages say."""
        return shown(self.name)

    def note(self, key: str, text: str) -> None:
        self.notes[key] = f'{self.notes[key]}; {text}' if key in self.notes else text


def shown(name: str) -> str:
    """A file or folder name as text that can be written anywhere: bytes of it that are not
    UTF-8 (a zip made on Windows in cp1252, unpacked here) become ``\\xNN``, the rest stays.

    The name on disk is never changed: the grader reads and writes the learner's files by
    the name itself (``os.fsencode`` gives back its bytes); only what it says uses this.
    Introduced for the grading (``docs/instructors.md``), never in a notebook.
    """
    return os.fsencode(name).decode('utf-8', 'backslashreplace')


def legal_name(name: str) -> Optional[str]:
    """None when ``name`` can be a learner's folder name, else why not."""
    if name in ('.', '..') or name.startswith('.'):
        return 'a hidden folder (its name starts with ".")'
    if '/' in name or '\x00' in name or not name.strip():
        return 'not a usable folder name'
    return None


def _student_id(name: str, number: int, taken: set[str]) -> str:
    """nbgrader's id for a learner: the folder name when nbgrader can use it."""
    usable = not _GLOB.search(name) and name == name.strip() and name.isprintable()
    candidate = name if usable else f'learner-{number:03d}'
    while candidate in taken:
        candidate += '-'
    taken.add(candidate)
    return candidate


def notebook_for(filename: str, notebooks: list[str]) -> Optional[str]:
    """The course notebook a file is, allowing for the names browsers give copies.

    ``03-write-the-publisher (1).ipynb`` and ``03-write-the-publisher-Copy1.ipynb`` are
    ``03-write-the-publisher``; ``notes.ipynb`` is none.
    """
    if not filename.endswith('.ipynb'):
        return None
    stem = filename[:-len('.ipynb')]
    if stem in notebooks:
        return stem
    match = _COPY.match(stem)
    return match.group('stem') if match and match.group('stem') in notebooks else None


def _times(entry: Path, learner: 'Learner', notebooks: list[str]) -> None:
    """The hand-in times ``entry`` says: its ``handed-in.json`` per notebook, else its nbgrader
    ``timestamp.txt`` for every notebook of the folder (:mod:`.hand_in_times`).

    :raises TimeProblem: for a time either file holds that the grader does not read.
    """
    stamp = entry / TIMESTAMP
    if not stamp.is_symlink() and stamp.is_file():
        when = read_timestamp(stamp)
        learner.handed_in.update({n: (when, TIMESTAMP) for n in notebooks})
    record = entry / HANDED_IN
    if not record.is_symlink() and record.is_file():
        learner.handed_in.update({n: (t, HANDED_IN)
                                  for n, t in read_record(record, notebooks).items()})


class SubmissionProblem(Mistakes):
    """Submissions the grader will not guess at: ``lines`` holds one line per mistake (a
    hand-in time it does not read), each saying what to write; nothing is graded."""


def find_learners(folder: Path, notebooks: list[str]) -> tuple[list[Learner], list[str]]:
    """One Learner per learner folder; also the lines about entries that are not graded.
    A folder's ``handed-in.json`` says when each notebook was handed in, its nbgrader
    ``timestamp.txt`` when all were (:func:`_times`).

    :return: the learners (sorted by name) and one line per entry refused.
    :raises SubmissionProblem: one line per hand-in time the grader does not read.
    """
    learners, refused, taken, problems = [], [], set[str](), []
    for number, entry in enumerate(sorted(folder.iterdir(), key=lambda p: p.name), start=1):
        if entry.is_symlink():
            refused.append(f'"{shown(entry.name)}": a link, not a learner folder (links are '
                           'not followed: put the learner\'s folder itself there)')
            continue
        if not entry.is_dir():
            refused.append(f'"{shown(entry.name)}": not a learner folder (only folders of '
                           'notebooks are graded)')
            continue
        problem = legal_name(entry.name)
        if problem:
            refused.append(f'"{shown(entry.name)}": {problem}, not graded')
            continue
        learner = Learner(entry.name, _student_id(entry.name, number, taken))
        if learner.id != learner.name:
            learner.note('_folder', f'graded under the id {learner.id} (nbgrader cannot use '
                                    f'the folder name {learner.shown} itself)')
        candidates: dict[str, list[Path]] = {}
        try:
            _times(entry, learner, notebooks)
        except TimeProblem as problem:
            problems.append(str(problem))
        for path in sorted(entry.iterdir()):
            if path.name in (TIMESTAMP, HANDED_IN):
                continue
            if path.is_symlink():
                learner.note('_folder', f'{shown(path.name)} is a link (links are not followed: '
                                        'hand in the notebook itself); not graded')
                continue
            notebook = notebook_for(path.name, notebooks) if path.is_file() else None
            if notebook is None:
                learner.note('_folder', f'{shown(path.name)} is not one of the course notebooks')
            else:
                candidates.setdefault(notebook, []).append(path)
        for notebook, paths in candidates.items():
            exact = [p for p in paths if p.stem == notebook]
            chosen = exact[0] if exact else max(paths, key=lambda p: p.lstat().st_mtime)
            learner.files[notebook] = chosen
            if chosen.stem != notebook:
                learner.note(notebook, f'graded {shown(chosen.name)} as {notebook}.ipynb')
            others = [shown(p.name) for p in paths if p != chosen]
            if others:
                learner.note(notebook, f'also handed in {", ".join(others)}: not graded '
                                       f'(graded {shown(chosen.name)})')
        learners.append(learner)
    if problems:
        raise SubmissionProblem(problems)
    return learners, refused


#: Largest notebook file read (a notebook with a few plots is a few MB).
MAX_SUBMISSION_BYTES = 400_000_000


def readable(path: Path) -> tuple[Optional[nbformat.NotebookNode], Optional[str]]:
    """A handed-in file as an nbformat 4 notebook, or None and why it cannot be graded.

    Read without following a link; an nbformat 3 notebook is converted (by nbformat).
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as error:
        return None, f'the file could not be read ({error.strerror})'
    with os.fdopen(fd, 'rb') as stream:
        size = os.fstat(stream.fileno()).st_size
        if not stat.S_ISREG(os.fstat(stream.fileno()).st_mode):
            return None, 'not a regular file'
        if size == 0:
            return None, 'the file is empty'
        if size > MAX_SUBMISSION_BYTES:
            return None, (f'the file is {size >> 20} MB, more than the '
                          f'{MAX_SUBMISSION_BYTES // 1_000_000} MB a notebook may be: remove '
                          'large pasted images or outputs and hand it in again')
        data = stream.read(MAX_SUBMISSION_BYTES + 1)
    try:
        nb = nbformat.reads(data.decode('utf-8'), as_version=4)
        nbformat.validate(nb)
    except Exception as error:  # json, schema or encoding errors alike
        return None, f'the file is not a valid notebook ({type(error).__name__})'
    return nb, None
