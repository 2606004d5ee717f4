"""Where an error went through the learner's own code: their frames, not the libraries'.

Part of :mod:`ros2nb.explain`: the explanations ask here which frame of a traceback is the
learner's (a cell, or a file of their workspace) and which are Python's, an installed
package's (rclpy, the messages, rosbags, IPython) or ros2nb's own.
"""

from __future__ import annotations

import os
import site
import sysconfig
from types import FrameType, TracebackType
from typing import Iterator, Optional

#: The ros2nb package: its files are not the learner's.
_HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _library_dirs() -> tuple[str, ...]:
    dirs = {_HERE, *site.getsitepackages(), site.getusersitepackages()}
    for key in ('stdlib', 'platstdlib', 'purelib', 'platlib'):
        dirs.add(sysconfig.get_paths()[key])
    return tuple(sorted(os.path.abspath(d) + os.sep for d in dirs if d))


_LIBRARY_DIRS = _library_dirs()


def is_library_file(path: str) -> bool:
    """True for files of Python, installed packages (rclpy, messages, IPython) and ros2nb."""
    path = os.path.abspath(path)
    return path.startswith(_LIBRARY_DIRS) or path.startswith('<frozen')


def learner_entry(exc: BaseException) -> Optional[TracebackType]:
    """The innermost traceback entry in the learner's own code (a cell or their file)."""
    found, tb = None, exc.__traceback__
    while tb is not None:
        if not is_library_file(tb.tb_frame.f_code.co_filename):
            found = tb
        tb = tb.tb_next
    return found


def frames_of(exc: BaseException) -> Iterator[FrameType]:
    """The frames of ``exc``'s traceback, outermost first."""
    tb = exc.__traceback__
    while tb is not None:
        yield tb.tb_frame
        tb = tb.tb_next


def raised_in(exc: BaseException, function: str) -> bool:
    """True when the innermost frame of ``exc`` is a library function named ``function``."""
    frames = list(frames_of(exc))
    return bool(frames) and frames[-1].f_code.co_name == function and \
        is_library_file(frames[-1].f_code.co_filename)


def learner_frame(exc: BaseException) -> Optional[FrameType]:
    """The innermost frame of the learner's own code (a cell or their file), or None."""
    entry = learner_entry(exc)
    return entry.tb_frame if entry is not None else None


def in_callback(frame: Optional[FrameType]) -> bool:
    """True when an rclpy executor is running ``frame`` (it is a callback's, or called from
    one)."""
    while frame is not None:
        if frame.f_code.co_filename.endswith(os.path.join('rclpy', 'executors.py')):
            return True
        frame = frame.f_back
    return False
