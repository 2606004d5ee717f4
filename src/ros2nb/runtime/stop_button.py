"""The Stop button while ros2nb spins: acted on where it is safe, or in the learner's callback.

Part of :class:`ros2nb.runtime.Runtime` (used by :class:`~ros2nb.runtime.spinning.Spinning`).
Jupyter's Stop button sends SIGINT, and Python raises ``KeyboardInterrupt`` at whatever line
the main thread runs then.  While ros2nb spins, that line is most often inside rclpy's
executor or a message's constructor, which do not expect it: a message taken by rclpy's C
code was dropped and the exception with it (the spin went on for ever), a task was left half
made (a warning after the spin's line), a cell ended with no line at all and the next one
hung.  So while a :class:`StopButton` is held, a press only marks the stop, and the
spin ends at its next safe point (:meth:`StopButton.point`, between two callbacks).  It is
acted on at once inside the learner's own callback and in a wait that may never end
(:meth:`StopButton.waiting`), and a second press before a safe point came interrupts
wherever the thread is.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from types import CodeType, FrameType
from typing import Iterator, Optional

from ..explain.frames import is_library_file


class StopButton:
    """SIGINT in the main thread, while held: marked, then acted on at a safe point.

    :param callback_entry: the code that runs one callback (``Spinning._run_one``): a press
        is acted on at once when learner code runs below it.
    """

    def __init__(self, callback_entry: CodeType) -> None:
        self._entry = callback_entry
        self._pressed = False
        self._held = False
        self._waiting = 0

    @contextlib.contextmanager
    def held(self) -> Iterator[None]:
        """Hold the Stop button for the block (re-entrant; only the main thread, and only
        where SIGINT would raise ``KeyboardInterrupt``: elsewhere the block runs as it is).

        :raises KeyboardInterrupt: at the block's end, if pressed and not yet acted on.
        """
        if (self._held or threading.current_thread() is not threading.main_thread()
                or signal.getsignal(signal.SIGINT) is not signal.default_int_handler):
            yield
            return
        self._held, self._pressed = True, False
        signal.signal(signal.SIGINT, self._on_press)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, signal.default_int_handler)
            self._held = False
        self.point()

    def point(self) -> None:
        """A safe point: :raises KeyboardInterrupt: if the Stop button was pressed."""
        if self._pressed:
            self._pressed = False
            raise KeyboardInterrupt

    @contextlib.contextmanager
    def waiting(self) -> Iterator[None]:
        """A wait the Stop button ends at once (one that may never end: for the background
        thread to pause, while it runs a callback that does not return).

        :raises KeyboardInterrupt: on entry if already pressed, or when pressed in the block.
        """
        self.point()
        self._waiting += 1
        try:
            yield
        finally:
            self._waiting -= 1

    def _on_press(self, _signum: int, frame: Optional[FrameType]) -> None:
        if self._pressed or self._waiting or self._in_learner_callback(frame):
            self._pressed = False
            raise KeyboardInterrupt
        self._pressed = True

    def _in_learner_callback(self, frame: Optional[FrameType]) -> bool:
        """True when the learner's code runs inside a callback the spin called."""
        learner = False
        while frame is not None:
            if frame.f_code is self._entry:
                return learner
            learner = learner or not is_library_file(frame.f_code.co_filename)
            frame = frame.f_back
        return False
