"""A real Jupyter kernel and a way to run one cell in it, reading what the learner sees.

Used by ``test_mistakes.py`` and the mutation tests (``mutation_runs.py``): the kernel is a
real IPython kernel; :meth:`Kernel.run` returns the cell's error (its ``ename`` and the
traceback lines IPython shows, colours removed) and its stream text.
"""

from __future__ import annotations

import os
import queue
import re
from typing import Optional

from jupyter_client.manager import start_new_kernel

from waiting import wait_until


class CellHung(AssertionError):
    """A cell that neither finished nor worked for the seconds it was given."""


class Kernel:
    """A real kernel and a way to run one cell in it."""

    def __init__(self, workspace: str, env: Optional[dict[str, str]] = None) -> None:
        environment = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
        environment.update(env or {})
        environment['ROS2NB_WORKSPACE'] = workspace
        self.manager, self.client = start_new_kernel(kernel_name='python3', env=environment)

    def run(self, code: str, seconds: float = 60) -> dict:
        """Run a cell; return its error (ename, traceback) and its stream text.

        :param seconds: for the whole cell (a node may print for ever): of the kernel's
            work, or of its idle waiting (tests/waiting.py), not of the wall clock.
        :raises CellHung: when the cell had them and had not finished.
        """
        msg_id = self.client.execute(code)
        result: dict = {'error': None, 'stdout': '', 'stderr': ''}

        def finished() -> bool:
            try:
                msg = self.client.get_iopub_msg(timeout=0.25)
            except queue.Empty:
                return False
            if msg['parent_header'].get('msg_id') != msg_id:
                return False
            kind, content = msg['msg_type'], msg['content']
            if kind == 'error':
                result['error'] = {'ename': content['ename'],
                                   'traceback': [re.sub(r'\x1b\[[0-9;]*m', '', line)
                                                 for line in content['traceback']]}
            elif kind == 'stream':
                result[content['name']] += content['text']
            return kind == 'status' and content['execution_state'] == 'idle'

        if not wait_until(finished, seconds, interval=0):
            raise CellHung(f'the cell did not finish within {seconds} s: {code!r}')
        return result

    def one_line(self, code: str, *fragments: str) -> str:
        """Run a cell that must fail; check it shows one line with every fragment."""
        result = self.run(code)
        assert result['error'] is not None, f'no error for {code!r}: {result}'
        shown = result['error']['traceback']
        assert len(shown) == 1, shown
        for fragment in fragments:
            assert fragment in shown[0], (fragment, shown[0])
        return shown[0]

    def close(self) -> None:
        self.client.stop_channels()
        self.manager.shutdown_kernel(now=True)
