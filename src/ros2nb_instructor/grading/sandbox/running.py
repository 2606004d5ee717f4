"""What a sandbox may use (:class:`Limits`), how it ended (:class:`Result`), and a started one
watched until it ends or runs out (:class:`Running`).

Part of :mod:`.bubblewrap` (runs on the instructor's host).  One thread per sandbox watches its
wall time and, through its cgroup (:mod:`.cgroups`), the CPU time of all its processes
together; the first limit that runs out kills the whole sandbox.
"""

from __future__ import annotations

import shutil
import subprocess
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ros2nb.patience import HeldBack, run_queue_seconds

from . import cgroups as cgroups_of

GiB = 1 << 30
MiB = 1 << 20


@dataclass(frozen=True)
class Limits:
    """Resource limits of one sandbox (defaults fit a Jupyter kernel running ROS 2 nodes).

    :param wall_s: seconds before the whole sandbox is killed, counted while it works or
        waits, never while the machine keeps it from running (:class:`Running`): a hang's
        bound, not a speed limit (``cpu_s`` bounds its work).
    :param cpu_s: CPU seconds (user + system) all its processes may use together before the
        whole sandbox is killed (per process without a cgroup); None: no limit.
    :param memory_bytes: memory of all its processes together (per process without a cgroup).
    :param pids: tasks (processes and threads) at once; a ROS 2 node has about 16 threads.
    :param file_size_bytes: largest file a process may write.
    :param cpu_share: CPUs its processes may use together at most (a CPU quota, e.g. ``1/6``:
        a sixth of one core, a small pod's share); None: as many as the machine gives.
    :param cpu_step_s: CPU seconds its processes may use together in one step of its work
        (from one :meth:`Running.step` to the next: a judge's check); None: no such limit.
    """

    wall_s: float = 900.0
    cpu_s: float | None = None
    memory_bytes: int = 4 * GiB
    pids: int = 512
    file_size_bytes: int = 256 * MiB
    cpu_share: float | None = None
    cpu_step_s: float | None = None


@dataclass(frozen=True)
class Result:
    """How a sandboxed run ended.

    :param returncode: the program's exit code; negative (a signal) when it was killed.
    :param timed_out: True when ``Limits.wall_s`` ran out and the sandbox was killed.
    :param limits_enforced: e.g. ``('wall', 'file-size', 'pids(cgroup)', 'memory(cgroup)')``.
    :param stdout: captured output when ``stdout=subprocess.PIPE`` was given, else None.
    :param stderr: the same for stderr.
    :param out_of_cpu: True when ``Limits.cpu_s`` (or ``cpu_step_s``) ran out and the
        sandbox was killed.
    :param cpu_s: CPU seconds its processes used, read from its cgroup (None without one).
    :param step: the step that ran out of ``Limits.cpu_step_s`` (None when none did).
    """

    returncode: int
    timed_out: bool
    limits_enforced: tuple[str, ...]
    stdout: Any = None
    stderr: Any = None
    out_of_cpu: bool = False
    cpu_s: float | None = None
    step: str | None = None


#: Seconds between two looks at a sandbox's CPU time (it may overrun its limit by this much
#: CPU time per CPU).
CPU_LOOK_S = 0.25
#: Seconds between two looks at the time the machine kept a sandbox's threads from running
#: (each look reads every thread's count from /proc: a judge and its subjects hold about a
#: hundred threads).
HELD_LOOK_S = 1.0


