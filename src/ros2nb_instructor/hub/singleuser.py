"""``ros2nb-hub-singleuser``: start one learner's Jupyter server on the course's JupyterHub.

Runs on the classroom server, as the learner (JupyterHub's spawner starts it), never as
root; ``make hub`` runs its ``--check`` as root first.

JupyterHub's spawner runs this as the learner, with ``HOME`` set to the learner's home and
``JUPYTERHUB_ROOT_DIR`` set to their course folder (``~/ros2-course``). It

1. creates that folder (readable by the learner only) and copies every learner notebook of
   the course (``notebooks/*.ipynb``) that is not there yet into its ``notebooks/``. It never
   replaces a notebook the learner has, so their work survives restarts; a changed course
   notebook goes beside theirs as ``NN-title (course update).ipynb`` (as ``make lab`` does,
   :mod:`ros2nb_instructor.lab`);
2. gives the learner their own ROS workspace, ``<course folder>/workspace/ROS2_and_RL_Tutorials``
   (``ROS2NB_WORKSPACE``, which ros2nb reads);
3. gives the server the learner's Jupyter configuration (no nbgrader instructor tools, no
   news pop-up, no Extension Manager: ``environment/jupyter-learner``);
4. builds matplotlib's font list in the learner's cache if it is not there, so that their first
   plot does not show "Matplotlib is building the font cache" (matplotlib says so when building
   takes over 5 s, as on a busy server);
5. puts the course's venv first on ``PATH`` and becomes ``jupyterhub-singleuser`` with the
   arguments the hub passed.

``make hub`` first runs it as ``ros2nb-hub-singleuser --check``: when the hub runs as root (so
that learners' servers run as the learners), every learner must be able to run the venv's
Python and read the course. A venv built on a Python under ``/root`` (pyenv) fails that.
"""

from __future__ import annotations

import os
import stat
import sys
from pathlib import Path
from typing import Mapping, MutableMapping, NoReturn, Optional

from ros2nb.terminal.workspace import WORKSPACE_NAME

from .. import lab
from ..lab import update_work_folder
from ..paths import EXTENSIONS, NOTEBOOKS, ROOT

#: The course repository.
COURSE = ROOT
#: The learner's course folder when the hub does not say (JupyterHub's notebook_dir).
DEFAULT_FOLDER = '~/ros2-course'


def learner_folder(env: Mapping[str, str]) -> Path:
    """Return the learner's course folder: ``$JUPYTERHUB_ROOT_DIR`` or ``~/ros2-course``."""
    return Path(env.get('JUPYTERHUB_ROOT_DIR') or DEFAULT_FOLDER).expanduser()


def copy_missing_notebooks(source: Path, folder: Path) -> list[str]:
    """Bring the course's notebooks into ``folder/notebooks`` as ``make lab`` does; never overwrite.

    A notebook the learner has is kept; a changed course version goes beside it
    (:func:`ros2nb_instructor.lab.update_work_folder`).

    :param source: the course's ``notebooks/``.
    :param folder: the learner's course folder; created readable by its owner only.
    :return: one line per notebook copied, updated or offered beside the learner's.
    """
    folder.mkdir(mode=0o700, parents=True, exist_ok=True)
    return update_work_folder(source, folder / 'notebooks')


def learner_environment(env: MutableMapping[str, str], folder: Path, venv_bin: Path) -> None:
    """Give the learner their own ROS workspace and work folder, the course's venv first on
    ``PATH``, the learner's lab."""
    env.setdefault('ROS2NB_WORKSPACE', str(folder / 'workspace' / WORKSPACE_NAME))
    env.setdefault(lab.WORK_ENV, str(folder / 'notebooks'))  # where their progress is kept
    env['PATH'] = os.pathsep.join([str(venv_bin), env.get('PATH', os.defpath)])
    env['VIRTUAL_ENV'] = str(venv_bin.parent)
    lab.learner_environment(env)  # nbgrader's instructor tools, news and Extension Manager off


def build_font_cache() -> None:
    """Have matplotlib build the learner's font list now (``~/.cache/matplotlib``), if missing.

    Building it is matplotlib's own work at its first import of ``font_manager``; done here, the
    server's log shows any "building the font cache" line instead of the learner's first plot.
    """
    import matplotlib.font_manager  # noqa: F401 - the import builds and saves the font list


def closed_to_others(path: Path, *, need: int) -> Optional[Path]:
    """Return the first folder on the way to ``path``, or ``path``, that other users cannot use.

    :param path: a file or folder; symbolic links are followed.
    :param need: the permission bits ``path`` itself must grant others (e.g. ``stat.S_IROTH``).
    :return: the folder or file that blocks other users, or ``None`` if nothing does.
    """
    real = path.resolve()
    for folder in reversed(real.parents):
        if not folder.stat().st_mode & stat.S_IXOTH:
            return folder
    return None if real.stat().st_mode & need == need else real


def extensions_open_to_learners(course: Path) -> Optional[str]:
    """Return why the course would show learners what is not theirs (its ``extensions.toml``,
    every learner's extensions, readable by others), or ``None``."""
    private = course / EXTENSIONS
    if private.exists() and private.stat().st_mode & (stat.S_IROTH | stat.S_IRGRP):
        return (f'Learners can read {private} (every learner\'s extensions): make it yours '
                f'alone, chmod 600 {private}, then start the hub again.')
    return None


def check_learners_can_use_course(python: Path) -> Optional[str]:
    """Return why learners could not start the course's server as themselves, or why the
    course would show them what is not theirs (:func:`extensions_open_to_learners`), or
    ``None``."""
    private = extensions_open_to_learners(COURSE)
    if private:
        return private
    needs = ((python, stat.S_IXOTH), (Path(__file__).resolve(), stat.S_IROTH),
             (NOTEBOOKS, stat.S_IROTH | stat.S_IXOTH))
    for path, need in needs:
        blocked = closed_to_others(path, need=need)
        if blocked is not None:
            return (f'Learners cannot use {path} ({blocked} is closed to other users): put the '
                    'course where everyone can read it (e.g. /opt/ros2-course) and build its venv '
                    'on a Python they can run, e.g. make setup PYTHON=/usr/bin/python3.')
    return None


def main(argv: Optional[list[str]] = None) -> NoReturn:
    """Prepare the learner's folder, then replace this process with jupyterhub-singleuser."""
    argv = sys.argv[1:] if argv is None else argv
    venv_bin = Path(sys.executable).parent
    if argv in (['-h'], ['--help']):
        print('usage: ros2nb-hub-singleuser [--check | JUPYTERHUB_SINGLEUSER_ARGUMENT ...]\n\n'
              "JupyterHub's spawner command for the course: copy the notebooks the learner's "
              'folder lacks (never overwriting theirs), then become jupyterhub-singleuser '
              'with the arguments given.\n  --check  as root, say whether learners can use '
              'the course (docs/classroom-server.md)')
        sys.exit(0)
    if argv == ['--check']:
        problem = check_learners_can_use_course(Path(sys.executable)) if os.geteuid() == 0 else None
        sys.exit(problem)
    server = venv_bin / 'jupyterhub-singleuser'
    if not server.exists():
        sys.exit(f'{server} is missing: run `make setup` in {COURSE} (it installs jupyterhub).')
    folder = learner_folder(os.environ)
    for line in copy_missing_notebooks(NOTEBOOKS, folder):
        print(f'ros2-course: {line}', file=sys.stderr)
    learner_environment(os.environ, folder, venv_bin)
    build_font_cache()
    os.execv(server, [str(server), *argv])


if __name__ == '__main__':
    main()
