"""The one place that stops processes: a process and everything it started.

Every process ros2nb starts (a node for ``ros2 run``, colcon, a check's helper process)
gets a session and process group of its own (``start_new_session=True``), so a signal
sent to the group reaches whatever it started too.  How long a process may take is
:mod:`ros2nb.patience`'s to decide.  No mention of ROS here.
"""

from __future__ import annotations

import atexit
import ctypes
import os
import signal
import subprocess
import sys
import time
from typing import NoReturn, Optional, Protocol, Sequence

from .patience import POLL_S, Patience, asked, process_tree, psutil_module, wait_for_work

#: Seconds a process gets to exit after Ctrl+C (SIGINT) before SIGTERM, then SIGKILL.
STOP_GRACE_S = 5.0
#: Seconds after SIGTERM before SIGKILL.
TERM_GRACE_S = 2.0
#: Seconds a process ended at once (kill_process_group) gets between SIGTERM and SIGKILL.
KILL_GRACE_S = 1.0


class Process(Protocol):
    """A process the course started in a session of its own: a :class:`subprocess.Popen`, or
    a child of the fork server (:class:`ros2nb.subject.forked.ForkedProcess`)."""

    pid: int  #: also its process group's id
    returncode: Optional[int]  #: its exit code once reaped (negative: the signal), else None

    def poll(self) -> Optional[int]:
        """Its exit code once it ended, else None (it never waits)."""

    def wait(self, timeout: Optional[float] = None) -> int:
        """Its exit code, waited for ``timeout`` s at most (then subprocess.TimeoutExpired)."""


def signal_group(proc: Process, sig: int) -> bool:
    """Send ``sig`` to the process group of ``proc``; return False if it is gone."""
    try:
        os.killpg(proc.pid, sig)
    except ProcessLookupError:
        return False
    return True


def stop_process_group(proc: Process, *,
                       signals: Sequence[tuple[int, float]] = (
                           (signal.SIGINT, STOP_GRACE_S), (signal.SIGTERM, TERM_GRACE_S),
                           (signal.SIGKILL, TERM_GRACE_S))) -> Optional[int]:
    """Stop ``proc`` and its whole process group, gently first.

    Each ``(signal, seconds)`` pair is sent to the group in turn until ``proc`` has
    exited; after the last one anything left of the group is killed.  Safe to call on a
    process that already exited.

    :param proc: a process started with ``start_new_session=True``.
    :param signals: signals and the seconds to wait after each (:func:`wait_patiently`:
        seconds of its work while it works, of the wall clock while it waits).
    :return: the exit code (negative: the signal that ended it), or None if it could not
        be reaped.
    """
    for sig, wait_s in signals:
        if proc.poll() is not None:
            break
        if not signal_group(proc, sig):
            break
        wait_patiently(proc, wait_s)  # a busy machine slows an exit: it is not a refusal
    signal_group(proc, signal.SIGKILL)  # whatever it started goes with it
    try:
        return proc.wait(TERM_GRACE_S)
    except subprocess.TimeoutExpired:
        return None


def kill_process_group(proc: Process) -> Optional[int]:
    """End ``proc`` and its process group now: SIGTERM, and SIGKILL :data:`KILL_GRACE_S`
    later; return the exit code.

    Not SIGKILL at once: a ROS process killed so leaves its Fast DDS shared-memory ports
    behind, and the next participants on that domain take seconds more to be discovered
    (docs/decisions.md); rclpy ends on SIGTERM in a fraction of that.
    """
    return stop_process_group(proc, signals=((signal.SIGTERM, KILL_GRACE_S),
                                             (signal.SIGKILL, TERM_GRACE_S)))


