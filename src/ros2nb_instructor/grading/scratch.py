"""A learner's folders while grading: outside the repository, shared by their notebooks in order.

Runs on the instructor's host.  Each notebook's judge gets a snapshot of the workspace as
that notebook left it, copied without following a link.
"""

from __future__ import annotations

import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path

from ros2nb.terminal.workspace import WORKSPACE_NAME

from .submissions import Learner


class Scratch:
    """One learner's folders outside the repository, shared by their notebooks in order."""

    def __init__(self, root: Path, learner: Learner) -> None:
        self.top = Path(tempfile.mkdtemp(prefix='learner-', dir=root))
        self.home = self.top / 'home'
        self.workspace = self.home / 'workspace' / WORKSPACE_NAME
        self.home.mkdir()
        self.top.chmod(0o711)  # the sandboxes' own user may pass, nobody may list

    def snapshot(self, notebook: str) -> Path:
        """A copy of the workspace as ``notebook``'s run left it, for that notebook's judge.

        The judge reads the copy while the learner's next notebook runs (and changes the
        workspace).  Links are copied as links, never followed; colcon's ``build``,
        ``install`` and ``log`` and anything that is not a file, folder or link stay behind
        (the judge builds a package of its own when it needs one).
        """
        target = self.top / f'workspace-{notebook}' / WORKSPACE_NAME
        target.parent.mkdir()
        target.parent.chmod(0o755)
        if self.workspace.is_dir() and not self.workspace.is_symlink():
            shutil.copytree(self.workspace, target, symlinks=True, ignore=_not_for_the_judge(
                self.workspace))
        else:
            target.mkdir()  # notebooks 00 and 01 make none
        target.chmod(0o755)
        return target

    def judge_folders(self, notebook: str) -> tuple[Path, Path]:
        """A fresh judge folder (writable by the judge and its subjects) and its inputs."""
        given, scratch = self.top / f'judge-in-{notebook}', self.top / f'judge-{notebook}'
        for folder, mode in ((given, 0o755), (scratch, 0o711)):
            folder.mkdir()
            folder.chmod(mode)  # the judge's sandbox user reads the given files
        return given, scratch


def _not_for_the_judge(workspace: Path):
    """``copytree``'s ignore function for :meth:`Scratch.snapshot`."""
    def ignored(folder: str, names: list[str]) -> list[str]:
        skip = {'build', 'install', 'log'} if Path(folder) == workspace else set()
        for name in names:
            mode = os.lstat(os.path.join(folder, name)).st_mode
            if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode) or stat.S_ISLNK(mode)):
                skip.add(name)  # a FIFO or device would block or mislead the copy
        return sorted(skip)
    return ignored


def sandbox_env(home: Path, **extra: str) -> dict[str, str]:
    """The environment inside a sandbox: everything in the learner's home, grading mode."""
    venv_bin = str(Path(sys.executable).parent)
    return {'PATH': f'{venv_bin}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
            'PYTHONUNBUFFERED': '1', 'ROS2NB_GRADING': '1', 'TMPDIR': '/tmp',
            'IPYTHONDIR': str(home / '.ipython'), 'MPLCONFIGDIR': str(home / '.matplotlib'),
            'JUPYTER_CONFIG_DIR': str(home / '.jupyter'),
            'JUPYTER_DATA_DIR': str(home / '.local/share/jupyter'),
            'JUPYTER_RUNTIME_DIR': str(home / '.local/share/jupyter/runtime'),
            'ROS_HOME': str(home / '.ros'), 'ROS_LOG_DIR': str(home / '.ros/log'), **extra}
