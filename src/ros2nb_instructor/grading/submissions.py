"""Who handed in what: learner folders, their notebook files, and a platform's .zip.

Part of the grading (:mod:`ros2nb_instructor.grading`), on the instructor's host.  Every learner folder with a legal name is graded or listed with
the reason; every file is graded or named in a note; nothing is skipped without a word.
"""

from __future__ import annotations

import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path, PurePosixPath
from typing import Optional

import nbformat

#: Characters nbgrader cannot have in a student id (it builds glob patterns from ids).
_GLOB = re.compile(r'[*?\[\]{}\\]')
#: What browsers and file managers add to a name they save twice.
_COPY = re.compile(r'^(?P<stem>.+?)(?: ?\(\d+\)| - Copy(?: \(\d+\))?| copy(?: \d+)?|-Copy\d*)$')
#: Files a platform's download may hold that are archives themselves.
ARCHIVE_SUFFIXES = ('.zip', '.tar', '.tgz', '.gz', '.bz2', '.xz', '.7z', '.rar')
ARCHIVE_MAGIC = (b'PK\x03\x04', b'\x1f\x8b', b'BZh', b'\xfd7zXZ', b'7z\xbc\xaf', b'Rar!')


@dataclass
class Learner:
    """One learner's submission and what happened to it.

    :ivar name: the folder's name, as the instructor knows the learner (CSV, feedback).
    :ivar id: the id nbgrader knows the learner by (the name, unless nbgrader cannot take it).
    :ivar files: notebook (e.g. ``03-write-the-publisher``) -> the file graded for it.
    :ivar notes: notebook (or ``_folder``) -> what happened, in a sentence.
    """

    name: str
    id: str
    files: dict[str, Path] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)

    def note(self, key: str, text: str) -> None:
        self.notes[key] = f'{self.notes[key]}; {text}' if key in self.notes else text


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


def find_learners(folder: Path, notebooks: list[str]) -> tuple[list[Learner], list[str]]:
    """One Learner per learner folder; also the lines about entries that are not graded.

    :return: the learners (sorted by name) and one line per entry refused.
    """
    learners, refused, taken = [], [], set()
    for number, entry in enumerate(sorted(folder.iterdir(), key=lambda p: p.name), start=1):
        if not entry.is_dir() or entry.is_symlink():
            refused.append(f'{entry.name!r}: not a learner folder (only folders of notebooks '
                           'are graded)')
            continue
        problem = legal_name(entry.name)
        if problem:
            refused.append(f'{entry.name!r}: {problem}, not graded')
            continue
        learner = Learner(entry.name, _student_id(entry.name, number, taken))
        if learner.id != learner.name:
            learner.note('_folder', f'graded under the id {learner.id} (nbgrader cannot use '
                                    'the folder name itself)')
        candidates: dict[str, list[Path]] = {}
        for path in sorted(entry.iterdir()):
            notebook = notebook_for(path.name, notebooks) if path.is_file() else None
            if notebook is None:
                learner.note('_folder', f'{path.name} is not one of the course notebooks')
            else:
                candidates.setdefault(notebook, []).append(path)
        for notebook, paths in candidates.items():
            exact = [p for p in paths if p.stem == notebook]
            chosen = exact[0] if exact else max(paths, key=lambda p: p.stat().st_mtime)
            learner.files[notebook] = chosen
            if chosen.stem != notebook:
                learner.note(notebook, f'graded {chosen.name} as {notebook}.ipynb')
            others = [p.name for p in paths if p != chosen]
            if others:
                learner.note(notebook, f'also handed in {", ".join(others)}: not graded '
                                       f'(graded {chosen.name})')
        learners.append(learner)
    return learners, refused


def _is_archive(name: str, head: bytes) -> bool:
    return name.lower().endswith(ARCHIVE_SUFFIXES) or head.startswith(ARCHIVE_MAGIC)


def screen_zip(archive: Path, cleaned: Path) -> list[str]:
    """Copy the members of a platform's .zip that may be graded into ``cleaned``.

    Refused, one line each: archives inside the archive (they are never unpacked, so
    nothing inside one can claim to be another learner), and learners who appear in two
    different places of the archive (which copy is theirs cannot be told); everything
    else is copied as it is, for nbgrader's ``zip_collect``.

    :return: one line per refusal.
    :raises zipfile.BadZipFile: when ``archive`` is not a zip file.
    """
    lines = []
    with zipfile.ZipFile(archive) as source:
        members = [m for m in source.infolist() if not m.is_dir()]
        places: dict[str, set[str]] = {}
        for member in members:
            path = PurePosixPath(member.filename)
            if path.suffix == '.ipynb' and len(path.parts) >= 2:
                places.setdefault(path.parts[-2], set()).add(str(path.parent))
        twice = {learner for learner, where in places.items() if len(where) > 1}
        for learner in sorted(twice):
            lines.append(f'{learner}: appears in {len(places[learner])} places of the archive '
                         f'({", ".join(sorted(places[learner]))}); not graded, send one copy')
        with zipfile.ZipFile(cleaned, 'w') as out:
            for member in members:
                path = PurePosixPath(member.filename)
                with source.open(member) as stream:
                    head = stream.read(8)
                if _is_archive(path.name, head):
                    lines.append(f'{member.filename}: an archive inside the archive is not '
                                 'unpacked; hand in the notebooks themselves')
                    continue
                if len(path.parts) >= 2 and path.parts[-2] in twice:
                    continue
                out.writestr(member, source.read(member))
    return lines


def readable(path: Path) -> Optional[str]:
    """Why a handed-in file cannot be graded, or None when it is a valid notebook."""
    if path.stat().st_size == 0:
        return 'the file is empty'
    try:
        nbformat.validate(nbformat.read(path, as_version=4))
    except Exception as error:  # json, schema or encoding errors alike
        return f'the file is not a valid notebook ({type(error).__name__})'
    return None