class Running:
    """A started sandbox: ``process`` is the :class:`subprocess.Popen` of its bwrap.

    ``timed_out`` and ``out_of_cpu`` say which limit stopped it (``stopped_step``: the step
    that ran out of its CPU time, :meth:`step`); ``cpu_s`` is the CPU time its processes used
    (from its cgroup, once it was stopped; None without a cgroup)."""

    def __init__(self, process: subprocess.Popen[Any], limits_enforced: tuple[str, ...],
                 cgroups: list[Path], stage: Path | None, limits: Limits) -> None:
        self.process = process
        self.limits_enforced = limits_enforced
        self.timed_out = self.out_of_cpu = False
        self.cpu_s: float | None = None
        self.stopped_step: str | None = None
        #: The step running now and the CPU seconds used when it began (:meth:`step`).
        self._step: tuple[str | None, float] = (None, 0.0)
        self._cgroups, self._stage = cgroups, stage
        self._stopping = threading.Event()
        self._watcher = threading.Thread(target=self._watch, args=(limits,), daemon=True)
        self._watcher.start()

    def _watch(self, limits: Limits) -> None:
        """Kill the sandbox when its wall time or its CPU time runs out.

        Its wall time counts what it worked and waited, not the time the machine kept it
        from running (the most one of its threads stood ready on the run queue, look by
        look: :class:`ros2nb.patience.HeldBack`): on a busy machine, or at a small share of
        a CPU, a notebook that does its honest work slowly is not a hang.  The launcher's
        own process counts from the start: until it has joined the cgroups (its interpreter
        starting, on a loaded machine for seconds) they list no thread at all.  Without a
        cgroup to list its threads, the wall clock alone counts."""
        launcher = self.process.pid  # single-threaded: its one thread's id is its pid
        held = HeldBack(lambda: run_queue_seconds(
            [launcher, *cgroups_of.threads(self._cgroups)])) if self._cgroups else None
        counted, looked = 0.0, time.monotonic()
        while not self._stopping.wait(CPU_LOOK_S):
            now = time.monotonic()
            if held is None or now - looked >= HELD_LOOK_S:  # the wall time, look by look
                if held is not None:
                    held.look()
                counted += now - looked - (held.take(now - looked) if held is not None else 0.0)
                looked = now
            if counted >= limits.wall_s:
                self._expire('timed_out')
                return
            used = cgroups_of.cpu_seconds(self._cgroups)
            step, began = self._step
            if used is not None and limits.cpu_step_s is not None \
                    and used - began >= limits.cpu_step_s:
                self.stopped_step = step
                self._expire('out_of_cpu')
                return
            if used is not None and limits.cpu_s is not None and used >= limits.cpu_s:
                self._expire('out_of_cpu')
                return

    def step(self, name: str) -> None:
        """A new step of the sandbox's work begins (a judge's next check): its CPU time counts
        from now against ``Limits.cpu_step_s``."""
        self._step = (name, cgroups_of.cpu_seconds(self._cgroups) or 0.0)

    def _expire(self, why: str) -> None:
        if self.process.poll() is None:
            setattr(self, why, True)
            self.process.kill()
            # Not bwrap alone: killed while it sets up, its child can outlive it, still
            # running the program and holding its pipes (bubblewrap#633), so that a reader
            # waiting for their end would wait forever.  The cgroup holds them all.
            cgroups_of.kill(self._cgroups)

    def wait(self, timeout: float | None = None) -> int:
        """Wait for the program to end, then clean up as :meth:`stop` does.

        :param timeout: seconds to wait at most (the wall-time limit applies in any case).
        :return: the exit code.
        :raises subprocess.TimeoutExpired: when ``timeout`` passed first (still running).
        """
        self.process.wait(timeout)
        return self.stop()

    def stop(self) -> int:
        """Kill the sandbox and everything in it (if still running), then remove its cgroup.

        :return: the exit code (negative: killed by that signal).
        """
        self._stopping.set()
        if self._watcher is not threading.current_thread():
            self._watcher.join()
        if self.process.poll() is None:
            self.process.kill()
        code = self.process.wait()
        if self._cgroups:
            cgroups_of.kill(self._cgroups)  # so that the count below is final
            self.cpu_s = cgroups_of.cpu_seconds(self._cgroups)
        remove(self._cgroups, self._stage)
        self._cgroups, self._stage = [], None
        return code

    def __enter__(self) -> Running:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


def remove(cgroups: list[Path], stage: Path | None) -> None:
    """Remove a sandbox's cgroups (killing what is left in them) and its staging folder."""
    cgroups_of.remove(cgroups)
    if stage:
        shutil.rmtree(stage, ignore_errors=True)
