"""Where a node's log line was called from, found without reading source files.

Part of :class:`ros2nb.runtime.Runtime`.  rclpy's logger puts the caller's function, file
and line in every ``/rosout`` message (and keys ``once=``/``throttle_duration_sec=`` on
them).  To find the caller it asks :func:`inspect.getframeinfo` for every frame it walks,
which also reads a line of source from disk, and resolves each file name with
:func:`os.path.realpath`, for every log line, and notebook 10's ``record_hour`` logs 7200
in a simulated hour (what that cost: docs/decisions.md).  The same
caller is found here from each frame's own file name (what ``getframeinfo`` returns for
it, without its look at the disk) and each file's real path remembered (only used to skip
rclpy's own frames, whose files do not move).  The messages are unchanged:
``tests/test_runtime.py`` compares the caller rclpy's own code finds with this one's.
"""

from __future__ import annotations

import functools
import importlib.machinery
import inspect
import os
import sys
from types import FrameType
from typing import Optional

from rclpy.impl import rcutils_logger

_rclpy_find_caller = rcutils_logger._find_caller
_rclpy_caller_id_new = rcutils_logger.CallerId.__new__


@functools.lru_cache(maxsize=4096)
def _real_path(filename: str) -> str:
    return os.path.realpath(filename)


#: File names of compiled code, which inspect maps back to their source's name.
_BYTECODE_SUFFIXES = tuple(importlib.machinery.DEBUG_BYTECODE_SUFFIXES
                           + importlib.machinery.OPTIMIZED_BYTECODE_SUFFIXES)


def _file_of(frame: FrameType) -> str:
    """``inspect.getframeinfo(frame).filename``, without its look at the disk: that is the
    code's own file name unless it names compiled code (inspect returns the name itself,
    or None and then the name itself, for every other file)."""
    name = frame.f_code.co_filename
    if name.endswith(_BYTECODE_SUFFIXES):
        return inspect.getframeinfo(frame, context=0).filename
    return name


def find_caller(frame: FrameType) -> FrameType:
    """The first frame outside rclpy's logging, as rclpy's ``_find_caller`` finds it."""
    if rcutils_logger._populate_internal_callers:
        _rclpy_find_caller(frame)  # rclpy fills in its own files' names on first use
    internal = rcutils_logger._internal_callers
    while any(name in _real_path(_file_of(frame)) for name in internal):
        if frame.f_back is None:  # the stack's first frame: no caller outside rclpy's logging
            return frame
        frame = frame.f_back
    return frame


def _caller_id_new(cls: type, frame: Optional[FrameType] = None) -> rcutils_logger.CallerId:
    if not frame:  # from rclpy's log(): its frames are skipped, as from rclpy's own __new__
        frame = find_caller(sys._getframe(1))  # the frame that called this one
    return tuple.__new__(cls, (frame.f_code.co_name, os.path.abspath(_file_of(frame)),
                               frame.f_lineno, frame.f_lasti))


def use_cheaper_caller_lookup() -> None:
    """Make rclpy's loggers in this process find their caller this way (idempotent)."""
    rcutils_logger._find_caller = find_caller
    setattr(rcutils_logger.CallerId, '__new__', _caller_id_new)


def use_rclpy_caller_lookup() -> None:
    """Put rclpy's own caller lookup back (the tests compare the two)."""
    rcutils_logger._find_caller = _rclpy_find_caller
    setattr(rcutils_logger.CallerId, '__new__', _rclpy_caller_id_new)
