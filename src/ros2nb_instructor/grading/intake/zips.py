"""A platform's .zip of submissions, screened into learner folders before anything is graded.

Part of the grading, on the instructor's host.  Two layouts are taken in:

- one folder per learner at the archive's top (below one export folder, if all is in one):
  Moodle's "Download all submissions", nbgrader's own, a folder zipped by hand;
- Canvas's "Download Submissions" zip: every file at the top, named
  ``<sortable name>[_LATE]_<user id>_<file id>_<file name>`` (canvas-lms,
  ``lib/content_zipper.rb``: ``get_filename``, ``add_upload_submission``).  The roster's
  ``lms_id`` (Canvas's user ID) says whose file it is; without a roster, or for a user the
  roster does not list, the file is refused with one line.  Canvas writes every entry when it
  makes the zip, so a Canvas zip says nothing about when a notebook was handed in: its
  notebooks are graded by the late policy's ``without_time`` (:mod:`.deadlines`).

Archives inside the archive are never unpacked, a second copy of a notebook in one
learner's folder is named and not graded, and nothing below a learner's folder ever names
another learner.
"""

from __future__ import annotations

import datetime
import re
import struct
import zipfile
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Mapping, Optional

from .hand_in_times import TIMESTAMP, ZIP_ENTRY, parse_time
from .submissions import legal_name

#: Files a platform's download may hold that are archives themselves.
ARCHIVE_SUFFIXES = ('.zip', '.tar', '.tgz', '.gz', '.bz2', '.xz', '.7z', '.rar')
ARCHIVE_MAGIC = (b'PK\x03\x04', b'\x1f\x8b', b'BZh', b'\xfd7zXZ', b'7z\xbc\xaf', b'Rar!')
#: A file of Canvas's submissions zip: its sortable name, LATE mark, user and file ids, name.
CANVAS_NAME = re.compile(r'(?P<name>\w*?)(?P<late>_LATE)?_(?P<user>\d+)_(?P<file>\d+)_'
                         r'(?P<filename>[^/]+)')
#: Where a learner's Canvas user id is kept in the roster.
CANVAS_ID = 'lms_id'


@dataclass(frozen=True)
class CanvasFile:
    """One file of Canvas's submissions zip, as its name says.

    :ivar user: Canvas's user ID (the roster's ``lms_id``).
    :ivar late: Canvas marked the submission late (by Canvas's own due date).
    :ivar filename: the name the learner's file had.
    """

    user: str
    late: bool
    filename: str


def canvas_files(names: list[str]) -> Optional[dict[str, CanvasFile]]:
    """Each of ``names`` (a zip's files) as Canvas's submissions zip names it, or None when
    the zip is not one (a file in a folder, or a name of another shape)."""
    found = {}
    for name in names:
        match = CANVAS_NAME.fullmatch(name)
        if match is None:
            return None
        found[name] = CanvasFile(match['user'], bool(match['late']), match['filename'])
    return found or None


def _is_archive(name: str, head: bytes) -> bool:
    return name.lower().endswith(ARCHIVE_SUFFIXES) or head.startswith(ARCHIVE_MAGIC)


def _learner_paths(members: list[zipfile.ZipInfo],
                   canvas_learners: Optional[Mapping[str, str]],
                   lines: list[str]) -> list[tuple[zipfile.ZipInfo, tuple[str, ...]]]:
    """Each member with its path's parts below the archive's top level: the first part
    names the learner.

    In a Canvas zip the learner is the roster's for the file's user id (a file whose user
    the roster does not list is refused, with its line in ``lines``).  Otherwise one folder
    around everything that holds no file itself (a platform's export folder) is left out,
    and nothing below a learner's folder ever names another.
    """
    canvas = canvas_files([m.filename for m in members])
    if canvas is not None:
        paths: list[tuple[zipfile.ZipInfo, tuple[str, ...]]] = []
        for member in members:
            made = canvas[member.filename]
            learner = (canvas_learners or {}).get(made.user)
            if learner is None:
                lines.append(f'{member.filename}: Canvas user {made.user} is not in the roster '
                             f'({CANVAS_ID} column): add their row (ROSTER=roster.csv), not graded')
            else:
                paths.append((member, (learner, made.filename)))
        return paths
    paths = [(m, tuple(PurePosixPath(m.filename).parts)) for m in members]
    tops = {parts[0] for _m, parts in paths}
    if len(tops) == 1 and all(len(parts) >= 3 for _m, parts in paths):
        paths = [(m, parts[1:]) for m, parts in paths]
    return paths


