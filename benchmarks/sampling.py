"""Reading /proc in the background while a block runs: the benchmarks' one sampling thread."""

from __future__ import annotations

import threading


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
