"""The one place that stops processes: a process and everything it started.

Every process ros2nb starts (a node for ``ros2 run``, colcon, a check's helper process)
gets a session and process group of its own (``start_new_session=True``), so a signal
sent to the group reaches whatever it started too.  It is also the one place that decides
when a process has had long enough (:class:`Patience`).  No mention of ROS here.
"""

from __future__ import annotations

import atexit
import os
import signal
import subprocess
import sys
import time
from collections import deque
from typing import NoReturn, Optional, Sequence

#: Seconds a process gets to exit after Ctrl+C (SIGINT) before SIGTERM, then SIGKILL.
STOP_GRACE_S = 5.0
#: Seconds after SIGTERM before SIGKILL.
TERM_GRACE_S = 2.0
#: Seconds a process ended at once (kill_process_group) gets between SIGTERM and SIGKILL.
KILL_GRACE_S = 1.0


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
    """End ``proc`` and its process group now: SIGTERM, and SIGKILL :data:`KILL_GRACE_S`
    later; return the exit code.

    Not SIGKILL at once: a ROS process killed so leaves its Fast DDS shared-memory ports
    behind, and the next participants on that domain took seconds more to be discovered
    (2-6 s instead of 0.3 s, measured); rclpy ends on SIGTERM in a fraction of that.
    """
    return stop_process_group(proc, signals=((signal.SIGTERM, KILL_GRACE_S),
                                             (signal.SIGKILL, TERM_GRACE_S)))


#: A process tree using less than this share of one CPU is waiting, not working.
BUSY_SHARE = 0.05
#: Seconds over which that share is measured.
BUSY_WINDOW_S = 5.0
#: A process tree one of whose threads stood ready to run in this share of the looks at it
#: is working (the kernel brings its time on the run queue up to date only when it runs).
READY_SHARE = 0.5
#: However busy it is, a process tree gets at most this many times its limit on the wall clock.
WALL_LIMIT_FACTOR = 10.0
#: Seconds between two looks at a process that is asked to exit.
POLL_EXIT_S = 0.1
_TICKS_PER_S = os.sysconf('SC_CLK_TCK')


def _processes() -> tuple[dict[int, list[int]], dict[int, float]]:
    """Every process's children, and the CPU seconds each used (with its reaped children's)."""
    children: dict[int, list[int]] = {}
    cpu: dict[int, float] = {}
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open(f'/proc/{entry}/stat') as stat:
                fields = stat.read().rsplit(')', 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(entry))
        # utime, stime, cutime, cstime: fields 14-17 of proc(5), counted from "state" here
        cpu[int(entry)] = sum(int(field) for field in fields[11:15]) / _TICKS_PER_S
    return children, cpu


def _children() -> dict[int, list[int]]:
    """Every process's children, read from /proc."""
    return _processes()[0]


def child_pids(pid: int) -> list[int]:
    """The processes ``pid`` started that are still there (running or not yet reaped)."""
    return _children().get(pid, [])


def _tree(pid: int, children: dict[int, list[int]]) -> list[int]:
    """``pid`` and every process under it."""
    found, pending = [pid], [pid]
    while pending:
        below = children.get(pending.pop(), [])
        found += below
        pending += below
    return found


def tree_pids(pid: int) -> list[int]:
    """``pid`` and every process under it now (read from /proc)."""
    return _tree(pid, _children())


def tree_cpu_seconds(pid: int) -> float:
    """CPU seconds (user + system) used so far by ``pid`` and every process under it.

    Processes of the tree that already ended count when their parent has reaped them.
    A process that is gone counts 0.
    """
    children, cpu = _processes()
    return sum(cpu.get(each, 0.0) for each in _tree(pid, children))


def queued_seconds(pids: Sequence[int]) -> tuple[float, bool]:
    """How much the threads of ``pids`` stood ready to run, waiting on the run queue for a
    CPU: the seconds the kernel counted (the second field of ``/proc/PID/task/TID/schedstat``,
    brought up to date only when a thread gets a CPU), and whether one of them stands ready
    now (state R).  Gone processes and threads, and a kernel without schedstats, count
    nothing."""
    total, ready = 0.0, False
    for pid in pids:
        try:
            tasks = os.listdir(f'/proc/{pid}/task')
        except OSError:
            continue
        for task in tasks:
            try:
                with open(f'/proc/{pid}/task/{task}/stat') as stat:
                    ready = ready or stat.read().rsplit(')', 1)[1].split()[0] == 'R'
                with open(f'/proc/{pid}/task/{task}/schedstat') as schedstat:
                    total += int(schedstat.read().split()[1]) / 1e9
            except (OSError, IndexError, ValueError):
                continue
    return total, ready