def entry_time(member: zipfile.ZipInfo, zone: datetime.tzinfo) -> datetime.datetime:
    """When a zip entry was last written: its UTC time where the zip's maker added one (the
    extended timestamp field, 0x5455), else its local time, taken in ``zone``."""
    extra, at = member.extra, 0
    while at + 4 <= len(extra):
        tag, size = struct.unpack('<HH', extra[at:at + 4])
        if tag == 0x5455 and size >= 5 and extra[at + 4] & 1:
            seconds = struct.unpack('<I', extra[at + 5:at + 9])[0]
            return datetime.datetime.fromtimestamp(seconds, datetime.timezone.utc)
        at += 4 + size
    return datetime.datetime(*member.date_time, tzinfo=zone)


def screen_zip(archive: Path, cleaned: Path,
               times: Optional[dict[tuple[str, str], tuple[datetime.datetime, str]]] = None,
               zone: datetime.tzinfo = datetime.timezone.utc,
               canvas_learners: Optional[Mapping[str, str]] = None) -> list[str]:
    """Copy the members of a platform's .zip that may be graded into ``cleaned``, as
    ``LEARNER/NAME`` for nbgrader's ``zip_collect``.

    A learner is a folder at the archive's top level (below one export folder, if all is
    in one), or, in Canvas's submissions zip, the roster's learner of a file's Canvas user
    id; their notebooks may be anywhere under their folder: a folder deeper down
    (``mallory/alice/``, ``mallory/extracted/bob/``) is mallory's, never alice's or bob's.
    Refused, one line each: archives inside the archive (never unpacked), files outside any
    learner's folder, a second copy of a notebook in one learner's folder (the shallowest
    is graded), and a Canvas file whose user the roster does not list.

    :param times: filled with (learner's folder, file name) -> (when it was handed in, where
        that comes from): a ``timestamp.txt`` in the learner's folder, else the entry's time
        (:func:`entry_time`, a zone-less time taken in ``zone``); a Canvas zip fills none.
    :param canvas_learners: Canvas user id -> the learner's name (the roster's).
    :return: one line per refusal.
    :raises zipfile.BadZipFile: when ``archive`` is not a zip file.
    :raises TimeProblem: for a ``timestamp.txt`` whose time the grader does not read.
    """
    stamped: dict[str, datetime.datetime] = {}
    lines: list[str] = []
    with zipfile.ZipFile(archive) as source, zipfile.ZipFile(cleaned, 'w') as out:
        members = [m for m in source.infolist() if not m.is_dir()]
        canvas = canvas_files([m.filename for m in members]) is not None
        chosen: dict[tuple[str, str], zipfile.ZipInfo] = {}
        for member, parts in sorted(_learner_paths(members, canvas_learners, lines),
                                    key=lambda mp: (len(mp[1]), mp[1])):
            with source.open(member) as stream:
                head = stream.read(8)
            if parts[-1] == TIMESTAMP and len(parts) >= 2 and not canvas:
                text = source.read(member)[:200].decode('utf-8', 'replace')
                stamped.setdefault(parts[0], parse_time(text, f'{archive}: {member.filename}'))
            elif _is_archive(parts[-1], head):
                lines.append(f'{member.filename}: an archive inside the archive is not '
                             'unpacked; hand in the notebooks themselves')
            elif len(parts) < 2 or legal_name(parts[0]):
                lines.append(f'{member.filename}: not in a learner\'s folder at the top of '
                             'the archive')
            elif (parts[0], parts[-1]) in chosen:
                lines.append(f'{member.filename}: another copy of {parts[-1]} in '
                             f'{parts[0]}\'s folder; graded '
                             f'{chosen[parts[0], parts[-1]].filename}')
            else:
                chosen[parts[0], parts[-1]] = member
                out.writestr(f'{parts[0]}/{parts[-1]}', source.read(member))
    if times is not None and not canvas:
        for (learner, name), member in chosen.items():
            times[learner, name] = ((stamped[learner], TIMESTAMP) if learner in stamped
                                    else (entry_time(member, zone), ZIP_ENTRY))
    return lines

