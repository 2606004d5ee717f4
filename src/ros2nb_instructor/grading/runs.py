"""Running one learner notebook in its sandbox, and saying what happened while it ran.

Runs on the instructor's host; the notebook runs in a sandbox (:mod:`.sandbox`) through
:mod:`.sandboxed.runner`.  What comes back is read only after the sandbox ended, and only
the two files the runner was asked to write.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Optional

import nbformat

from ..paths import ROOT
from . import sandbox
from .scratch import Scratch, sandbox_env
from .settings import Settings

#: The program that runs in the sandbox: it executes the notebook with nbclient.
RUNNER = 'ros2nb_instructor.grading.sandboxed.runner'
#: Largest executed notebook read back (the runner cuts each cell's output at 100 kB).
MAX_NOTEBOOK_BYTES = 20_000_000


def run_notebook(scratch: Scratch, notebook: str, prepared: nbformat.NotebookNode,
                 settings: Settings) -> tuple[nbformat.NotebookNode, dict, Optional[str]]:
    """Execute the prepared notebook in the learner's sandbox.

    :return: the executed notebook (what ran of it), the runner's status, and a note when
        the sandbox had to be stopped.
    """
    folder = scratch.home / 'notebooks'
    folder.mkdir(exist_ok=True)
    given, done = folder / f'{notebook}.ipynb', folder / f'{notebook}.run.ipynb'
    nbformat.write(prepared, given)
    argv = [sys.executable, '-m', RUNNER, str(given), str(done),
            f'--cell-timeout={settings.cell_timeout}']
    env = sandbox_env(scratch.home, ROS2NB_WORKSPACE=str(scratch.workspace))
    limits = sandbox.Limits(wall_s=settings.notebook_timeout)
    stopped = None
    if settings.sandboxed:
        box = sandbox.Sandbox(writable=[scratch.home], env=env, cwd=folder,
                              readable=[ROOT / 'src'],
                              hidden=[ROOT / 'src' / 'ros2nb' / 'reference'])
        result = box.run(argv, limits, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if result.timed_out:
            stopped = (f'it ran longer than the {settings.notebook_timeout} s limit for a '
                       'notebook and was stopped')
    else:
        try:
            subprocess.run(argv, env=env, cwd=folder, timeout=settings.notebook_timeout,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            stopped = (f'it ran longer than the {settings.notebook_timeout} s limit for a '
                       'notebook and was stopped')
    try:
        if done.stat().st_size > MAX_NOTEBOOK_BYTES:
            raise ValueError('too large')
        executed = nbformat.read(done, as_version=4)
        status = json.loads(Path(str(done) + '.status.json').read_text())
    except (OSError, ValueError):  # it deleted, broke or bloated what the runner wrote
        return prepared, {'ran': 0, 'timed_out': [], 'output_cut': [], 'kernel_died_at': None,
                          'runner_error': 'its run left no readable notebook'}, stopped
    return executed, status, stopped


def run_note(status: dict, stopped: Optional[str]) -> Optional[str]:
    """What happened while the notebook ran, in words (None when nothing worth saying)."""
    notes = [stopped] if stopped else []
    if status.get('kernel_died_at') is not None:
        notes.append(f'its kernel died while cell {status["kernel_died_at"] + 1} ran (the '
                     'process was killed or exited); the cells after it did not run')
    if status.get('timed_out'):
        cells = ', '.join(str(i + 1) for i in status['timed_out'])
        notes.append(f'cell(s) {cells} ran longer than the limit and were interrupted; the '
                     'cells after them still ran')
    if status.get('output_cut'):
        cells = ', '.join(str(i + 1) for i in status['output_cut'])
        notes.append(f'the output of cell(s) {cells} was cut (too large to keep)')
    if status.get('runner_error'):
        notes.append(f'running it stopped early: {status["runner_error"]}')
    if not notes and not status.get('finished'):
        notes.append(f'its run ended at cell {status["ran"] + 1} of {status["cells"]}: the '
                     'notebook stopped or killed the processes running it')
    return '; '.join(notes) or None