def wait_patiently(proc: Process, limit_s: float) -> Optional[int]:
    """Wait for ``proc`` to exit, with :class:`Patience` (``limit_s`` of its tree's work, or
    of its idle waiting): on a busy machine a slow exit is not a hang.

    Introduced in ``03-write-the-publisher.ipynb`` (a main() stopped with Ctrl+C).

    :return: its exit code, or None when it had its limit and still runs.
    """
    if wait_for_work(lambda: proc.poll() is not None, [proc.pid], limit_s):
        return proc.returncode
    return None


def until_waiting(proc: Process, limit_s: float) -> bool:
    """Wait until the main thread of every process under ``proc`` (bubblewrap's own aside)
    sits waiting, in two looks in a row: a program idle in its spin, as a person at a
    terminal sees it before pressing Ctrl+C.  Whether a signal lands in the spin's wait or
    between two of its rounds then depends on the program, not on how busy the machine is.

    :param limit_s: how long to wait at most (:class:`Patience`): a program that never waits
        (a loop) is signalled all the same.
    :return: True when it sat waiting, False when it had its limit (or ended).
    """
    patience, calm = Patience(proc.pid, limit_s), 0
    while calm < 2:
        if proc.poll() is not None or patience.exhausted():
            return False
        tree = [p for p in process_tree([proc.pid]) if asked(p, 'name', '') != 'bwrap']
        waiting = ('sleeping', 'disk-sleep')  # psutil's STATUS_SLEEPING, STATUS_DISK_SLEEP
        calm = calm + 1 if tree and all(asked(p, 'status', '') in waiting for p in tree) else 0
        time.sleep(POLL_S)
    return True


def interrupt(proc: Process, sig: int = signal.SIGINT) -> None:
    """Press Ctrl+C for ``proc``: send ``sig`` to its process group, as a terminal does.

    A program started inside a sandbox (bubblewrap) is reached past the sandbox's own
    processes, which would otherwise take the signal and kill the sandbox before the
    program could handle it: ``sig`` goes to every process under ``proc`` that is not
    bubblewrap.
    """
    tree = process_tree([proc.pid])
    if not tree or asked(tree[0], 'name', '') != 'bwrap':
        signal_group(proc, sig)
        return
    for process in tree[1:]:
        if asked(process, 'name', '') != 'bwrap':
            try:
                process.send_signal(sig)
            except psutil_module().Error:
                pass


#: ``prctl`` option: the signal this process gets when the thread that started it ends.
PR_SET_PDEATHSIG = 1


def die_with_parent(sig: int = signal.SIGTERM) -> None:
    """Have the kernel send ``sig`` to this process when its parent ends (Linux's parent-death
    signal; nothing elsewhere): a judge whose kernel was restarted or killed, a fork server
    whose judge was, a subject whose server was, does not live on with no one to end it.
    A process whose parent ended while this was being set (it was adopted meanwhile) gets
    ``sig`` now.

    Call it first thing; ``sig`` must end the process or lead it to end.
    """
    parent = os.getppid()
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0)
    except (OSError, AttributeError):  # not Linux: nothing to set
        return
    if os.getppid() != parent:  # (a sandbox's first process has parent 1: not a sign)
        os.kill(os.getpid(), sig)


def end_this_process(code: int) -> NoReturn:
    """End the calling process with exit status ``code``, as ``sys.exit`` would, but sooner.

    The exit handlers (:mod:`atexit`) run and standard output and error are flushed, as at
    a normal exit; what is skipped is the interpreter's teardown of every module and object,
    which in a process that ran ROS costs a tenth of a CPU-second (Fast DDS's libraries, a
    thousand modules).  The judge and its subjects end this way, after they have closed
    what they opened: ``make test`` starts hundreds of them.  multiprocessing ends its child
    processes with ``os._exit`` for the same reason.  Not for the learner's kernel, whose
    exit handlers other code registers.

    :param code: the exit status (0-255).
    """
    try:
        atexit._run_exitfuncs()  # what a normal exit runs first, in the same order
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # closed, or its reader gone: nothing more to say
                pass
        os._exit(code)
