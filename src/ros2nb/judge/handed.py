"""The files a judge hands its subjects, those it takes back from them, and their folders.

Part of the judge (:mod:`ros2nb.judge`; :class:`~ros2nb.judge.session.Session` calls these
with its scratch folder, which the subjects may write, and the descriptor it opened on it
before any subject ran).  Every step goes through a descriptor of a folder the judge made,
never following a link, so a learner's thread that swaps a name for a link meanwhile makes
the judge write or read nothing it did not mean to.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import stat
import tempfile
from pathlib import Path
from typing import Iterator

from ..errors import CheckFailed
from ..temporary import owned_folder
from .subjects import home_and_tmp

#: Most bytes :func:`taken_back` copies out of one folder (an hour's bag is < 1 MiB).
MAX_TAKEN_BACK_BYTES = 64 << 20


def hand_over(scratch: Path, scratch_fd: int, prefix: str, files: dict[str, bytes]) -> Path:
    """A new folder in the scratch folder with ``files`` (a relative path, ``a/b.xml``, to
    its bytes) that the learner's code may read: the check's own inputs.

    Subjects may write the scratch folder, and a learner's thread may swap a name there for
    a link the moment it appears.  So every folder and file is made relative to the
    descriptor of a folder made here, opened without following links, and never over an
    entry that exists: the judge writes only into folders it made, whatever is at the path.

    :param prefix: the start of the new folder's name (a random part follows).
    :return: the new folder's path (what the learner's code is given).
    :raises CheckFailed: when a name the judge was making was taken over meanwhile (only
        the learner's own code, running beside the check, can do that).
    """
    name = f'{prefix}{secrets.token_hex(6)}'
    made: dict[tuple[str, ...], int] = {}  # folder (as parts) -> its descriptor

    def folder(parts: tuple[str, ...]) -> int:
        if parts not in made:
            parent = folder(parts[:-1]) if len(parts) > 1 else scratch_fd
            os.mkdir(parts[-1], 0o755, dir_fd=parent)
            made[parts] = os.open(parts[-1], os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW,
                                  dir_fd=parent)
        return made[parts]

    try:
        for relative, data in files.items():
            *parents, leaf = Path(relative).parts
            where = folder((name, *parents))
            fd = os.open(leaf, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644,
                         dir_fd=where)
            with os.fdopen(fd, 'wb') as out:
                out.write(data)
    except OSError as error:
        raise CheckFailed(f"The check's own folder {scratch / name} changed while the "
                          f'grader wrote it ({error.strerror}): something in your code '
                          'writes there; leave files you did not make alone.') from None
    finally:
        for fd in made.values():
            os.close(fd)
    return scratch / name


@contextlib.contextmanager
def taken_back(scratch: Path, scratch_fd: int, folder: Path) -> Iterator[Path]:
    """A copy, in a temporary folder of the judge's own (no subject sees it), of the files
    the learner's code left in ``folder``, a folder of the scratch folder: what the check
    then reads is what was there, never a file a link points to.

    Every step goes from the scratch folder's descriptor, without following links, and
    only regular files are copied (one level: a bag folder), at most
    :data:`MAX_TAKEN_BACK_BYTES` in all.

    :raises CheckFailed: for a link, a folder or anything else that is not a file, or for
        too many bytes.
    """
    relative = folder.relative_to(scratch)
    opened: list[int] = []
    private = owned_folder('ros2nb-taken-back-')
    try:
        where = scratch_fd
        for part in relative.parts:
            try:
                where = os.open(part, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW,
                                dir_fd=where)
            except OSError as error:
                raise CheckFailed(f'{folder} is not a folder ({error.strerror}): write '
                                  'your files there, not links.') from None
            opened.append(where)
        total = 0
        for name in sorted(os.listdir(where)):
            try:
                fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=where)
            except OSError as error:
                raise CheckFailed(f'{folder / name} cannot be read ({error.strerror}): '
                                  'the grader reads files there, not links.') from None
            with os.fdopen(fd, 'rb') as source:
                if not stat.S_ISREG(os.fstat(fd).st_mode):
                    raise CheckFailed(f'{folder / name} is not a file: the grader reads '
                                      'only the files you wrote there.')
                data = source.read(MAX_TAKEN_BACK_BYTES - total + 1)
            total += len(data)
            if total > MAX_TAKEN_BACK_BYTES:
                raise CheckFailed(f'{folder} holds more than {MAX_TAKEN_BACK_BYTES >> 20} '
                                  'MiB: the grader reads no more than that.')
            (private / name).write_bytes(data)
        yield private
    finally:
        for fd in opened:
            os.close(fd)
        shutil.rmtree(private, ignore_errors=True)


def own_folder(top: Path) -> Path:
    """A new folder in ``top`` for one subject or program: its working folder, with its home
    and temporary files.  Only it may write there (while grading, its sandbox shows it no
    other process's), and no later process reads it."""
    folder = Path(tempfile.mkdtemp(prefix='own-', dir=top))
    for part in home_and_tmp(folder):
        part.mkdir()
    return folder


def at_home(env: dict[str, str], folder: Path) -> dict[str, str]:
    """``env`` with its home and temporary folder in ``folder`` (what lay under its old home
    moves with it: ROS's logs, matplotlib's folder)."""
    home, tmp = home_and_tmp(folder)
    old = env.get('HOME', '')
    moved = {name: str(home) + value[len(old):] for name, value in env.items()
             if old and (value == old or value.startswith(old + os.sep))}
    return {**env, **moved, 'HOME': str(home), 'TMPDIR': str(tmp)}


@contextlib.contextmanager
def outbox(scratch: Path, open_now: list[Path], prefix: str) -> Iterator[Path]:
    """A new, empty folder in ``scratch``, kept in ``open_now`` while it is open (the session
    lets the processes it starts meanwhile write it), removed afterwards with what they put
    there."""
    folder = Path(tempfile.mkdtemp(prefix=prefix, dir=scratch))
    folder.chmod(0o755)
    open_now.append(folder)
    try:
        yield folder
    finally:
        open_now.remove(folder)
        shutil.rmtree(folder, ignore_errors=True)
