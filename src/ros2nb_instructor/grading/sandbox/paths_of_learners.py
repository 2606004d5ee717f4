"""Paths a learner's code could have changed, read by the grader without following a link.

Runs on the instructor's host, as root while grading.  A sandbox may leave links anywhere it
could write (its home, its output folder): the grader opens what it reads back by file
descriptor with ``O_NOFOLLOW`` from a folder of its own, and checks with ``lstat`` that no
part of a path it copies from is a link.  It never writes where a sandbox could write.
"""

from __future__ import annotations

import errno
import os
import stat
import subprocess
from pathlib import Path


class NotARegularFile(OSError):
    """What the grader was to read is a link, a folder or a device, or is too large."""


def read_regular(folder: Path, name: str, limit: int) -> bytes:
    """The bytes of ``folder/name``, a regular file of at most ``limit`` bytes.

    :param folder: a folder the grader made (itself no link; opened with ``O_NOFOLLOW``).
    :param name: a file name in it (no ``/``).
    :param limit: most bytes read.
    :raises NotARegularFile: when the file is a link, not a regular file or too large.
    :raises OSError: when it is missing or unreadable.
    """
    if '/' in name:
        raise NotARegularFile(errno.EINVAL, f'{name}: not a file name')
    where = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW)
    try:
        try:
            fd = os.open(name, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK, dir_fd=where)
        except OSError as error:
            if error.errno == errno.ELOOP:
                raise NotARegularFile(errno.ELOOP, f'{name} is a link') from None
            raise
    finally:
        os.close(where)
    with os.fdopen(fd, 'rb') as stream:
        found = os.fstat(stream.fileno())
        if not stat.S_ISREG(found.st_mode):
            raise NotARegularFile(errno.EINVAL, f'{name} is not a regular file')
        if found.st_size > limit:
            raise NotARegularFile(errno.EFBIG, f'{name} is {found.st_size >> 20} MB')
        data = stream.read(limit + 1)
    if len(data) > limit:
        raise NotARegularFile(errno.EFBIG, f'{name} grew beyond {limit} bytes')
    return data


def real_folder_below(top: Path, path: Path) -> bool:
    """True when ``path`` is a folder under ``top`` and no part of it below ``top`` is a link.

    Race-free only while nothing of the learner's runs (the grader checks after a sandbox
    ended and before the next one starts).
    """
    try:
        parts = path.relative_to(top).parts
    except ValueError:
        return False
    here = top
    for part in parts:
        here = here / part
        try:
            if not stat.S_ISDIR(os.lstat(here).st_mode):
                return False
        except OSError:
            return False
    return True


def mount_capped(folder: Path, size_bytes: int) -> bool:
    """Put a tmpfs of ``size_bytes`` over ``folder`` (root only); True when mounted.

    What is written there counts against that size in total, whatever the number of files:
    a learner who fills it runs out of space there, and nobody else does.
    """
    if os.geteuid() != 0:
        return False
    done = subprocess.run(['mount', '-t', 'tmpfs', '-o',
                           f'size={size_bytes},mode=0711,nosuid,nodev', 'ros2nb-scratch',
                           str(folder)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return done.returncode == 0


def unmount(folder: Path) -> None:
    """Detach a tmpfs :func:`mount_capped` put there (its files go with it)."""
    subprocess.run(['umount', '-l', str(folder)], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)


def nearly_full(folder: Path, margin_bytes: int = 1 << 20) -> bool:
    """True when the file system of ``folder`` has less than ``margin_bytes`` free."""
    try:
        found = os.statvfs(folder)
    except OSError:
        return False
    return found.f_bavail * found.f_frsize < margin_bytes
