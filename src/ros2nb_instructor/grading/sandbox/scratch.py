"""A learner's folders while grading: outside the repository, shared by their notebooks in order.

Runs on the instructor's host.  Each notebook's judge gets a snapshot of the workspace as
that notebook left it, copied without following a link.  The folders a sandbox may write
(the learner's home, a run's output folder, a judge's folder) are each a size-capped tmpfs
when the grader is root, so one learner filling the disk fills only their own space.  The
grader writes only in folders of its own, which no sandbox can write.  A grader killed
before it could unmount them leaves its folder behind, mounts and all, until the next grader
on the machine starts (:func:`grading_folder`).
"""

from __future__ import annotations

import contextlib
import os
import shutil
import stat
import sys
import tempfile
import threading
from pathlib import Path
from typing import Callable, Iterator, Optional


from ros2nb import temporary
from ros2nb.terminal.workspace import WORKSPACE_NAME

from ..intake.submissions import Learner
from .paths_of_learners import mount_capped, nearly_full, real_folder_below, unmount

MiB = 1 << 20
#: Bytes a learner's home (their workspace and everything their notebooks write) may hold.
HOME_BYTES = 1024 * MiB
#: Bytes a notebook's run may leave in its output folder (the executed notebook, its status).
RUN_OUT_BYTES = 64 * MiB
#: Bytes a judge and its subjects may write in the judge's folder.
JUDGE_BYTES = 256 * MiB
#: What a note says when a learner filled their space.
OUT_OF_SPACE = ('it ran out of scratch space ({} MB for a learner\'s files); what it wrote '
                'after that was lost')


@contextlib.contextmanager
def grading_folder(prefix: str) -> Iterator[Path]:
    """A folder of this grader's in the temporary directory, for its learners' scratch.

    Its name carries this process's id: a grader killed before it could clean up (SIGKILL,
    the OOM killer, a Dask worker lost mid-class) leaves its folder and its tmpfs mounts
    behind, and the next grader on this machine that uses ``prefix`` removes them first
    (:func:`sweep_left_behind`).

    :param prefix: what the folder's name starts with, e.g. ``'ros2nb-grading-'``.
    """
    sweep_left_behind(prefix)
    with tempfile.TemporaryDirectory(prefix=f'{prefix}{os.getpid()}-') as folder:
        Path(folder).chmod(0o711)  # the sandboxes' own user may pass, nobody may list
        yield Path(folder)


def sweep_left_behind(prefix: str, where: Optional[Path] = None) -> list[Path]:
    """Remove the folders :func:`grading_folder` made for graders that no longer run, each
    with the tmpfs mounts below it (deepest first): :func:`ros2nb.temporary.sweep_left_behind`.

    :param where: the folder to look in (default: the temporary directory).
    :returns: the folders removed.
    """
    return temporary.sweep_left_behind(prefix, where, unmount)


