"""Temporary folders the course makes, each named for the process that owns it, and swept
once that process no longer runs.

A kernel, a judge or a grader that is killed (a kernel restart, the Stop of a slow check,
SIGKILL, the OOM killer) cannot remove what it made.  Every temporary folder of the course is
``<prefix><pid>-<random>`` in the temporary folder (or one given), and whoever next makes one
with that prefix first removes those whose process is gone (:func:`sweep_left_behind`).  No
mention of ROS here.
"""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import tempfile
from pathlib import Path
from typing import Callable, Optional

from .patience import psutil_module


def owned_folder(prefix: str, parent: Optional[Path] = None) -> Path:
    """A new folder ``<parent>/<prefix><pid>-<random>`` of this process (``parent``: the
    temporary folder by default), made after those of ``prefix`` that no process owns any
    more were removed.

    :param prefix: what its name starts with, e.g. ``'ros2nb-judge-'``.
    :raises OSError: when it cannot be made.
    """
    sweep_left_behind(prefix, parent)
    return Path(tempfile.mkdtemp(prefix=f'{prefix}{os.getpid()}-', dir=parent))


def temporary_folder(name: str) -> tempfile.TemporaryDirectory[str]:
    """A temporary folder of this kernel's for files a notebook makes (bags, a parameters
    file): removed when the kernel ends, and, when the kernel was killed instead, by the next
    kernel that asks for one.  Use its ``name`` (a path string), as of any
    :class:`tempfile.TemporaryDirectory`.

    Introduced in ``08-parameters.ipynb`` (``ros2nb.temporary_folder('params')``).

    :param name: a word for what it holds, e.g. ``'bags'`` (it names the folder).
    :raises OSError: when it cannot be made.
    """
    prefix = f'ros2nb-{name}-'
    sweep_left_behind(prefix)
    return tempfile.TemporaryDirectory(prefix=f'{prefix}{os.getpid()}-')


def sweep_left_behind(prefix: str, where: Optional[Path] = None,
                      unmount: Optional[Callable[[Path], None]] = None) -> list[Path]:
    """Remove the folders :func:`owned_folder` made for processes that no longer run.

    A folder is left alone when it is a link or not this user's, when its name carries no
    process id, or when that process runs and started before the folder last changed.

    :param where: the folder to look in (default: the temporary folder).
    :param unmount: detaches a mount below a folder before it is removed, deepest first (the
        grader's tmpfs mounts; None: mounts are not looked for).
    :returns: the folders removed.
    """
    top = Path(os.path.realpath(where or tempfile.gettempdir()))
    swept = []
    for folder in sorted(top.glob(f'{prefix}*')):
        owner = folder.name[len(prefix):].split('-', 1)[0]
        try:
            found = os.lstat(folder)
        except OSError:
            continue
        if not owner.isdigit() or not stat.S_ISDIR(found.st_mode) \
                or found.st_uid != os.geteuid() or running_since(int(owner), found.st_ctime):
            continue
        if unmount is not None:
            below = [Path(p.mountpoint) for p in psutil_module().disk_partitions(all=True)
                     if Path(p.mountpoint).is_relative_to(folder)]
            for mount in sorted(below, key=lambda path: len(path.parts), reverse=True):
                unmount(mount)
        shutil.rmtree(folder, ignore_errors=True)
        swept.append(folder)
    return swept


def sweep_all(where: Optional[Path] = None) -> list[Path]:
    """Remove every folder of the course's (``ros2nb-...-<pid>-<random>``) in ``where`` (the
    temporary folder by default) whose process no longer runs, whatever its prefix: what
    ``make test`` does last, for the processes it ended (a kernel nbval stopped) or that were
    killed, and whose folder no later one of their kind swept.  Folders of processes that
    still run, and the machine's domain locks (``ros2nb-domains``), stay.

    :returns: the folders removed.
    """
    top = Path(os.path.realpath(where or tempfile.gettempdir()))
    swept = []
    for folder in sorted(top.glob('ros2nb-*')):
        parts = folder.name.split('-')
        if len(parts) >= 3 and parts[-2].isdigit():
            swept += sweep_left_behind(folder.name[:-len('-'.join(parts[-2:]))], top,
                                       _unmounted)
    return swept


def _unmounted(folder: Path) -> None:
    """Detach a mount below a folder left behind (a grader's tmpfs: it was root)."""
    subprocess.run(['umount', '-l', str(folder)], stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)


def running_since(pid: int, since: float) -> bool:
    """True when process ``pid`` runs and started by ``since`` (seconds since the epoch),
    give or take a second: not a later process given a dead one's id, nor a killed one
    its parent has not reaped yet."""
    psutil = psutil_module()
    try:
        process = psutil.Process(pid)
        return process.create_time() <= since + 1.0 and \
            process.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False
