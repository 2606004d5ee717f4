"""A real Jupyter kernel for a test, and what one of its cells sent: every output message.

The tests of what a learner sees in a cell (a check's lines, the line long work updates, the
progress table, the mutation tests' ``mutation_runs.py``) read the kernel's own messages, as
JupyterLab gets them.  The wait for a cell counts the kernel's work, not the wall clock
(tests/waiting.py).  The solutions' cells are here by id, and the monitor's file as the
``%%part`` cells of notebooks 04 and 08 write it (the walks through earlier notebooks).
"""

from __future__ import annotations

import os
import queue
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from jupyter_client.manager import KernelManager

from waiting import wait_until

#: The messages of a cell's output (the rest, status and the echo of its code, are left out).
OUTPUTS = ('stream', 'error', 'display_data', 'update_display_data', 'execute_result')


@dataclass
class Cell:
    """What one cell sent, in order, and the wall seconds it took.

    :ivar messages: ``(kind, content)`` of each output message.
    """

    messages: list[tuple[str, dict]] = field(default_factory=list)
    seconds: float = 0.0

    @property
    def stdout(self) -> str:
        return ''.join(content['text'] for kind, content in self.messages
                       if kind == 'stream' and content['name'] == 'stdout')

    @property
    def stderr(self) -> str:
        return ''.join(content['text'] for kind, content in self.messages
                       if kind == 'stream' and content['name'] == 'stderr')

    @property
    def error(self) -> Optional[tuple[str, list[str]]]:
        """The error's name and its traceback lines as shown (colours removed), or None."""
        for kind, content in self.messages:
            if kind == 'error':
                return content['ename'], [re.sub(r'\x1b\[[0-9;]*m', '', line)
                                          for line in content['traceback']]
        return None

    @property
    def html(self) -> list[str]:
        return [c['data']['text/html'] for k, c in self.messages
                if k == 'display_data' and 'text/html' in c['data']]


class CellHung(AssertionError):
    """A cell that neither finished nor worked for the seconds it was given."""


def _raise_dead() -> bool:
    raise RuntimeError('the kernel died while it started')


class Kernel:
    """A real ``python3`` kernel with the test process's environment (no ROS domain of its
    own: the kernel claims one), the given workspace and ``env`` on top."""

    def __init__(self, workspace: Optional[Path | str] = None, **env: str) -> None:
        environment = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
        if workspace is not None:
            environment['ROS2NB_WORKSPACE'] = str(workspace)
        environment.update(env)
        self.manager = KernelManager(kernel_name='python3')
        self.manager.start_kernel(env=environment)
        self.client = self.manager.client()
        self.client.start_channels()

        def ready() -> bool:  # a kernel queued for a CPU is slow, not gone
            try:
                self.client.wait_for_ready(timeout=1)
            except RuntimeError:
                return not self.manager.is_alive() and _raise_dead()
            return True

        if not wait_until(ready):
            raise RuntimeError('the kernel never answered while it had its patience')

    def run(self, code: str, seconds: float = 600) -> Cell:
        """Run a cell; what it sent.

        :param seconds: for the whole cell (a node may print for ever): of the kernel's work,
            or of its idle waiting.
        :raises CellHung: when the cell had them and had not finished.
        """
        msg_id, began, cell = self.client.execute(code), time.monotonic(), Cell()

        def finished() -> bool:
            try:
                msg = self.client.get_iopub_msg(timeout=0.25)
            except queue.Empty:
                return False
            if msg['parent_header'].get('msg_id') != msg_id:
                return False
            kind, content = msg['msg_type'], msg['content']
            if kind in OUTPUTS:
                cell.messages.append((kind, content))
            return kind == 'status' and content['execution_state'] == 'idle'

        if not wait_until(finished, seconds, interval=0):
            raise CellHung(f'the cell did not finish within {seconds} s: {code!r}')
        cell.seconds = time.monotonic() - began
        return cell

    def one_line(self, code: str, *fragments: str) -> str:
        """Run a cell that must fail; check it shows one line with every fragment."""
        cell = self.run(code)
        assert cell.error is not None, f'no error for {code!r}: {cell.messages}'
        shown = cell.error[1]
        assert len(shown) == 1, shown
        for fragment in fragments:
            assert fragment in shown[0], (fragment, shown[0])
        return shown[0]

    def restart(self) -> None:
        self.manager.restart_kernel(now=True)
        self.client.wait_for_ready(timeout=120)

    def close(self) -> None:
        self.client.stop_channels()
        self.manager.shutdown_kernel(now=True)


ROOT = Path(__file__).resolve().parent.parent


def solution_cells(notebook: str) -> dict[str, str]:
    """A solution notebook's cells' sources by id (``'10-record-and-replay'``)."""
    import json
    data = json.loads((ROOT / 'solutions' / f'{notebook}.ipynb').read_text())
    return {c['id']: ''.join(c['source']) for c in data['cells']}


N04, N08 = solution_cells('04-write-the-subscriber'), solution_cells('08-parameters')
#: The subscriber's parts as 04 writes them, and as 08 writes them.
PARTS_04 = {3: N04['c43c4e05'], 4: N04['9bfa2c2b']}
PARTS_08 = {1: N08['08-18'], 2: N08['08-19'], 3: N08['08-21'], 4: N08['08-24'], 5: N08['08-27']}
N10 = solution_cells('10-record-and-replay')
#: Notebook 10's cells by what they do: ros2nb.course.catch_up(10); the context that imports
#: the monitor; record_hour(bag_path) and its check; replay(bag_path, rate) and its check.
CATCH_UP_10, CONTEXT_10 = N10['b61bfe20'], N10['5d79509a']
RECORD_HOUR_10, CHECK_RECORDING_10 = N10['1266d1a4'], N10['fededecd']
REPLAY_10, CHECK_REPLAY_10 = N10['2cbd3dc0'], N10['efb946fb']
#: nbgrader's lines around a solution, which the learner's file never holds.
MARKERS = ('### BEGIN SOLUTION', '### END SOLUTION')


def body(cell: str) -> str:
    """A ``%%part`` cell's code, as the file gets it (nbgrader's markers left out)."""
    return '\n'.join(line for line in cell.split('\n')[1:] if line.strip() not in MARKERS)


def monitor(parts: dict[int, str]) -> str:
    """The monitor's file as the given ``%%part`` cells (part number -> cell) write it."""
    return '\n\n'.join(body(parts[n]).rstrip('\n') for n in sorted(parts)) + '\n'
