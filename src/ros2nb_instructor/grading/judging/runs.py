"""Running one learner notebook in its sandbox, and saying what happened while it ran.

Runs on the instructor's host; the notebook runs in a sandbox (:mod:`.bubblewrap`) through
:mod:`.sandboxed.runner`.  What comes back is read only after the sandbox ended, and only
the two files the runner was asked to write: the executed notebook and its
:class:`~.sandboxed.runner.RunStatus`.
"""

from __future__ import annotations

import dataclasses
import errno
import json
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import nbformat

from ros2nb.typed_json import Unreadable, decoded

from ...paths import ROOT
from ..sandbox import bubblewrap
from ..sandbox.paths_of_learners import NotARegularFile, read_regular
from ..sandbox.scratch import Scratch, sandbox_env
from ..sandboxed.runner import RunStatus
from .settings import Settings

#: The program that runs in the sandbox: it executes the notebook with nbclient.
RUNNER = 'ros2nb_instructor.grading.sandboxed.runner'
#: Largest executed notebook read back (the runner cuts each cell's output at 100 kB).
MAX_NOTEBOOK_BYTES = 20_000_000
#: A status's cell numbers are below this (a larger one was not written by the runner).
MAX_CELLS = 1_000_000
#: The status of a run that said nothing readable.
NO_STATUS = RunStatus(ran=0, cells=0, timed_out=(), output_cut=(), finished=False)
#: The status's fields: what else a status holds is not read (the runner writes nothing else).
_STATUS_FIELDS = frozenset(field.name for field in dataclasses.fields(RunStatus))


@dataclass(frozen=True)
class NotebookRun:
    """One notebook's run in the learner's sandbox, as the grader read it back on its host
    after the sandbox ended (:func:`run_notebook`).

    :ivar executed: the executed notebook (what ran of it), or the prepared one when none
        could be read.
    :ivar status: the runner's status, every field checked (:func:`checked_status`);
        :data:`NO_STATUS` when it could not be read.
    :ivar unread: the grader's own words when the runner's files could not be read, or None.
    :ivar stopped: the note of a sandbox stopped at a limit (:func:`stopped_note`), or None.
    """

    executed: nbformat.NotebookNode
    status: RunStatus
    unread: Optional[str] = None
    stopped: Optional[str] = None


