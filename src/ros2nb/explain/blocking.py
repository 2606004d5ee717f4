"""``time.sleep()`` refused inside a node's callback in a check's subject, with one line.

Part of :mod:`ros2nb.explain`; installed in every judge's subject (:mod:`ros2nb.subject`).
A callback that sleeps holds its node up: no other callback runs and no message is taken
until it returns, and on the grader's clock every step waits for it (a second's sleep per
reading kept a check of notebook 03 silent for minutes, then let it pass).  So the
learner's ``time.sleep`` in a callback raises at once, naming itself, and the check says so
at its line.  The course's own code sleeps as before, and so does everything outside a
callback; a kernel leaves ``time.sleep`` alone (notebook 06 shows there what a callback
that sleeps does to an executor).  Introduced in ``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import sys
import time
from typing import Any

from ..errors import Ros2nbError
from .frames import in_callback, is_library_file

_GUARDED = '_ros2nb_guarded'


class BlockingCallError(Ros2nbError):
    """The learner's callback called ``time.sleep()``."""


def guard_sleep() -> None:
    """Make ``time.sleep`` refuse, with one line, to wait in a callback of the learner's
    (their code calling it while an rclpy executor runs it).  Installing it again changes
    nothing.

    Introduced in ``03-write-the-publisher.ipynb`` (installed in a check's subject).
    """
    original = time.sleep
    if getattr(original, _GUARDED, False):
        return

    def sleep(seconds: Any) -> None:
        caller = sys._getframe(1)
        if not is_library_file(caller.f_code.co_filename) and in_callback(caller):
            raise BlockingCallError(
                f'time.sleep({seconds!r}) in a callback holds its node up: nothing else runs, '
                'and no message is taken, until it returns: remove it; a timer '
                '(create_timer) already sets the pace.')
        original(seconds)

    sleep.__doc__ = original.__doc__
    setattr(sleep, _GUARDED, True)
    time.sleep = sleep
