"""Every command the course installs answers ``--help`` with its usage, and does nothing else.

``ros2nb-lab --help`` once copied the notebooks into a working folder and started JupyterLab,
``ros2nb-hub-singleuser --help`` filled ``~/ros2-course``, and ``ros2nb-solutions --help``
crashed looking for a notebook called ``--help``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
COMMANDS = sorted(tomllib.loads((ROOT / 'pyproject.toml').read_text())['project']['scripts'])


@pytest.mark.parametrize('command', COMMANDS)
def test_help_says_the_usage_and_touches_nothing(command: str, tmp_path: Path) -> None:
    home, work = tmp_path / 'home', tmp_path / 'work'
    home.mkdir()
    env = {**os.environ, 'HOME': str(home), 'ROS2NB_WORK': str(work),
           'JUPYTERHUB_ROOT_DIR': str(home / 'ros2-course')}
    done = subprocess.run([str(Path(sys.executable).with_name(command)), '--help'],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=60)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(f'usage: {command}'), done.stdout[:300]
    assert sorted(p.name for p in tmp_path.iterdir()) == ['home'], list(tmp_path.rglob('*'))
    assert list(home.iterdir()) == [], list(home.rglob('*'))


def test_a_notebook_not_of_the_course_gets_one_line(tmp_path: Path) -> None:
    done = subprocess.run([str(Path(sys.executable).with_name('ros2nb-solutions')),
                           str(tmp_path / 'x.ipynb')], capture_output=True, text=True, timeout=60)
    assert done.returncode == 2
    assert done.stderr.splitlines()[-1] == (
        f'ros2nb-solutions: error: {tmp_path / "x.ipynb"} is not a notebook of '
        f'{ROOT / "solutions"}: name one of solutions/*.ipynb')