def run_notebook(scratch: Scratch, notebook: str, prepared: nbformat.NotebookNode,
                 settings: Settings) -> NotebookRun:
    """Execute the prepared notebook in the learner's sandbox.

    The notebook goes in through a folder of the grader's (read-only inside); the runner
    writes into an output folder of its own; the grader reads the two files back by file
    descriptor, never through a link, after the sandbox ended.  It writes nothing in the
    learner's home, whatever the learner's code put there.

    :return: the executed notebook (what ran of it), the runner's status (checked: every
        field of the right type), why they could not be read, and a note when the sandbox
        had to be stopped.
    """
    given, out = scratch.run_folders(notebook)
    (given / f'{notebook}.ipynb').write_text(nbformat.writes(prepared))
    (given / f'{notebook}.ipynb').chmod(0o644)
    argv = [sys.executable, '-m', RUNNER, str(given / f'{notebook}.ipynb'),
            str(out / f'{notebook}.run.ipynb'), f'--cell-timeout={settings.cell_timeout}',
            f'--folder={scratch.home / "notebooks"}']
    env = sandbox_env(scratch.home, ROS2NB_WORKSPACE=str(scratch.workspace))
    limits = bubblewrap.Limits(wall_s=settings.notebook_timeout, cpu_s=settings.notebook_cpu,
                            cpu_share=settings.cpu_share)
    stopped, out_of_cpu = None, False
    if settings.sandboxed:
        box = bubblewrap.Sandbox(writable=[scratch.home, out], env=env, cwd=scratch.home,
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
    executed, status, unread = _read_back(out, notebook, prepared)
    if timed_out or out_of_cpu:
        stopped = stopped_note(status, f'the limit of {settings.notebook_cpu:g} CPU-seconds for '
                               'running a notebook (its kernel and every process it started, '
                               'together)' if out_of_cpu else
                               f'the limit of {settings.notebook_timeout} s for running a '
                               'notebook')
    return NotebookRun(executed, status, unread, stopped)


def stopped_note(status: RunStatus, limit: str) -> str:
    """The note of a run stopped at ``limit``: which cells did not run, and that the points
    come from the grader's checks (a heavy honest run, or a loop, alike: no blame)."""
    ran, cells = status.ran, status.cells
    which = (f'it was stopped while cell {ran + 1} of {cells} ran, so cells {ran + 1}-{cells} '
             'did not run' if 0 < ran + 1 < cells else
             f'it was stopped while cell {ran + 1} of {cells} ran' if cells else
             'it was stopped')
    return (f'its run reached {limit}: {which}; its points come from the grader\'s checks, '
            'which read its answer cells and the files its cells wrote before it was stopped')


def _read_back(out: Path, notebook: str, prepared: nbformat.NotebookNode
               ) -> tuple[nbformat.NotebookNode, RunStatus, Optional[str]]:
    """The executed notebook and the runner's status, or the prepared one (or
    :data:`NO_STATUS`) and why not."""
    try:
        executed = nbformat.reads(read_regular(out, f'{notebook}.run.ipynb', MAX_NOTEBOOK_BYTES)
                                  .decode('utf-8'), as_version=4)
    except (OSError, ValueError) as error:  # deleted, broken, linked or bloated
        why = ('it left a link where its executed notebook belongs'
               if isinstance(error, NotARegularFile) and error.errno == errno.ELOOP
               else 'its run left no readable notebook')
        return prepared, NO_STATUS, why
    try:
        data = json.loads(read_regular(out, f'{notebook}.run.ipynb.status.json', 1_000_000))
    except (OSError, ValueError):
        data = None
    status = checked_status(data)
    if status is None:
        return executed, NO_STATUS, (
            "the runner's status was unreadable or rewritten (its kernel or the runner was "
            "killed, or the notebook changed it); what ran of the notebook is graded")
    return executed, status, None


def checked_status(data: object) -> Optional[RunStatus]:
    """The runner's status (parsed JSON) as a :class:`~.sandboxed.runner.RunStatus` when
    every field it has has its type (whole numbers below :data:`MAX_CELLS`, lists of them),
    else None.  Keys it does not have are not read."""
    if not isinstance(data, dict):
        return None
    try:
        status: RunStatus = decoded(RunStatus, {key: value for key, value in data.items()
                                                if key in _STATUS_FIELDS})
    except Unreadable:
        return None
    died = () if status.kernel_died_at is None else (status.kernel_died_at,)
    numbers = (status.ran, status.cells, *status.timed_out, *status.output_cut, *died)
    return status if all(0 <= number < MAX_CELLS for number in numbers) else None


def run_note(run: NotebookRun) -> Optional[str]:
    """What happened while the notebook ran, in words (None when nothing worth saying)."""
    status = run.status
    notes = [run.stopped] if run.stopped else []
    if status.kernel_died_at is not None:
        notes.append(f'its kernel died while cell {status.kernel_died_at + 1} ran (the '
                     'process was killed or exited); the cells after it did not run')
    if status.timed_out:
        cells = ', '.join(str(i + 1) for i in status.timed_out)
        notes.append(f'cell(s) {cells} ran longer than the limit and were interrupted; the '
                     'cells after them still ran')
    if status.output_cut:
        cells = ', '.join(str(i + 1) for i in status.output_cut)
        notes.append(f'the output of cell(s) {cells} was cut (too large to keep)')
    if run.unread:  # the grader's own words
        notes.append(f'running it stopped early: {run.unread}')
    if status.runner_error:
        # The status is written inside the sandbox, where the learner's code runs: its words
        # are quoted as the run's, never said as the grader's.
        said = json.dumps(status.runner_error[:300], ensure_ascii=False)
        notes.append(f'running it stopped early; the run inside the sandbox reported (its own '
                     f'words, unchecked): {said}')
    if not notes and not status.finished:
        notes.append(f'its run ended at cell {status.ran + 1} of {status.cells}: the '
                     'notebook stopped or killed the processes running it')
    return '; '.join(notes) or None
