"""The checks' tests run their judge in the test process: one way to set that up.

:func:`judge_session` gives a judge :class:`Session` on a fresh workspace caught up to a
notebook, bound as the current judge, and puts everything back afterwards.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

from ros2nb import course
from ros2nb.checks.base import bind_judge
from ros2nb.checks.dispatch import IN_JUDGE_ENV
from ros2nb.judge.session import Session
from ros2nb.terminal import workspace as ws_module


@contextmanager
def judge_session(root: Path, notebook: int) -> Iterator[Session]:
    """A judge session (this process is the judge) on ``root/ws``, caught up to ``notebook``."""
    saved = {k: os.environ.get(k) for k in ('ROS2NB_WORKSPACE', IN_JUDGE_ENV)}
    os.environ['ROS2NB_WORKSPACE'] = str(root / 'ws')
    os.environ[IN_JUDGE_ENV] = '1'
    ws_module._current = None
    course.catch_up(notebook)
    session = Session(root / 'ws')
    bind_judge(session)
    try:
        yield session
    finally:
        bind_judge(None)
        session.close()
        for key, value in saved.items():
            if value is None:
                os.environ.pop(key, None)
            else:
                os.environ[key] = value
        ws_module._current = None
