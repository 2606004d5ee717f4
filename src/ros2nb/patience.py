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
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Mapping, NamedTuple, Optional, Sequence

if TYPE_CHECKING:
    import psutil

#: Seconds between two looks at a condition (:func:`poll`).
POLL_S = 0.02
#: A process tree using less than this share of one CPU between two looks may be waiting, not
#: working (unless a thread of it was kept from running: :data:`WANTING_SHARE`).
BUSY_SHARE = 0.05
#: A thread that stood ready on the run queue for this share of the time between two looks
#: wanted a CPU for most of it: it works, however little the machine let it run.  An idle
#: thread that wakes for a moment stands there too on a busy machine, but sleeps between.
WANTING_SHARE = 0.5
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
    found: dict[int, Any] = {}  # pid -> its psutil.Process, in the order found
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


class Thread(NamedTuple):
    """One thread as the kernel counts it (``/proc/PID/task/TID/stat`` and ``schedstat``)."""
    #: ``R`` (running or ready to run), ``S`` (sleeping), ... as ``ps`` shows it.
    state: str
    #: Seconds it ran on a CPU so far (nanosecond precision, unlike psutil's ticks).
    run_s: float
    #: Seconds it stood ready on the run queue, waiting for a CPU, so far (brought up to date
    #: only when it gets a CPU).
    queued_s: float