class Scratch:
    """One learner's folders outside the repository, shared by their notebooks in order."""

    def __init__(self, root: Path, learner: Learner) -> None:
        self.top = Path(tempfile.mkdtemp(prefix='learner-', dir=root))
        self.home = self.top / 'home'
        self.workspace = self.home / 'workspace' / WORKSPACE_NAME
        self._mounts: list[Path] = []
        self._lock = threading.Lock()  # a judge's thread releases its snapshot
        self.top.chmod(0o711)  # the sandboxes' own user may pass, nobody may list
        self.home = self._capped('home', HOME_BYTES)

    def _capped(self, name: str, size_bytes: int) -> Path:
        """A fresh folder of the grader's in ``top``: a tmpfs of ``size_bytes`` when root."""
        folder = self.top / name
        folder.mkdir()
        if mount_capped(folder, size_bytes):
            with self._lock:
                self._mounts.append(folder)
        return folder

    def home_full(self) -> bool:
        """True when the learner's home has (almost) no space left."""
        return nearly_full(self.home)

    def run_folders(self, notebook: str) -> tuple[Path, Path]:
        """A folder with the notebook to run (the grader's, read-only inside) and its
        output folder."""
        given = self.top / f'run-in-{notebook}'
        given.mkdir()
        given.chmod(0o755)
        return given, self._capped(f'run-out-{notebook}', RUN_OUT_BYTES)

    def remove(self) -> None:
        """Remove every folder of the learner's, unmounting what was mounted, never
        following a link."""
        with self._lock:
            for folder in reversed(self._mounts):
                unmount(folder)
            self._mounts = []
        shutil.rmtree(self.top, ignore_errors=True)

    def snapshot(self, notebook: str) -> Path:
        """A copy of the workspace as ``notebook``'s run left it, for that notebook's judge.

        The judge reads the copy while the learner's next notebook runs (and changes the
        workspace).  Links are copied as links, never followed; colcon's ``build``,
        ``install`` and ``log`` and anything that is not a file, folder or link stay behind
        (the judge builds a package of its own when it needs one).
        """
        # On a tmpfs of the home's size: the copy counts against a cap, never the host's
        # disk, and :meth:`release` frees it once the judge is done with it.
        target = self._capped(f'workspace-{notebook}', HOME_BYTES) / WORKSPACE_NAME
        target.parent.chmod(0o755)
        # No part of the path below the home may be a link: a home/workspace linked to the
        # host would hand the judge (and so the learner's code in it) the host's files.
        if real_folder_below(self.home, self.workspace):
            shutil.copytree(self.workspace, target, symlinks=True, ignore=_not_for_the_judge(
                self.workspace))
        else:
            target.mkdir()  # notebooks 00 and 01 make none
        target.chmod(0o755)
        return target

    def release(self, snapshot: Path) -> None:
        """Free a :meth:`snapshot` (its judge has ended): unmounted and removed at once, so
        a learner holds at most the snapshots still being judged."""
        folder = snapshot.parent
        with self._lock:
            if folder in self._mounts:
                self._mounts.remove(folder)
                unmount(folder)
        shutil.rmtree(folder, ignore_errors=True)

    def judge_folders(self, notebook: str) -> tuple[Path, Path]:
        """A fresh folder of the judge's inputs (read-only inside), and its writable folder."""
        given = self.top / f'judge-in-{notebook}'
        given.mkdir()
        given.chmod(0o755)  # the judge's sandbox user reads the given files
        scratch = self._capped(f'judge-{notebook}', JUDGE_BYTES)
        scratch.chmod(0o711)
        return given, scratch


def _not_for_the_judge(workspace: Path) -> Callable[[str, list[str]], list[str]]:
    """``copytree``'s ignore function for :meth:`Scratch.snapshot`."""
    def ignored(folder: str, names: list[str]) -> list[str]:
        skip = {'build', 'install', 'log'} if Path(folder) == workspace else set()
        for name in names:
            mode = os.lstat(os.path.join(folder, name)).st_mode
            if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode) or stat.S_ISLNK(mode)):
                skip.add(name)  # a FIFO or device would block or mislead the copy
        return sorted(skip)
    return ignored


#: What the ROS 2 wheels' bootstrapper (a ``.pth`` file of the venv) sets before it runs a
#: new Python process again, once, from the start: the libraries' path, and the mark that it
#: was done.  The grader's own process has both; handed on, they spare each sandboxed runner
#: and judge that second start (docs/decisions.md).
ROS_WHEELS_ENV = ('LD_LIBRARY_PATH', '_ROS_WHEELS_BOOTSTRAP_COMPLETE')


def sandbox_env(home: Path, **extra: str) -> dict[str, str]:
    """The environment inside a sandbox: everything in the learner's home, grading mode.

    It carries the ROS 2 wheels' bootstrap of the grader's process when there is one
    (:data:`ROS_WHEELS_ENV`), so that the runner and the judge each start once, not twice.
    """
    venv_bin = str(Path(sys.executable).parent)
    bootstrapped = ({name: os.environ.get(name, '') for name in ROS_WHEELS_ENV}
                    if os.environ.get('_ROS_WHEELS_BOOTSTRAP_COMPLETE') else {})
    return {**bootstrapped,
            'PATH': f'{venv_bin}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
            'PYTHONUNBUFFERED': '1', 'ROS2NB_GRADING': '1', 'TMPDIR': '/tmp',
            'IPYTHONDIR': str(home / '.ipython'), 'MPLCONFIGDIR': str(home / '.matplotlib'),
            'JUPYTER_CONFIG_DIR': str(home / '.jupyter'),
            'JUPYTER_DATA_DIR': str(home / '.local/share/jupyter'),
            'JUPYTER_RUNTIME_DIR': str(home / '.local/share/jupyter/runtime'),
            'ROS_HOME': str(home / '.ros'), 'ROS_LOG_DIR': str(home / '.ros/log'),
            'OPENBLAS_NUM_THREADS': '1',  # as the Makefile says why: no spinning BLAS threads
            **extra}
