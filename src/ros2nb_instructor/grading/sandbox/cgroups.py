"""Cgroups for a sandbox: a fresh group per sandbox limits its tasks and its memory and
counts its CPU time.

Part of :mod:`.bubblewrap` (runs on the instructor's host, as root while grading).  cgroup v1
``pids`` and ``memory`` (and ``cpuacct``, to count) when the host has them, else cgroup v2
with both controllers delegated (v2 counts CPU time in every group); none when neither can be
made (then :mod:`.bubblewrap` falls back to rlimits).
"""

from __future__ import annotations

import itertools
import os
import signal
import time
from pathlib import Path
from typing import Mapping

from ros2nb.temporary import running_since

_CGROUP_PREFIX = 'ros2nb-sandbox-'
_counter = itertools.count()


def _own_cgroup(controller: str) -> Path | None:
    """This process's cgroup folder for a v1 controller, or for cgroup v2 when ``''``."""
    mount = None
    for line in _read(Path('/proc/self/mountinfo')).splitlines():
        before, after = line.split(' - ', 1)
        fstype, _, options = after.split()[:3]
        if (fstype == 'cgroup2' and not controller
                or fstype == 'cgroup' and controller in options.split(',')):
            mount = Path(before.split()[4])
    for line in _read(Path('/proc/self/cgroup')).splitlines():
        _, names, path = line.split(':', 2)
        if mount and (controller in names.split(',') if controller else names == ''):
            return mount / path.lstrip('/')
    return None


#: Microseconds of the scheduler's period a CPU share is a quota of (the kernel's default).
CPU_PERIOD_US = 100_000


def make_cgroups(pids: int, memory_bytes: int, cpu_share: float | None = None
                 ) -> tuple[list[Path], list[str]]:
    """Fresh cgroups limiting tasks and memory, v1 pids+memory (with cpuacct), else v2;
    [] when impossible.  :func:`cpu_seconds` reads their CPU time, :func:`threads` lists
    their threads.

    :param cpu_share: CPUs the processes may use together at most (``1/6``: a sixth of one
        core, as a small pod of a hub gets), a quota of the scheduler's period (v1 ``cpu``,
        v2 ``cpu.max``); None: no quota.  A quota that cannot be set is left out of the
        enforced names.
    """
    name = f'{_CGROUP_PREFIX}{os.getpid()}-{next(_counter)}'
    sweep_left_behind()
    quota = None if cpu_share is None else max(1000, round(cpu_share * CPU_PERIOD_US))
    v1 = {'pids': {'pids.max': pids},
          'memory': {'memory.limit_in_bytes': memory_bytes,
                     'memory.memsw.limit_in_bytes': memory_bytes}}
    if quota is not None:
        v1['cpu'] = {'cpu.cfs_period_us': CPU_PERIOD_US, 'cpu.cfs_quota_us': quota}
    made, enforced = [], []
    for controller, files in v1.items():
        parent = _own_cgroup(controller)
        if parent and _try_cgroup(parent / name, files):
            made.append(parent / name)
            enforced.append(f'{controller}(cgroup)')
    parent = _own_cgroup('cpuacct')
    if made and parent and parent / name not in made and _try_cgroup(parent / name, {}):
        made.append(parent / name)  # counts, limits nothing (made above where cpu shares it)
    parent = _own_cgroup('')
    if not made and parent and {'pids', 'memory'} <= set(
            _read(parent / 'cgroup.subtree_control').split()):
        v2: dict[str, int | str] = {'pids.max': pids, 'memory.max': memory_bytes,
                                    'memory.swap.max': 0}
        cpu = quota is not None and 'cpu' in _read(parent / 'cgroup.subtree_control').split()
        if cpu:
            v2['cpu.max'] = f'{quota} {CPU_PERIOD_US}'
        if _try_cgroup(parent / name, v2):
            made = [parent / name]
            enforced = ['pids(cgroup)', 'memory(cgroup)', *(['cpu(cgroup)'] if cpu else [])]
    return made, enforced


def sweep_left_behind() -> list[Path]:
    """Remove the sandbox cgroups of graders that no longer run (killed before they could:
    a cgroup outlives its processes), killing what is left in them; return them.  One of a
    grader that still runs is left alone."""
    swept = []
    for controller in ('pids', 'memory', 'cpu', 'cpuacct', ''):
        parent = _own_cgroup(controller)
        for cgroup in sorted(parent.glob(f'{_CGROUP_PREFIX}*')) if parent else ():
            owner = cgroup.name[len(_CGROUP_PREFIX):].split('-', 1)[0]
            try:
                if not owner.isdigit() or running_since(int(owner), cgroup.stat().st_ctime):
                    continue
                remove([cgroup])
            except OSError:  # gone meanwhile (its grader removed it), or busy: left alone
                continue
            swept.append(cgroup)
    return swept


def threads(cgroups: list[Path]) -> list[int]:
    """The ids of every thread in the cgroups now (v1 ``tasks``, v2 ``cgroup.threads``)."""
    found: set[int] = set()
    for cgroup in cgroups:
        for listing in ('tasks', 'cgroup.threads'):
            found.update(int(tid) for tid in _read(cgroup / listing).split() if tid.isdigit())
    return sorted(found)


def cpu_seconds(cgroups: list[Path]) -> float | None:
    """CPU seconds (user + system) the processes of these cgroups used, the ended ones
    included; None when none of them counts CPU time (no v1 ``cpuacct``, no v2 group)."""
    for cgroup in cgroups:
        usage = _read(cgroup / 'cpuacct.usage').strip()
        if usage.isdigit():
            return int(usage) / 1e9
        for line in _read(cgroup / 'cpu.stat').splitlines():
            key, _, value = line.partition(' ')
            if key == 'usage_usec' and value.strip().isdigit():
                return int(value) / 1e6
    return None


def _read(path: Path) -> str:
    try:
        return path.read_text()
    except OSError:
        return ''


def _try_cgroup(path: Path, files: Mapping[str, int | str]) -> bool:
    try:
        path.mkdir()
    except OSError:
        return False
    try:
        for name, value in files.items():
            if (path / name).exists():
                (path / name).write_text(str(value))
        return True
    except OSError:
        path.rmdir()
        return False


#: Seconds :func:`kill` and :func:`remove` keep at it before giving up.
PATIENCE_S = 10.0


def kill(cgroups: list[Path]) -> None:
    """SIGKILL every process in the cgroups, again until none is left.

    The kernel takes a zombie out of ``cgroup.procs`` (Linux 4.4, the commit "cgroup: keep
    zombies associated with their original cgroups"), so our own unreaped child does
    not keep this waiting.  Whatever a process forks meanwhile is born in the same cgroup
    and is killed in the next round.  Gives up silently after :data:`PATIENCE_S`
    (:func:`remove` raises then).
    """
    deadline = time.monotonic() + PATIENCE_S
    for cgroup in cgroups:
        while pids := _read(cgroup / 'cgroup.procs').split():
            for pid in pids:
                _kill(int(pid))
            if time.monotonic() > deadline:
                return
            time.sleep(0.01)


def remove(cgroups: list[Path]) -> None:
    """Kill whatever is left in the cgroups (nothing, normally) and remove them."""
    deadline = time.monotonic() + PATIENCE_S
    for cgroup in cgroups:
        while cgroup.exists():
            kill([cgroup])
            try:
                cgroup.rmdir()
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.02)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
