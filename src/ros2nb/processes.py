"""The one place that stops processes: a process and everything it started.

Every process ros2nb starts (a node for ``ros2 run``, colcon, a check's helper process)
gets a session and process group of its own (``start_new_session=True``), so a signal
sent to the group reaches whatever it started too.  No mention of ROS here.
"""

from __future__ import annotations

import os
import signal
import subprocess
from typing import Optional, Sequence

#: Seconds a process gets to exit after Ctrl+C (SIGINT) before SIGTERM, then SIGKILL.
STOP_GRACE_S = 5.0
#: Seconds after SIGTERM before SIGKILL.
TERM_GRACE_S = 2.0


def signal_group(proc: subprocess.Popen, sig: int) -> bool:
    """Send ``sig`` to the process group of ``proc``; return False if it is gone."""
    try:
        os.killpg(proc.pid, sig)
    except ProcessLookupError:
        return False
    return True


def stop_process_group(proc: subprocess.Popen, *,
                       signals: Sequence[tuple[int, float]] = (
                           (signal.SIGINT, STOP_GRACE_S), (signal.SIGTERM, TERM_GRACE_S),
                           (signal.SIGKILL, TERM_GRACE_S))) -> Optional[int]:
    """Stop ``proc`` and its whole process group, gently first.

    Each ``(signal, seconds)`` pair is sent to the group in turn until ``proc`` has
    exited; after the last one anything left of the group is killed.  Safe to call on a
    process that already exited.

    :param proc: a process started with ``start_new_session=True``.
    :param signals: signals and the seconds to wait after each.
    :return: the exit code (negative: the signal that ended it), or None if it could not
        be reaped.
    """
    for sig, wait_s in signals:
        if proc.poll() is not None:
            break
        if not signal_group(proc, sig):
            break
        try:
            proc.wait(wait_s)
        except subprocess.TimeoutExpired:
            continue
    signal_group(proc, signal.SIGKILL)  # whatever it started goes with it
    try:
        return proc.wait(TERM_GRACE_S)
    except subprocess.TimeoutExpired:
        return None


def kill_process_group(proc: subprocess.Popen) -> Optional[int]:
    """Kill ``proc`` and its process group at once (SIGKILL); return the exit code."""
    return stop_process_group(proc, signals=((signal.SIGKILL, TERM_GRACE_S),))