def _threads(pid: int) -> dict[int, Thread]:
    """Each thread of ``pid`` by thread id (none once it is gone, or on a kernel without
    schedstats).

    Read from /proc here, not through psutil: psutil gives a thread's CPU times in clock
    ticks but neither its time on the run queue nor its state, and these are what tell a
    program the scheduler starves from one that waits (:class:`Patience`)."""
    try:
        tasks = os.listdir(f'/proc/{pid}/task')
    except OSError:
        return {}
    found = {}
    for task in tasks:
        try:
            with open(f'/proc/{pid}/task/{task}/stat') as stat:
                state = stat.read().rsplit(')', 1)[1].split()[0]
            with open(f'/proc/{pid}/task/{task}/schedstat') as schedstat:
                run, queued = schedstat.read().split()[:2]
            found[int(task)] = Thread(state, int(run) / 1e9, int(queued) / 1e9)
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
    never more than an interval at a time.

    :param threads: each thread's seconds on the run queue so far, by thread (its id, e.g.
        :func:`run_queue_seconds`, or any key that names it), read at every look.
    """

    def __init__(self, threads: Callable[[], Mapping[Any, float]]) -> None:
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


@dataclass(frozen=True)
class TreeLook:
    """What process trees had done when looked at (:func:`look_at_trees`)."""
    #: CPU seconds (user + system) of every process of the trees, with the children they
    #: reaped and the threads that ended (psutil's clock ticks).
    cpu_s: float
    #: Each thread of the trees, by ``(pid, thread id)``.
    threads: dict[tuple[int, int], Thread]


def look_at_trees(pids: Sequence[int], *, skip: Optional[tuple[int, int]] = None) -> TreeLook:
    """What the process trees of ``pids`` have done so far, as the kernel counts it.

    Only the trees count, not the process that watches them: a judge at work beside its
    watch (its executor and Fast DDS threads, busy with other subjects) would make every
    program it waits on look busy.

    Introduced in ``03-write-the-publisher.ipynb`` (how long the judge waits for a subject).

    :param skip: ``(pid, thread id)`` of a thread left out: the one that looks, which runs
        while it reads (a process that waits for itself, :func:`wait_for_work`).
    """
    trees = process_tree(pids)
    threads = {(process.pid, tid): thread for process in trees
               for tid, thread in _threads(process.pid).items() if (process.pid, tid) != skip}
    return TreeLook(sum(_cpu_seconds(process) for process in trees), threads)


class Patience:
    """Whether process trees asked to do something have had long enough to do it.

    A limit on the wall clock alone cuts honest work short on a busy machine, where a
    process gets a fraction of a CPU.  So the limit counts what the
    trees do: they have had long enough once they used ``limit_s`` CPU seconds (an endless
    loop), or once they sat idle, waiting for an event, for ``limit_s`` seconds on the wall
    clock.  Between two looks they sat idle when they used less than :data:`BUSY_SHARE` of
    a CPU and none of their threads was kept from running: none stood ready on the run
    queue for :data:`WANTING_SHARE` of the interval, and none stands ready at the look
    without having run since the last (the kernel brings the time on the run queue up to
    date only when a thread runs).  A program the scheduler starves is working, not
    waiting, however long that takes: what bounds a machine that never runs it is outside
    (a test's time limit, a sandbox's wall time, the learner's stop button).  Their time on
    the run queue is not work: on a busy machine an idle program's many threads (Fast DDS
    has a dozen) each stand there a moment whenever they wake, and in all for a large share
    of the wall clock.

    What the trees wait for may be the watcher's own process (a subject waits for its
    judge's clock, its answers, its discovery messages): time the machine kept the watcher
    from running is not the trees' idle time either.  So an idle interval counts only the
    part of it that the watcher's most delayed thread did not stand on the run queue
    (:class:`HeldBack`, every thread, the one that looks included: it may be the one that
    serves what the trees wait for; its CPU time never counts: a judge busy with other
    subjects would make every program it waits on look busy), and at most two looks of it:
    a watcher kept from looking longer (by its own work, or by a thread of its process that
    holds the GIL while the machine starves it) was late, which says nothing of the trees.

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
        #: The thread that looks (the one that made this: it is left out of what it watches).
        self._looker = _this_thread()
        self._last = look_at_trees(self.pids, skip=self._looker)
        self.cpu_at_start = self._last.cpu_s
        #: Seconds on the wall clock the trees sat idle so far.  Of the time before this
        #: first look, a look's length counts: what the watcher took beyond it was its own
        #: lateness (the machine, or its own work, kept it from looking), not their waiting.
        self.idle_s = min(now - self.started, LOOK_S)
        self._looked = now
        self._verdict = False
        #: What kept the watcher's own process from running (:meth:`_watcher_threads`).
        self._held = HeldBack(self._watcher_threads)

    def _watcher_threads(self) -> dict[int, float]:
        """Each thread of the watcher's process, the one that looks included: its seconds on
        the run queue so far.  Nothing when the watcher is one of the trees (then its threads
        are the trees' own)."""
        pid = os.getpid()
        if pid in self.pids:
            return {}
        return {task: thread.queued_s for task, thread in _threads(pid).items()}

    @staticmethod
    def _idle_between(before: TreeLook, after: TreeLook, interval: float) -> bool:
        """Whether the trees sat idle between two looks ``interval`` seconds apart: they
        used little CPU, and none of their threads wanted more (it stood on the run queue
        for most of the interval, or stands there now and has not run since the last look)."""
        ran, wanting = 0.0, False
        for key, thread in after.threads.items():
            earlier = before.threads.get(key, Thread('R', 0.0, 0.0))  # new: ready since made
            ran += thread.run_s - earlier.run_s
            wanting = wanting or thread.queued_s - earlier.queued_s >= WANTING_SHARE * interval \
                or thread.state == earlier.state == 'R' and thread.run_s == earlier.run_s
        return not wanting and max(ran, after.cpu_s - before.cpu_s) < BUSY_SHARE * interval

    def exhausted(self) -> bool:
        """True once the trees have had their limit (call it every fraction of a second: it
        reads /proc once every :data:`LOOK_S`)."""
        now = time.monotonic()
        if self._verdict or now - self._looked < LOOK_S:
            return self._verdict
        before, self._last = self._last, look_at_trees(self.pids, skip=self._looker)
        self._held.look()
        if self._idle_between(before, self._last, now - self._looked):
            # Looks come a LOOK_S apart; of a longer interval, what is beyond two looks was the
            # watcher's lateness (its own work, or a thread of its process the machine starves
            # holding the GIL it needs), not the trees' waiting, as before the first look.
            interval = min(now - self._looked, 2 * LOOK_S)
            self.idle_s += interval - self._held.take(interval)
        self._looked = now
        self._verdict = self._last.cpu_s - self.cpu_at_start >= self.limit_s \
            or self.idle_s >= self.limit_s
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
