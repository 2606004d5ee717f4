"""A node from the learner's file, created in a subject and watched by the judge.

Part of :mod:`ros2nb.checks`: what the checks of notebooks 03 and 04 share.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from ..errors import CheckFailed
from .base import ARRIVAL_TIMEOUT_S, Judge, learner_error


def new_node(judge: Judge, relative: str, cls: str, *, placeholders: tuple[str, ...] = (),
              seed: Optional[int] = None) -> tuple[Any, dict]:
    """Create the learner's node from their file in a subject; raise for what went wrong."""
    subject = judge.file_subject(relative)
    reply = subject.request('new_node', cls=cls, placeholders=list(placeholders),
                            seed=seed)
    file = Path(relative).name
    if reply.get('no_class'):
        others = reply['classes']
        hint = (f' (it defines {", ".join(others)}: names must match exactly; the tutorial '
                'misspelt TemperaturSensor in places)' if others else '')
        raise CheckFailed(f'{file} defines no class {cls}{hint}.')
    if reply.get('refused'):
        raise CheckFailed(reply['refused'])
    if not reply['ok']:
        raise learner_error(f'{cls}()', reply['error'])
    return subject, reply


def started_log_verdict(judge: Judge, info: dict, mark: int, cls: str) -> None:
    if info['started_lines'] == 0 or not caught_up(judge, info, mark, info['started_lines']):
        raise CheckFailed(f'{cls} logged nothing when it started: log a line such as '
                          f"'{cls[:11]} {cls[11:]} Node Started' with the node's logger.")


def caught_up(judge: Judge, info: dict, mark: int, lines: int) -> list[str]:
    """Wait until the judge has ``lines`` log lines of the node after ``mark``; return them."""
    observer = judge.observer
    observer.wait_until(lambda: len(observer.lines_of(info['name'], mark)) >= lines,
                        ARRIVAL_TIMEOUT_S)
    return observer.lines_of(info['name'], mark)
