#!/usr/bin/env python3
"""Execute one learner notebook for grading, with limits: \
``python -m ros2nb_instructor.grading.sandboxed.runner IN OUT``.

Runs inside the learner's sandbox (:mod:`ros2nb_instructor.grading.sandbox.bubblewrap`), as the
sandbox's user, beside the learner's kernel: nothing it writes is trusted beyond the two
files the grader reads back.  nbclient does the executing.  What
it adds: every cell has a time limit after which its kernel is interrupted and the next
cell runs; a cell's output is cut at a size limit, with a note; the notebook is saved
after every cell, so whatever ran is kept even if the sandbox is stopped from outside;
and ``OUT.status.json`` says what happened (a :class:`RunStatus`): cells that ran too long, a
kernel that died, output that was cut.  Nothing here decides a grade (ros2nb.judge does,
nbgrader scores).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import DeadKernelError

#: Characters of text output one cell may keep (printed text, tracebacks, text/plain).
MAX_CELL_OUTPUT_BYTES = 100_000
#: Bytes of images (base64) one cell may keep besides: a plot or two.
MAX_CELL_IMAGE_BYTES = 2_000_000
IMAGE_TYPES = ('image/png', 'image/jpeg', 'image/svg+xml')


@dataclass(frozen=True, kw_only=True)
class RunStatus:
    """What happened while the notebook ran, as far as it ran.

    The runner writes it beside the executed notebook (``OUT.status.json``, :func:`save`)
    inside the learner's sandbox; the grader reads it back on its host after the sandbox
    ended (:func:`ros2nb_instructor.grading.judging.runs.checked_status`, with
    :func:`ros2nb.typed_json.decoded`).  The learner's code runs beside the runner, as the
    same user, and may rewrite the file: a status that does not fit is that learner's note.

    :ivar ran: cells run so far (the number of the cell running, counted from 0).
    :ivar cells: cells in the notebook.
    :ivar timed_out: the cells (from 0) interrupted at the cell limit.
    :ivar output_cut: the cells (from 0) whose output was cut (:data:`MAX_CELL_OUTPUT_BYTES`).
    :ivar kernel_died_at: the cell (from 0) its kernel died in, or None.
    :ivar finished: True once every cell ran.
    :ivar runner_error: why nbclient could not go on (``Type: text``), or None.
    """

    ran: int
    cells: int
    timed_out: tuple[int, ...]
    output_cut: tuple[int, ...]
    kernel_died_at: Optional[int] = None
    finished: bool
    runner_error: Optional[str] = None


def _size(output: Any) -> int:
    """Text characters of an output (images are counted apart, by :func:`_image_size`)."""
    if output.get('output_type') == 'stream':
        return len(output.get('text', ''))
    return sum(len(str(v)) for k, v in output.get('data', {}).items() if k not in IMAGE_TYPES) \
        + len(str(output.get('traceback', '')))


def _image_size(output: Any) -> int:
    return sum(len(str(v)) for k, v in output.get('data', {}).items() if k in IMAGE_TYPES)


class LimitedClient(NotebookClient):
    """nbclient with a size limit per cell and a save after every cell."""

    def __init__(self, nb: nbformat.NotebookNode, out: Path, status: RunStatus,
                 **kwargs: Any) -> None:
        super().__init__(nb, **kwargs)
        self.out_path, self.status = out, status
        self._notes: dict[int, Any] = {}
        self.on_cell_executed = self._saved

    def output(self, outs: list[nbformat.NotebookNode], msg: dict[str, Any],
               display_id: Optional[str], cell_index: int) -> Any:
        out = super().output(outs, msg, display_id, cell_index)
        if out is None:
            return None
        note = self._notes.get(cell_index)
        kept = sum(_size(o) for o in outs if o is not note)
        images = sum(_image_size(o) for o in outs)
        if kept > MAX_CELL_OUTPUT_BYTES or images > MAX_CELL_IMAGE_BYTES:
            outs.remove(out)
            if out.get('output_type') == 'stream':  # keep the first part of the text
                room = MAX_CELL_OUTPUT_BYTES - (kept - _size(out))
                if room > 0:
                    out['text'] = out['text'][:room]
                    outs.insert(len(outs) - (note is not None), out)
            if note is None:
                self.status = dataclasses.replace(
                    self.status, output_cut=(*self.status.output_cut, cell_index))
                note = self._notes[cell_index] = nbformat.v4.new_output(
                    'stream', name='stderr', text=(
                        f'\n[The grader cut this cell\'s output at {MAX_CELL_OUTPUT_BYTES // 1000} '
                        f'kB of text and {MAX_CELL_IMAGE_BYTES // 1_000_000} MB of images; what '
                        'it showed beyond that is not kept.]\n'))
                outs.append(note)
        return out

    def _saved(self, cell: Any, cell_index: int, execute_reply: dict[str, Any]) -> None:
        error = execute_reply.get('content', {})
        if error.get('ename') == 'CellTimeoutError':
            self.status = dataclasses.replace(
                self.status, timed_out=(*self.status.timed_out, cell_index))
        self.status = dataclasses.replace(self.status, ran=cell_index + 1)
        save(self.nb, self.out_path, self.status)


def save(nb: nbformat.NotebookNode, out: Path, status: RunStatus) -> None:
    """Write the notebook and its status atomically (a kill never leaves half a file)."""
    for path, text in ((out, nbformat.writes(nb)),
                       (Path(str(out) + '.status.json'),
                        json.dumps(dataclasses.asdict(status)))):
        partial = path.with_name(path.name + '.partial')
        partial.write_text(text)
        os.replace(partial, path)


def _working_folder(folder: Path) -> Path:
    """``folder`` as a real folder: whatever an earlier notebook left there (a link) goes.

    Inside the sandbox a link resolves only to what the sandbox sees; the folder is the
    learner's, made anew when their last notebook replaced it.
    """
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        folder.unlink()
    folder.mkdir(parents=True, exist_ok=True)
    return folder


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('notebook', type=Path)
    parser.add_argument('out', type=Path)
    parser.add_argument('--cell-timeout', type=int, default=120)
    parser.add_argument('--folder', type=Path, default=None,
                        help="the kernel's working folder (made here, inside the sandbox)")
    args = parser.parse_args(argv)
    folder = _working_folder(args.folder or args.notebook.parent)
    nb = nbformat.read(args.notebook, as_version=4)
    status = RunStatus(ran=0, cells=len(nb.cells), timed_out=(), output_cut=(), finished=False)
    timeout_error = {'ename': 'CellTimeoutError',
                     'evalue': f'the grader stopped this cell after {args.cell_timeout} s',
                     'traceback': [f'CellTimeoutError: the grader stopped this cell after '
                                   f'{args.cell_timeout} s; the cells after it still ran.']}
    client = LimitedClient(nb, args.out, status, timeout=args.cell_timeout,
                           kernel_name='python3', allow_errors=True, interrupt_on_timeout=True,
                           error_on_timeout=timeout_error, record_timing=False,
                           resources={'metadata': {'path': str(folder)}})
    save(nb, args.out, status)
    try:
        client.execute()
        client.status = dataclasses.replace(client.status, finished=True)
    except DeadKernelError:
        client.status = dataclasses.replace(client.status, kernel_died_at=client.status.ran)
        # Whether the kernel said the number of the cell it died in before it died is a race
        # of the machine's: no number is shown for that cell on any machine.
        for cell in nb.cells[client.status.ran:]:
            if cell.cell_type == 'code':
                cell.execution_count = None
    except Exception as error:  # nbclient could not go on: say why, keep what ran
        client.status = dataclasses.replace(
            client.status, runner_error=f'{type(error).__name__}: {str(error)[:300]}')
    save(nb, args.out, client.status)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
