"""The one place that decides when a process has had long enough (:class:`Patience`).

A limit on the wall clock alone cuts honest work short on a busy machine, so every wait for
what processes do counts what their trees do: CPU seconds and time on the run queue.  psutil
walks the process trees and reads their CPU times; what psutil does not give (a thread's time
on the run queue, its state) is read from /proc here.  :mod:`ros2nb.processes` stops them.
No mention of ROS here.
"""

from __future__ import annotations

import os
import threading
import time
from typing import TYPE_CHECKING, Any, Callable, Optional, Sequence

if TYPE_CHECKING:
    import psutil

#: Seconds between two looks at a condition (:func:`poll`).
POLL_S = 0.02
#: A process tree using less than this share of one CPU between two looks, counting the
#: time its threads stood ready on the run queue, is waiting, not working.
BUSY_SHARE = 0.05
#: Seconds between two looks at a process tree's work (each look reads every process's
#: parent from /proc: milliseconds on a busy machine).
LOOK_S = 0.25


def psutil_module() -> Any:
    """psutil, imported on first use: a process that never looks at a tree (a judge's
    subject, which only runs nodes) does not pay for its import."""
    import psutil
    return psutil


def process_tree(pids: Sequence[int]) -> list['psutil.Process']:
    """Each of ``pids`` that is still there and every process under them, once, as
    :class:`psutil.Process` (psutil walks the tree from every process's parent)."""
    psutil = psutil_module()
    found: dict[int, Any] = {}  # pid -> its Process, in the order found
    for pid in dict.fromkeys(pids):
        if pid in found:
            continue
        try:
            top = psutil.Process(pid)
            below = top.children(recursive=True)
        except psutil.Error:  # gone meanwhile
            continue
        found.update((each.pid, each) for each in [top, *below] if each.pid not in found)
    return list(found.values())


def asked(process: 'psutil.Process', what: str, gone: Any) -> Any:
    """``process.what()`` (psutil's ``name``, ``status``, ``cpu_times``), or ``gone`` once
    the process is gone."""
    try:
        return getattr(process, what)()
    except psutil_module().Error:
        return gone


def _cpu_seconds(process: 'psutil.Process') -> float:
    """CPU seconds (user + system) of ``process`` and of its children it reaped; 0 once gone."""
    times = asked(process, 'cpu_times', None)
    return times.user + times.system + times.children_user + times.children_system if times \
        else 0.0


def child_pids(pid: int) -> list[int]:
    """The processes ``pid`` started that are still there (running or not yet reaped)."""
    psutil = psutil_module()
    try:
        return [child.pid for child in psutil.Process(pid).children()]
    except psutil.Error:
        return []


def tree_pids(pid: int) -> list[int]:
    """``pid`` and every process under it now."""
    return [process.pid for process in process_tree([pid])]


def tree_cpu_seconds(pid: int) -> float:
    """CPU seconds (user + system) used so far by ``pid`` and every process under it.

    Processes of the tree that already ended count when their parent has reaped them.
    A process that is gone counts 0.
    """
    return sum(_cpu_seconds(process) for process in process_tree([pid]))


def _this_thread() -> tuple[int, int]:
    """``(pid, thread id)`` of the calling thread, as /proc names them."""
    return os.getpid(), threading.get_native_id()


def queued_seconds(pids: Sequence[int], *, skip: Optional[tuple[int, int]] = None
                   ) -> tuple[float, bool]:
    """How much the threads of ``pids`` stood ready to run, waiting on the run queue for a
    CPU: the seconds the kernel counted (the second field of ``/proc/PID/task/TID/schedstat``,
    brought up to date only when a thread gets a CPU), and whether one of them stands ready
    now (state R).  Gone processes and threads, and a kernel without schedstats, count
    nothing.

    Read from /proc here, not through psutil: psutil gives a thread's CPU times but neither
    its time on the run queue nor its state, and these two are what tell a program the
    scheduler starves from one that waits (:class:`Patience`).

    :param skip: ``(pid, thread id)`` of a thread left out: the one that looks, which runs
        while it reads (a process that waits for itself, :func:`wait_for_work`).
    """
    total, ready = 0.0, False
    for pid in pids:
        for task, state, delay in _threads(pid):
            if (pid, task) == skip:
                continue
            ready = ready or state == 'R'
            total += delay
    return total, ready


def _threads(pid: int) -> list[tuple[int, str, float]]:
    """``(thread id, state, seconds on the run queue so far)`` of each thread of ``pid``
    (none once it is gone)."""
    try:
        tasks = os.listdir(f'/proc/{pid}/task')
    except OSError:
        return []
    found = []
    for task in tasks:
        try:
            with open(f'/proc/{pid}/task/{task}/stat') as stat:
                state = stat.read().rsplit(')', 1)[1].split()[0]
            with open(f'/proc/{pid}/task/{task}/schedstat') as schedstat:
                found.append((int(task), state, int(schedstat.read().split()[1]) / 1e9))
        except (OSError, IndexError, ValueError):
            continue
    return found


def run_queue_seconds(thread_ids: Sequence[int]) -> dict[int, float]:
    """Each thread's seconds on the run queue so far (``/proc/TID/schedstat``), by thread id;
    a thread that is gone is left out."""
    found = {}
    for tid in thread_ids:
        try:
            with open(f'/proc/{tid}/schedstat') as schedstat:
                found[tid] = int(schedstat.read().split()[1]) / 1e9
        except (OSError, IndexError, ValueError):
            continue
    return found


