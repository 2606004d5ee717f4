"""What long work says while it works: one line, replaced as the work goes on.

A check that runs in a judge, a colcon build, an hour of simulated time: work that takes
longer than about two seconds says what it is doing (:func:`say`), so that a learner never
looks at a bare ``[*]`` wondering whether anything happens.  Where the line goes depends on
the process that says it:

- in a judge that a learner's kernel asked for a check (:data:`ENV`, set by
  :func:`ros2nb.checks.dispatch.ask_judge` and taken by :func:`tell_on_stderr`): one line on
  the judge's stderr, marked with :data:`MARK`, which the kernel reads as it comes
  (:func:`said`);
- in the learner's kernel, inside :func:`shown`: one display that shows the latest line once
  the work has run :data:`SHOW_AFTER_S`, updated in place (IPython's display handle), and
  emptied when the work ends.  nbval compares a display as it was first sent, and it is first
  sent empty; so a cell's outputs are the same however long its work took (the course's
  stored outputs drop the empty display: :mod:`ros2nb_instructor.authoring.solutions`);
- anywhere else (a test, a script, a subject, a judge while grading): nowhere.

The line only tells what happens; no verdict and no message of a check depends on it.
No ROS import.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import time
from typing import Any, Iterator, Optional

#: Environment variable that asks a judge to say what it does on its stderr.
ENV = 'ROS2NB_WORKING'
#: How a line of what the judge does starts on its stderr (every other line is its own).
MARK = '[ros2nb working] '
#: Seconds of work before its line shows in a kernel: what ends sooner shows nothing.
SHOW_AFTER_S = 1.0
#: Seconds between two updates of the shown line (and two counts a judge writes).
EVERY_S = 0.25


class Working:
    """One piece of the kernel's work whose line shows in the running cell.

    :ivar title: what the work is (``check_entry_points``, ``recording /temperature``).
    :ivar detail: what it does now (the latest :meth:`say`), shown after the title.
    """

    def __init__(self, title: str) -> None:
        self.title, self.detail = title, ''
        self.began = time.monotonic()
        self._handle: Any = None
        self._shown_at = 0.0
        self._shown = ''

    def say(self, detail: str) -> None:
        """Tell what the work does now; shown at once if the display is due."""
        self.detail = detail
        self.tick()

    def text(self, now: float) -> str:
        """The line as it shows ``now`` (``time.monotonic()``), with the seconds so far."""
        what = f'{self.title}: {self.detail}' if self.detail else self.title
        return f'{what} ({now - self.began:.0f} s)'

    def tick(self) -> None:
        """Show the latest line if the work has run long enough and the display is due.

        Only the kernel's main thread (the cell's own) touches the display."""
        now = time.monotonic()
        if now - self.began < SHOW_AFTER_S or now - self._shown_at < EVERY_S \
                or threading.current_thread() is not threading.main_thread():
            return
        text = self.text(now)
        if text == self._shown:
            return
        if self._handle is None:
            self._handle = _display_handle()
            if self._handle is None:
                return
        self._handle.update({'text/plain': text}, raw=True)
        self._shown, self._shown_at = text, now

    def end(self) -> None:
        """Empty the display: the work's answer follows in the cell's own output."""
        if self._handle is not None:
            self._handle.update({}, raw=True)
            self._handle = None


_current: list[Working] = []  # the kernel's work being shown, outermost first
_to_stderr = False  # a judge a kernel asked: say() writes on stderr
_last_said: list[Any] = [0.0, '']  # when and what a judge last wrote


def _display_handle() -> Any:
    """A new display in the running cell, sent empty; None outside a Jupyter kernel."""
    try:
        from IPython import get_ipython
        from IPython.display import display
    except ImportError:  # pragma: no cover - IPython comes with the course
        return None
    shell = get_ipython()
    if shell is None or getattr(shell, 'kernel', None) is None:
        return None
    return display({}, raw=True, display_id=True)


@contextlib.contextmanager
def shown(title: str) -> Iterator[Working]:
    """In the learner's kernel: show what the work inside the block does, as one line.

    A block inside another adds its title to the outer one's line while it runs.
    Introduced in ``03-write-the-publisher.ipynb`` (the first check that runs in a judge).

    :param title: what the work is, e.g. ``'check_sensor_hour'`` or ``'recording /temperature'``;
        :func:`say` tells what it does now.
    """
    if _current:
        outer = _current[-1]
        before = outer.title, outer.detail
        outer.title, outer.detail = f'{outer.title}: {title}', ''
        try:
            yield outer
        finally:
            outer.title, outer.detail = before
        return
    work = Working(title)
    _current.append(work)
    try:
        yield work
    finally:
        _current.remove(work)
        work.end()


def say(line: str, *, often: bool = False) -> None:
    """Tell whoever waits what this process is doing now, e.g. ``'running colcon build'``.

    In the kernel, inside :func:`shown`, it shows after the block's title; in a judge a
    kernel asked for a check, it writes one marked line on stderr; elsewhere it does nothing.

    :param often: the caller says it many times a second (a count that goes up): a judge
        then writes it at most once every :data:`EVERY_S`.
    """
    if _current:
        _current[-1].say(line)
        return
    if not _to_stderr:
        return
    now = time.monotonic()
    if line == _last_said[1] or (often and now - _last_said[0] < EVERY_S):
        return
    _last_said[:] = [now, line]
    try:
        sys.stderr.write(MARK + line.replace('\n', ' ') + '\n')
        sys.stderr.flush()
    except (OSError, ValueError):  # no one reads any more: nothing to tell
        pass


def tell_on_stderr() -> None:
    """In a judge: say what it does on stderr if the kernel that started it asked (:data:`ENV`).

    The request is taken out of the environment, so that no process the judge starts (a
    subject, the learner's program, colcon) inherits it: only the judge's own lines are marked.
    """
    global _to_stderr
    _to_stderr = bool(os.environ.pop(ENV, ''))


def said(stderr_line: str) -> Optional[str]:
    """The line of work a judge's stderr line tells (:data:`MARK`), or None for its own."""
    return stderr_line[len(MARK):].rstrip('\n') if stderr_line.startswith(MARK) else None
