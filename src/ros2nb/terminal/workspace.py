"""The tutorial's workspace: where it is, creating it like ``mkdir -p``, listing it like ``tree``.

Introduced in ``01-create-a-workspace.ipynb``.  No ROS import.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Iterable, Optional, Sequence, Union

from ..errors import Ros2nbError

PathLike = Union[str, os.PathLike[str]]

#: Environment variable that moves the course workspace (tests point it at a temp dir).
WORKSPACE_ENV = 'ROS2NB_WORKSPACE'
#: The tutorial's workspace name.
WORKSPACE_NAME = 'ROS2_and_RL_Tutorials'
#: Folders the tutorial creates with ``mkdir -p src docs scripts resources/images``.
WORKSPACE_FOLDERS = ('src', 'docs', 'scripts', 'resources/images')

_current: Optional[Path] = None


def course_root() -> Path:
    """Return the course repository's root (the folder with ``pyproject.toml``), or the cwd."""
    here = Path.cwd().resolve()
    for folder in (here, *here.parents):
        if (folder / 'pyproject.toml').is_file() and (folder / 'solutions').is_dir():
            return folder
    return here


def default_workspace() -> Path:
    """Return ``$ROS2NB_WORKSPACE`` or ``<course>/workspace/ROS2_and_RL_Tutorials``."""
    configured = os.environ.get(WORKSPACE_ENV)
    if configured:
        return Path(configured).expanduser().resolve()
    return course_root() / 'workspace' / WORKSPACE_NAME


def current_workspace() -> Path:
    """Return the workspace the workspace verbs use (the last one created, else the default).

    Introduced in ``01-create-a-workspace.ipynb``.
    """
    return _current if _current is not None else default_workspace()


def workspace_file(path: PathLike) -> Path:
    """Return ``path`` with ``~`` expanded; a relative path is taken inside the current
    workspace."""
    path = Path(path).expanduser()
    return path if path.is_absolute() else current_workspace() / path


def workspace_or_current(workspace_path: Optional[PathLike]) -> Path:
    """``workspace_path`` as a Path, or the current workspace when it is None."""
    return Path(workspace_path) if workspace_path is not None else current_workspace()


def shown(path: PathLike) -> str:
    """Return ``path`` as ``<workspace name>/...`` when inside the workspace (same on
    every machine)."""
    path = Path(path).resolve()
    ws = current_workspace().resolve()
    try:
        return str(Path(ws.name) / path.relative_to(ws))
    except ValueError:
        return str(path)


def create_workspace(path: Optional[PathLike] = None, *,
                     folders: Sequence[str] = WORKSPACE_FOLDERS,
                     allow_outside_course: bool = False) -> Path:
    """Create the workspace and its folders like ``mkdir -p``, and make it the current one.

    Existing folders and files are left as they are, so running it twice is harmless.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param path: where to create it; ``~`` is expanded.  ``None`` uses
        :func:`default_workspace`, a git-ignored folder of the course.
    :param folders: sub-folders to create, relative to the workspace.
    :param allow_outside_course: ``True`` to create it outside the course folder,
        e.g. ``'~/Documents/ROS2_and_RL_Tutorials'``.
    :return: the workspace's absolute path.
    :raises Ros2nbError: if the path is outside the course and you did not allow it, or a
        file stands where a folder should be.
    """
    global _current
    target = default_workspace() if path is None else Path(path).expanduser().resolve()
    root = course_root()
    if path is not None and not allow_outside_course and root not in (target, *target.parents):
        raise Ros2nbError(f'{target} is outside the course folder {root}; pass '
                          'allow_outside_course=True if that is where you want it.')
    for folder in ('.', *folders):
        where = target / folder
        if where.exists() and not where.is_dir():
            raise Ros2nbError(f'{where} exists and is a file, not a folder: move it away and '
                              'run this cell again.')
        where.mkdir(parents=True, exist_ok=True)
    _current = target
    return target


def tree(path: Optional[PathLike] = None, *, skip: Iterable[str] = ('build', 'install', 'log',
                                                                    '__pycache__')) -> None:
    """Print a folder as an indented tree, folders first, sorted (like ``tree``).

    Introduced in ``01-create-a-workspace.ipynb``.

    :param path: the folder; ``None`` is the current workspace.
    :param skip: folder names whose contents are not listed.
    """
    top = Path(path) if path is not None else current_workspace()
    if not top.is_dir():
        raise Ros2nbError(f'{top} is not a folder: create it first.')
    print(shown(top) + '/')

    def walk(folder: Path, depth: int) -> None:
        entries = sorted(p for p in folder.iterdir() if not p.name.startswith('.'))
        for entry in sorted(entries, key=lambda p: (not p.is_dir(), p.name)):
            print('    ' * depth + entry.name + ('/' if entry.is_dir() else ''))
            if entry.is_dir() and entry.name not in skip:
                walk(entry, depth + 1)

    walk(top, 1)
