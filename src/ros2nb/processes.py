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


def _children() -> dict[int, list[int]]:
    """Every process's children, read from /proc."""
    found: dict[int, list[int]] = {}
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open(f'/proc/{entry}/stat') as stat:
                fields = stat.read().rsplit(')', 1)[1].split()
        except OSError:
            continue
        found.setdefault(int(fields[1]), []).append(int(entry))
    return found


def _name(pid: int) -> str:
    try:
        with open(f'/proc/{pid}/comm') as comm:
            return comm.read().strip()
    except OSError:
        return ''


def interrupt(proc: subprocess.Popen, sig: int = signal.SIGINT) -> None:
    """Press Ctrl+C for ``proc``: send ``sig`` to its process group, as a terminal does.

    A program started inside a sandbox (bubblewrap) is reached past the sandbox's own
    processes, which would otherwise take the signal and kill the sandbox before the
    program could handle it: ``sig`` goes to every process under ``proc`` that is not
    bubblewrap.
    """
    if _name(proc.pid) != 'bwrap':
        signal_group(proc, sig)
        return
    children = _children()
    pending, targets = list(children.get(proc.pid, [])), []
    while pending:
        pid = pending.pop()
        pending.extend(children.get(pid, []))
        if _name(pid) != 'bwrap':
            targets.append(pid)
    for pid in targets:
        try:
            os.kill(pid, sig)
        except ProcessLookupError:
            pass
