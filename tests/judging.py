"""The checks' tests run their judge in the test process: one way to set that up.

:func:`judge_session` gives a judge :class:`Session` on a fresh workspace caught up to a
notebook and puts everything back afterwards; :func:`run_check` runs a check's body with it,
as the judge process does.
"""

from __future__ import annotations

import os
import re
from contextlib import contextmanager
from pathlib import Path
from typing import Callable, Iterator, Union

import nbformat

from ros2nb import checks, course
from ros2nb.judge.session import Session
from ros2nb.terminal import workspace as ws_module


@contextmanager
def judging_env(root: Path) -> Iterator[Path]:
    """This process as a judge on the workspace ``root/ws``; everything put back afterwards."""
    saved = os.environ.get('ROS2NB_WORKSPACE')
    os.environ['ROS2NB_WORKSPACE'] = str(root / 'ws')
    ws_module._current = None
    try:
        yield root / 'ws'
    finally:
        if saved is None:
            os.environ.pop('ROS2NB_WORKSPACE', None)
        else:
            os.environ['ROS2NB_WORKSPACE'] = saved
        ws_module._current = None


@contextmanager
def judge_session(root: Path, notebook: int) -> Iterator[Session]:
    """A judge session (this process is the judge) on ``root/ws``, caught up to ``notebook``:
    a check's body runs with it through :func:`run_check`."""
    with judging_env(root) as ws:
        course.catch_up(notebook)
        session = Session(ws)
        try:
            yield session
        finally:
            session.close()


def run_check(session: Session, check: Union[str, Callable[..., None]], *args: object,
              **kwargs: object) -> None:
    """Run ``check`` (its name, or the notebook's function of it) with ``session`` as its
    judge, as ``python -m ros2nb.judge`` does."""
    checks.run_check(check if isinstance(check, str) else check.__name__, session,
                     *args, **kwargs)


#: A forging learner's module code that finds the subject's request loop from the learner's import
#: and keeps its handlers and its Subject (nothing happens when the file runs as a program).  The
#: loop is the frame with both names: a forked subject's stack also holds the fork server's frames.
FIND_SUBJECT = '''
import sys as _sys
_frame = _sys._getframe()
while _frame is not None and not {'handlers', 'subject'} <= _frame.f_locals.keys():
    _frame = _frame.f_back
_HANDLERS = _frame.f_locals['handlers'] if _frame else {}
_SUBJECT = _frame.f_locals['subject'] if _frame else None
'''


def answer_cells(path: str) -> tuple[str, dict[str, str]]:
    """A notebook's grading-context cell, and each answer cell by the function it defines
    (nbgrader's ``### BEGIN/END SOLUTION`` lines left out)."""
    context, answers = '', {}
    for cell in nbformat.read(path, as_version=4).cells:
        if 'grading-context' in cell.metadata.get('tags', []):
            context = cell.source
        if cell.metadata.get('nbgrader', {}).get('solution'):
            name = re.match(r'def (\w+)\(', cell.source).group(1)
            answers[name] = '\n'.join(line for line in cell.source.splitlines()
                                      if not line.strip().startswith('###'))
    return context, answers