class HeldBack:
    """How long the machine kept some threads from running, look by look.

    Of each interval between two looks, what counts is the most seconds one of the threads
    stood ready on the run queue (threads wait side by side: their sum is no time of
    anyone's).  The kernel brings a thread's count up to date only when the thread runs, so
    what one look misses a later one finds: it is owed, and taken from later intervals,
    never more than an interval at a time.  The caller takes from every interval, whatever
    it makes of it: what the threads stood on the run queue while it looked elsewhere (an
    interval it counts as work, or the part of a late look it leaves out) is owed by no
    later interval, and, kept owed, it would be taken from every interval after it.

    :param threads: each thread's seconds on the run queue so far, by thread id (e.g.
        :func:`run_queue_seconds`), read at every look.
    """

    def __init__(self, threads: Callable[[], dict[int, float]]) -> None:
        self._threads = threads
        self._last = threads()
        self._owed = 0.0

    def look(self) -> None:
        """Read the threads again; what they stood on the run queue since is owed."""
        now = self._threads()
        grown = max((delay - self._last.get(tid, 0.0) for tid, delay in now.items()),
                    default=0.0)
        self._last = now
        self._owed += max(0.0, grown)

    def take(self, interval_s: float) -> float:
        """The seconds of an interval of ``interval_s`` that the threads were kept from
        running (taken from what is owed)."""
        held = min(self._owed, interval_s)
        self._owed -= held
        return held


def tree_work(pids: int | Sequence[int], *, skip: Optional[tuple[int, int]] = None
              ) -> tuple[float, float, bool]:
    """What process trees have done, as the kernel counts it: the CPU seconds of ``pids``
    and every process under them; the seconds their threads stood ready on the run queue
    for a CPU (:func:`queued_seconds`); and whether one of them stands ready now.

    Only the trees count, not the process that watches them: a judge at work beside its
    watch (its executor and Fast DDS threads, busy with other subjects) would make every
    program it waits on look busy.

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).

    :param skip: a thread left out (:func:`queued_seconds`).
    """
    trees = process_tree([pids] if isinstance(pids, int) else pids)
    queued, ready = queued_seconds([process.pid for process in trees], skip=skip)
    return sum(_cpu_seconds(process) for process in trees), queued, ready


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

    What the trees wait for may be the watcher's own process (a subject waits for its
    judge's clock, its answers, its discovery messages): time the machine kept the watcher
    from running is not the trees' idle time either.  So an idle interval counts only the
    part of it that the watcher's most delayed thread did not stand on the run queue (its
    CPU time never counts: a judge busy with other subjects would make every program it
    waits on look busy), and at most two looks of it: a watcher kept from looking longer
    (by its own work, or by a thread of its process that holds the GIL while the machine
    starves it) was late, which says nothing of the trees.

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).

    :param pids: the process (or processes) at the top of the trees (a sandbox's own
        process is fine; the watcher's own process too, a wait for itself: the thread
        that looks is left out).
    :param limit_s: seconds of CPU time, or of idle waiting, the trees are given.
    :param started: when the trees were asked (``time.monotonic()``; default now), at most
        a look (:data:`LOOK_S`) ago as the caller meant it; that time counts as waiting.
        CPU time counts from now: a caller whose answers mostly come at once starts
        measuring late, and spares /proc meanwhile.
    """

    def __init__(self, pids: int | Sequence[int], limit_s: float,
                 started: Optional[float] = None) -> None:
        self.pids = [pids] if isinstance(pids, int) else list(pids)
        self.limit_s = limit_s
        now = time.monotonic()
        self.started = now if started is None else started
        self.cpu_at_start, queued, _ready = tree_work(self.pids, skip=_this_thread())
        #: Seconds on the wall clock the trees sat idle so far.  Of the time before this
        #: first look, a look's length counts: what the watcher took beyond it was its own
        #: lateness (the machine, or its own work, kept it from looking), not their waiting.
        self.idle_s = min(now - self.started, LOOK_S)
        self._look = (now, self.cpu_at_start + queued)
        self._verdict = False
        #: What kept the watcher's own process from running (:meth:`_watcher_threads`).
        self._held = HeldBack(self._watcher_threads)

    def _watcher_threads(self) -> dict[int, float]:
        """Each thread of the watcher's process, the one that looks included (kept from
        running, it looks late, and the interval grows by time nobody waited): its seconds
        on the run queue so far.  Nothing when the watcher is one of the trees (then its time
        on the run queue is the trees' work already)."""
        pid = os.getpid()
        if pid in self.pids:
            return {}
        return {task: delay for task, _state, delay in _threads(pid)}

    def exhausted(self) -> bool:
        """True once the trees have had their limit (call it every fraction of a second: it
        reads /proc once every :data:`LOOK_S`)."""
        now = time.monotonic()
        then, busy_then = self._look
        if self._verdict or now - then < LOOK_S:
            return self._verdict
        cpu, queued, ready = tree_work(self.pids, skip=_this_thread())
        self._held.look()
        # What the machine kept the watcher from running is taken from this interval, busy or
        # idle, and from the whole of it: owed on, it was taken from every idle interval after
        # (a judge's threads stand on a loaded machine's run queue most of every interval).
        held = self._held.take(now - then)
        if not ready and cpu + queued - busy_then < BUSY_SHARE * (now - then):
            # Looks come a LOOK_S apart; of the rest of a longer interval, what is beyond two
            # looks was the watcher's lateness (its own work, or a thread of its process the
            # machine starves holding the GIL it needs), not the trees' waiting, as before the
            # first look.
            self.idle_s += min(now - then - held, 2 * LOOK_S)
        self._look = (now, cpu + queued)
        self._verdict = cpu - self.cpu_at_start >= self.limit_s or self.idle_s >= self.limit_s
        return self._verdict

    @property
    def ran_out_idle(self) -> bool:
        """Whether the trees had their limit by sitting idle (waiting for something), not by
        working: of what they waited for, the caller knows whose it was."""
        return self._verdict and self.idle_s >= self.limit_s


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