def tree_work(pid: int) -> tuple[float, float, bool]:
    """What a process tree has done, as the kernel counts it: the CPU seconds of ``pid`` and
    every process under it; the seconds their threads stood ready on the run queue for a
    CPU (:func:`queued_seconds`); and whether one of them stands ready now.

    The watching process's own threads do not count: a judge at work (the corpora grade in
    the test process, its executor and Fast DDS threads beside the watch) stood ready in
    every look on a busy machine, and a ``main()`` that never starts ROS was given ten
    times its limit (124 s instead of 20 beside two CPU burners).

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).
    """
    children, cpu = _processes()
    tree = _tree(pid, children)
    queued, ready = queued_seconds(tree)
    return sum(cpu.get(each, 0.0) for each in tree), queued, ready


class Patience:
    """Whether a process tree asked to do something has had long enough to do it.

    A limit on the wall clock alone cuts honest work short on a busy machine, where a
    process gets a fraction of a CPU.  So the limit counts work: the tree has had long
    enough once it used ``limit_s`` CPU seconds (an endless loop), or once ``limit_s``
    seconds passed on the wall clock while it sat waiting: less than :data:`BUSY_SHARE` of a
    CPU over the last :data:`BUSY_WINDOW_S` seconds, counting the time its threads stood
    ready on the run queue for a CPU (:func:`queued_seconds`), or one of them stood ready in
    :data:`READY_SHARE` of the looks.  A program the scheduler starves is working, not
    waiting: beside two CPU burners and a test run, a starting program was measured at
    0.07 s of CPU and 8.7 s queued in its first 10 s.  A tree that keeps working slowly is
    cut after ``WALL_LIMIT_FACTOR * limit_s`` seconds.

    :param pid: the process at the top of the tree (a sandbox's own process is fine).
    :param limit_s: seconds of CPU time, or of waiting, the tree is given.
    :param started: when the tree was asked (``time.monotonic()``; default now).  CPU time
        counts from now: reading /proc costs a few milliseconds on a busy machine, so a
        caller whose answers mostly come at once may start measuring late.
    """

    def __init__(self, pid: int, limit_s: float, started: Optional[float] = None) -> None:
        self.pid, self.limit_s = pid, limit_s
        self.started = time.monotonic() if started is None else started
        self.cpu_at_start, queued, ready = tree_work(pid)
        # (when, CPU and queued seconds then, a thread ready then): the busy share is
        # measured between real samples
        self._samples: deque[tuple[float, float, bool]] = deque(
            [(time.monotonic(), self.cpu_at_start + queued, ready)])

    def exhausted(self) -> bool:
        """True once the tree has had its limit (call it every fraction of a second)."""
        (cpu, queued, ready), now = tree_work(self.pid), time.monotonic()
        self._samples.append((now, cpu + queued, ready))
        while len(self._samples) > 2 and now - self._samples[1][0] >= BUSY_WINDOW_S:
            self._samples.popleft()
        waited = now - self.started
        if cpu - self.cpu_at_start >= self.limit_s or waited >= WALL_LIMIT_FACTOR * self.limit_s:
            return True
        if waited < self.limit_s:
            return False
        (since, busy_then, _), recent = self._samples[0], list(self._samples)[1:]
        if sum(sample[2] for sample in recent) >= READY_SHARE * len(recent):
            return False  # starved, not waiting: the kernel counts its queueing late
        return cpu + queued - busy_then < BUSY_SHARE * (now - since)


def wait_patiently(proc: subprocess.Popen, limit_s: float) -> Optional[int]:
    """Wait for ``proc`` to exit, with :class:`Patience` (``limit_s`` of its tree's work, or
    of its waiting): on a busy machine a slow exit is not a hang.

    Introduced in ``03-write-the-publisher.ipynb`` (a main() stopped with Ctrl+C).

    :return: its exit code, or None when it had its limit and still runs.
    """
    patience = Patience(proc.pid, limit_s)
    while True:
        try:
            return proc.wait(POLL_EXIT_S)
        except subprocess.TimeoutExpired:
            if patience.exhausted():
                return None


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
