"""Running one learner notebook in its sandbox, and saying what happened while it ran.

Runs on the instructor's host; the notebook runs in a sandbox (:mod:`.sandbox`) through
:mod:`.sandboxed.runner`.  What comes back is read only after the sandbox ended, and only
the two files the runner was asked to write.
"""

from __future__ import annotations

import errno
import json
import subprocess
import sys
from pathlib import Path
from typing import Any, Optional

import nbformat

from ..paths import ROOT
from . import sandbox
from .paths_of_learners import NotARegularFile, read_regular
from .scratch import Scratch, sandbox_env
from .settings import Settings

#: The program that runs in the sandbox: it executes the notebook with nbclient.
RUNNER = 'ros2nb_instructor.grading.sandboxed.runner'
#: Largest executed notebook read back (the runner cuts each cell's output at 100 kB).
MAX_NOTEBOOK_BYTES = 20_000_000


def run_notebook(scratch: Scratch, notebook: str, prepared: nbformat.NotebookNode,
                 settings: Settings) -> tuple[nbformat.NotebookNode, dict[str, Any], Optional[str]]:
    """Execute the prepared notebook in the learner's sandbox.

    The notebook goes in through a folder of the grader's (read-only inside); the runner
    writes into an output folder of its own; the grader reads the two files back by file
    descriptor, never through a link, after the sandbox ended.  It writes nothing in the
    learner's home, whatever the learner's code put there.

    :return: the executed notebook (what ran of it), the runner's status (checked: every
        field of the right type), and a note when the sandbox had to be stopped.
    """
    given, out = scratch.run_folders(notebook)
    (given / f'{notebook}.ipynb').write_text(nbformat.writes(prepared))
    (given / f'{notebook}.ipynb').chmod(0o644)
    argv = [sys.executable, '-m', RUNNER, str(given / f'{notebook}.ipynb'),
            str(out / f'{notebook}.run.ipynb'), f'--cell-timeout={settings.cell_timeout}',
            f'--folder={scratch.home / "notebooks"}']
    env = sandbox_env(scratch.home, ROS2NB_WORKSPACE=str(scratch.workspace))
    limits = sandbox.Limits(wall_s=settings.notebook_timeout, cpu_s=settings.notebook_cpu,
                            cpu_share=settings.cpu_share)
    stopped, out_of_cpu = None, False
    if settings.sandboxed:
        box = sandbox.Sandbox(writable=[scratch.home, out], env=env, cwd=scratch.home,
                              readable=[ROOT / 'src', given],
                              hidden=[ROOT / 'src' / 'ros2nb' / 'reference'])
        result = box.run(argv, limits, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        timed_out, out_of_cpu = result.timed_out, result.out_of_cpu
    else:
        try:
            subprocess.run(argv, env=env, cwd=scratch.home, timeout=settings.notebook_timeout,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            timed_out = False
        except subprocess.TimeoutExpired:
            timed_out = True
    executed, status = _read_back(out, notebook, prepared)
    if timed_out or out_of_cpu:
        stopped = stopped_note(status, f'the limit of {settings.notebook_cpu:g} CPU-seconds for '
                               'running a notebook (its kernel and every process it started, '
                               'together)' if out_of_cpu else
                               f'the limit of {settings.notebook_timeout} s for running a '
                               'notebook')
    return executed, status, stopped


def stopped_note(status: dict[str, Any], limit: str) -> str:
    """The note of a run stopped at ``limit``: which cells did not run, and that the points
    come from the grader's checks (a heavy honest run, or a loop, alike: no blame)."""
    ran, cells = status.get('ran', 0), status.get('cells', 0)
    which = (f'it was stopped while cell {ran + 1} of {cells} ran, so cells {ran + 1}-{cells} '
             'did not run' if 0 < ran + 1 < cells else
             f'it was stopped while cell {ran + 1} of {cells} ran' if cells else
             'it was stopped')
    return (f'its run reached {limit}: {which}; its points come from the grader\'s checks, '
            'which read its answer cells and the files its cells wrote before it was stopped')


def _read_back(out: Path, notebook: str, prepared: nbformat.NotebookNode
               ) -> tuple[nbformat.NotebookNode, dict[str, Any]]:
    """The executed notebook and the runner's status, or the prepared one and why not."""
    try:
        executed = nbformat.reads(read_regular(out, f'{notebook}.run.ipynb', MAX_NOTEBOOK_BYTES)
                                  .decode('utf-8'), as_version=4)
    except (OSError, ValueError) as error:  # deleted, broken, linked or bloated
        why = ('it left a link where its executed notebook belongs'
               if isinstance(error, NotARegularFile) and error.errno == errno.ELOOP
               else 'its run left no readable notebook')
        return prepared, {**NO_STATUS, 'unread': why}
    try:
        status = json.loads(read_regular(out, f'{notebook}.run.ipynb.status.json', 1_000_000))
    except (OSError, ValueError):
        status = None
    status = checked_status(status)
    if status is None:
        return executed, {**NO_STATUS, 'unread': (
            "the runner's status was unreadable or rewritten (its kernel or the runner was "
            "killed, or the notebook changed it); what ran of the notebook is graded")}
    return executed, status


#: A status of a run that said nothing readable.
NO_STATUS = {'ran': 0, 'cells': 0, 'timed_out': [], 'output_cut': [], 'kernel_died_at': None,
             'finished': False}


def checked_status(status: object) -> Optional[dict[str, Any]]:
    """The runner's status when every field has its type (ints, lists of ints), else None."""
    def whole(value: object) -> bool:
        return isinstance(value, int) and not isinstance(value, bool) and 0 <= value < 1_000_000

    if not isinstance(status, dict):
        return None
    died = status.get('kernel_died_at')
    lists = (status.get('timed_out'), status.get('output_cut'))
    error = status.get('runner_error')
    ok = (whole(status.get('ran')) and whole(status.get('cells'))
          and isinstance(status.get('finished'), bool) and (died is None or whole(died))
          and all(isinstance(v, list) and all(whole(i) for i in v) for v in lists)
          and (error is None or isinstance(error, str)))
    if not ok:
        return None
    return {key: status.get(key) for key in (*NO_STATUS, 'runner_error')}


def run_note(status: dict[str, Any], stopped: Optional[str]) -> Optional[str]:
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
    if status.get('unread'):  # the grader's own words
        notes.append(f'running it stopped early: {status["unread"]}')
    if status.get('runner_error'):
        # The status is written inside the sandbox, where the learner's code runs: its words
        # are quoted as the run's, never said as the grader's.
        said = json.dumps(status['runner_error'][:300], ensure_ascii=False)
        notes.append(f'running it stopped early; the run inside the sandbox reported (its own '
                     f'words, unchecked): {said}')
    if not notes and not status.get('finished'):
        notes.append(f'its run ended at cell {status["ran"] + 1} of {status["cells"]}: the '
                     'notebook stopped or killed the processes running it')
    return '; '.join(notes) or None
