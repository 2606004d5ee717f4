"""Reading /proc in the background while a block runs: the benchmarks' one sampling thread."""

from __future__ import annotations

import os
import threading
from pathlib import Path

TICKS_PER_S = os.sysconf('SC_CLK_TCK')


class Sampling:
    """Context manager: calls :meth:`sample` every ``period_s`` seconds in a thread of its
    own while the block runs.  Subclasses define ``sample``."""

    def __init__(self, period_s: float) -> None:
        self.period_s, self._stop = period_s, threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def sample(self) -> None:
        """Read what the subclass keeps (called from the sampling thread)."""
        raise NotImplementedError

    def __enter__(self) -> 'Sampling':
        self._thread.start()
        return self

    def __exit__(self, *_exc: object) -> None:
        self._stop.set()
        self._thread.join()

    def _run(self) -> None:
        while not self._stop.wait(self.period_s):
            self.sample()


class TreeCpu(Sampling):
    """CPU seconds of a process and of every process started under it (found by parent,
    every 50 ms: one that lives less is missed).  ``seen`` maps (pid, start time) to CPU
    seconds; ``parent`` and ``command`` give each pid's parent and command line."""

    def __init__(self, root: int) -> None:
        super().__init__(0.05)
        self._ours: set[int] = {root}
        self.seen: dict[tuple[int, str], float] = {}
        self.parent: dict[int, int] = {}
        self.command: dict[int, str] = {}

    def sample(self) -> None:
        stats = {}
        for entry in os.listdir('/proc'):
            if entry.isdigit():
                try:
                    stats[int(entry)] = Path(f'/proc/{entry}/stat').read_text().rsplit(
                        ')', 1)[1].split()
                except OSError:  # ended meanwhile
                    continue
        grew = True
        while grew:  # a child seen before its parent was known is found on the next pass
            grew = False
            for pid, stat in stats.items():
                if pid not in self._ours and int(stat[1]) in self._ours:
                    self._ours.add(pid)
                    grew = True
        for pid in self._ours & stats.keys():
            stat = stats[pid]
            self.seen[(pid, stat[19])] = (int(stat[11]) + int(stat[12])) / TICKS_PER_S
            if pid not in self.command:
                self.parent[pid] = int(stat[1])
                try:
                    self.command[pid] = Path(f'/proc/{pid}/cmdline').read_bytes().replace(
                        b'\0', b' ').decode(errors='replace')
                except OSError:
                    self.command[pid] = ''
