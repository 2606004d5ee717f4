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
from typing import Any, Callable, NoReturn, Optional, Protocol, Sequence

#: Seconds a process gets to exit after Ctrl+C (SIGINT) before SIGTERM, then SIGKILL.
STOP_GRACE_S = 5.0
#: Seconds after SIGTERM before SIGKILL.
TERM_GRACE_S = 2.0
#: Seconds a process ended at once (kill_process_group) gets between SIGTERM and SIGKILL.
KILL_GRACE_S = 1.0
#: Seconds between two looks at a condition while waiting for it.
POLL_S = 0.02


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


#: A process tree using less than this share of one CPU between two looks, counting the
#: time its threads stood ready on the run queue, is waiting, not working.
BUSY_SHARE = 0.05
#: Seconds between two looks at a process tree's work in /proc (each look reads every
#: process's stat: milliseconds on a busy machine).
LOOK_S = 0.25
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


def _trees(pids: Sequence[int], children: dict[int, list[int]]) -> list[int]:
    """Each of ``pids`` and every process under them, once."""
    found, pending = list(dict.fromkeys(pids)), list(dict.fromkeys(pids))
    while pending:
        below = [pid for pid in children.get(pending.pop(), []) if pid not in found]
        found += below
        pending += below
    return found


def tree_pids(pid: int) -> list[int]:
    """``pid`` and every process under it now (read from /proc)."""
    return _trees([pid], _children())


def tree_cpu_seconds(pid: int) -> float:
    """CPU seconds (user + system) used so far by ``pid`` and every process under it.

    Processes of the tree that already ended count when their parent has reaped them.
    A process that is gone counts 0.
    """
    children, cpu = _processes()
    return sum(cpu.get(each, 0.0) for each in _trees([pid], children))


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


def tree_work(pids: int | Sequence[int]) -> tuple[float, float, bool]:
    """What process trees have done, as the kernel counts it: the CPU seconds of ``pids``
    and every process under them; the seconds their threads stood ready on the run queue
    for a CPU (:func:`queued_seconds`); and whether one of them stands ready now.

    Only the trees count, not the process that watches them: a judge at work beside its
    watch (its executor and Fast DDS threads, busy with other subjects) would make every
    program it waits on look busy.

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).
    """
    children, cpu = _processes()
    trees = _trees([pids] if isinstance(pids, int) else pids, children)
    queued, ready = queued_seconds(trees)
    return sum(cpu.get(each, 0.0) for each in trees), queued, ready


class Patience:
    """Whether process trees asked to do something have had long enough to do it.

    A limit on the wall clock alone cuts honest work short on a busy machine, where a
    process gets a fraction of a CPU.  So the limit counts what the
    trees do: they have had long enough once they used ``limit_s`` CPU seconds (an endless
    loop), or once they sat idle, waiting for an event, for ``limit_s`` seconds on the wall
    clock.  Between two looks they sat idle when they used less than :data:`BUSY_SHARE` of
    a CPU, counting the time their threads stood ready on the run queue, and none of their
    threads stands ready at the look (the kernel brings the time on the run queue up to
    date only when a thread runs).  A program the scheduler starves is working, not
    waiting, however long that takes: what bounds a machine that never runs it is outside
    (a test's time limit, a sandbox's wall time, the learner's stop button).

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).

    :param pids: the process (or processes) at the top of the trees (a sandbox's own
        process is fine).
    :param limit_s: seconds of CPU time, or of idle waiting, the trees are given.
    :param started: when the trees were asked (``time.monotonic()``; default now); the time
        since then counts as waiting.  CPU time counts from now: a caller whose answers
        mostly come at once starts measuring late, and spares /proc meanwhile.
    """

    def __init__(self, pids: int | Sequence[int], limit_s: float,
                 started: Optional[float] = None) -> None:
        self.pids = [pids] if isinstance(pids, int) else list(pids)
        self.limit_s = limit_s
        now = time.monotonic()
        self.started = now if started is None else started
        self.cpu_at_start, queued, _ready = tree_work(self.pids)
        #: Seconds on the wall clock the trees sat idle so far.
        self.idle_s = now - self.started
        self._look = (now, self.cpu_at_start + queued)
        self._verdict = False

    def exhausted(self) -> bool:
        """True once the trees have had their limit (call it every fraction of a second: it
        reads /proc once every :data:`LOOK_S`)."""
        now = time.monotonic()
        then, busy_then = self._look
        if self._verdict or now - then < LOOK_S:
            return self._verdict
        cpu, queued, ready = tree_work(self.pids)
        if not ready and cpu + queued - busy_then < BUSY_SHARE * (now - then):
            self.idle_s += now - then
        self._look = (now, cpu + queued)
        self._verdict = cpu - self.cpu_at_start >= self.limit_s or self.idle_s >= self.limit_s
        return self._verdict


def poll(condition: Callable[[], Any], seconds: float) -> bool:
    """Look at ``condition()`` every few milliseconds for ``seconds``; whether it held."""
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() >= deadline:
            return False
        time.sleep(POLL_S)
    return True


def wait_for_work(condition: Callable[[], Any], pids: Sequence[int], limit_s: float, *,
                  look: Callable[[Callable[[], Any], float], bool] = poll) -> bool:
    """Wait until ``condition()`` holds, while the process trees of ``pids`` work towards it.

    The one wait for what processes do (a start, an exit, a line, a message, discovery):
    it ends when the condition holds (True), or when the trees had ``limit_s``
    (:class:`Patience`: of CPU time, or of sitting idle on the wall clock; False), so a busy
    machine never decides it.  With no process to watch, ``limit_s`` is wall-clock time.
    /proc is read only once the condition has kept the caller waiting for :data:`LOOK_S`.

    Introduced in ``03-write-the-publisher.ipynb`` (the judge waits for a ``main()``).

    :param look: how to wait for the condition at most a given number of seconds (default
        :func:`poll`); the judge's node passes one that wakes when a message arrives.
    """
    began = time.monotonic()
    if look(condition, min(LOOK_S, limit_s)):
        return True
    patience = Patience(pids, limit_s, started=began) if pids else None
    while not look(condition, LOOK_S):
        if patience.exhausted() if patience else time.monotonic() - began >= limit_s:
            return False
    return True


def wait_patiently(proc: Process, limit_s: float) -> Optional[int]:
    """Wait for ``proc`` to exit, with :class:`Patience` (``limit_s`` of its tree's work, or
    of its idle waiting): on a busy machine a slow exit is not a hang.

    Introduced in ``03-write-the-publisher.ipynb`` (a main() stopped with Ctrl+C).

    :return: its exit code, or None when it had its limit and still runs.
    """
    if wait_for_work(lambda: proc.poll() is not None, [proc.pid], limit_s):
        return proc.returncode
    return None


def _name(pid: int) -> str:
    try:
        with open(f'/proc/{pid}/comm') as comm:
            return comm.read().strip()
    except OSError:
        return ''


def _state(pid: int) -> str:
    """A process's state as /proc shows its main thread: R running or ready, S or D waiting,
    Z ended, ... ('' when it is gone)."""
    try:
        with open(f'/proc/{pid}/stat') as stat:
            return stat.read().rsplit(')', 1)[1].split()[0]
    except (OSError, IndexError):
        return ''


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
        pids = [pid for pid in tree_pids(proc.pid) if _name(pid) != 'bwrap']
        calm = calm + 1 if pids and all(_state(pid) in ('S', 'D') for pid in pids) else 0
        time.sleep(POLL_S)
    return True


def interrupt(proc: Process, sig: int = signal.SIGINT) -> None:
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
