"""``ros2nb-lab``: the learner's JupyterLab (``make lab``), their work kept apart from the course.

Runs on the learner's machine (``make lab``), on the classroom server as the learner
(:mod:`ros2nb_instructor.hub.singleuser`), and for the instructor (``make lab-instructor``).

- :func:`update_work_folder` copies the course's learner notebooks (``notebooks/``) into the
  learner's working folder (``work/``, which git ignores). A notebook already there is never
  replaced once it differs from the copy it started as: a changed course notebook is put
  beside it as ``NN-title (course update).ipynb``, with one line saying so.
- :data:`LEARNER_CONFIG` is the Jupyter configuration a learner gets (a folder on
  ``JUPYTER_CONFIG_PATH``): nbgrader's instructor tools (Create Assignment, Formgrader,
  Course List, Assignment List, Validate), the news pop-up and the Extension Manager off.
- ``ros2nb-lab [--instructor] [JUPYTER-LAB-ARGS...]`` does both, then becomes ``jupyter lab``;
  ``--instructor`` opens the course folder itself with every tool on.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import sys
from pathlib import Path
from typing import MutableMapping, NoReturn, Optional

from ros2nb.graded_parts import WORK_ENV

from .paths import NOTEBOOKS, ROOT

#: The learner's working folder for ``make lab`` (git ignores it); ``$ROS2NB_WORK`` moves it.
WORK = ROOT / 'work'
#: The Jupyter configuration of a learner's server (labconfig/page_config.json and the
#: server's extensions); put on ``JUPYTER_CONFIG_PATH``.
LEARNER_CONFIG = ROOT / 'environment' / 'jupyter-learner'
#: What the working folder remembers of each course notebook it was given (name -> sha256).
RECORD = '.course-versions.json'
#: How a changed course notebook is named beside the learner's own.
UPDATE_SUFFIX = ' (course update)'


def _digest(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def update_name(notebook: str) -> str:
    """``03-write-the-publisher.ipynb`` -> ``03-write-the-publisher (course update).ipynb``."""
    stem, dot, suffix = notebook.rpartition('.')
    return f'{stem}{UPDATE_SUFFIX}{dot}{suffix}'


def _update_one(course: Path, work: Path, record: dict[str, str]) -> Optional[str]:
    """Bring one course notebook into ``work``; return the line to show, or None (no change)."""
    mine, new = work / course.name, _digest(course)
    given = record.get(course.name)
    if not mine.exists() and not mine.is_symlink():
        shutil.copyfile(course, mine)
        record[course.name] = new
        return f'{mine}: new notebook from the course.'
    if given == new:
        return None
    record[course.name] = new
    if mine.is_file() and not mine.is_symlink() and given == _digest(mine):
        shutil.copyfile(course, mine)  # never opened or changed since it was given: no work lost
        return f'{mine}: updated from the course (you had not changed it).'
    beside = work / update_name(course.name)
    shutil.copyfile(course, beside)
    return (f'{beside}: the course changed {course.name}; yours is kept as it is, the new '
            'version is beside it (copy what you need across).')


def update_work_folder(source: Path, work: Path) -> list[str]:
    """Copy the course's notebooks into the learner's working folder, keeping their work.

    Introduced by ``make lab`` (README, notebook 00).  A notebook missing from ``work`` is
    copied; one the learner has is never overwritten: when the course's version changed
    since it was given, the new one goes beside it as ``NN-title (course update).ipynb``
    (replaced by a newer course update later).  A copy still exactly as it was given is
    simply updated.

    :param source: the course's learner notebooks (``notebooks/``).
    :param work: the learner's working folder; created (readable by its owner only) if missing.
    :return: one line per notebook copied, updated or offered beside the learner's.
    """
    work.mkdir(mode=0o700, parents=True, exist_ok=True)
    record_file = work / RECORD
    record = json.loads(record_file.read_text()) if record_file.is_file() else {}
    lines = [line for course in sorted(source.glob('*.ipynb'))
             if (line := _update_one(course, work, record)) is not None]
    record_file.write_text(json.dumps(record, indent=1, sort_keys=True) + '\n')
    return lines


def learner_environment(env: MutableMapping[str, str]) -> None:
    """Give a Jupyter server started with ``env`` the learner's configuration (first on
    the path)."""
    paths = [p for p in env.get('JUPYTER_CONFIG_PATH', '').split(os.pathsep) if p]
    env['JUPYTER_CONFIG_PATH'] = os.pathsep.join([str(LEARNER_CONFIG), *paths])


def main(argv: Optional[list[str]] = None) -> NoReturn:
    """``make lab``: update the working folder, then become ``jupyter lab`` on it
    (learner's config).

    ``--instructor`` (``make lab-instructor``): the course folder, every tool on.
    Any other argument is passed to ``jupyter lab``.
    """
    parser = argparse.ArgumentParser(
        prog='ros2nb-lab', allow_abbrev=False,
        description='make lab: copy the notebooks the working folder lacks (never '
        'overwriting yours), then start JupyterLab on it.',
        epilog='Any other argument goes to jupyter lab (e.g. --ServerApp.ip=0.0.0.0).')
    parser.add_argument('--instructor', action='store_true',
                        help='the course folder itself, every tool on (make lab-instructor)')
    given, args = parser.parse_known_args(sys.argv[1:] if argv is None else list(argv))
    if given.instructor:
        root, default_url = ROOT, '/lab/tree/notebooks'
    else:
        root = Path(os.environ.get(WORK_ENV) or WORK).resolve()
        for line in update_work_folder(NOTEBOOKS, root):
            print(line, file=sys.stderr)
        print(f'Your notebooks are in {root} (the course never overwrites them); keep each '
              'notebook open in one tab only.', file=sys.stderr)
        learner_environment(os.environ)
        os.environ[WORK_ENV] = str(root)  # the kernels keep the learner's progress there
        default_url = '/lab'
    # Localhost unless told otherwise (the course's image listens on every interface of its
    # container: `make lab LAB_ARGS=--ServerApp.ip=0.0.0.0`); traitlets refuses two values.
    given_ip = any(a.startswith(('--ServerApp.ip', '--ip')) for a in args)
    argv = [str(Path(sys.executable).with_name('jupyter-lab')),
            *([] if given_ip else ['--ServerApp.ip=127.0.0.1']),
            f'--ServerApp.root_dir={root}', f'--LabApp.default_url={default_url}',
            *(['--allow-root'] if os.geteuid() == 0 else []), *args]
    os.execv(argv[0], argv)


if __name__ == '__main__':
    main()
