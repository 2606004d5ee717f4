"""How to grade: the limits and whether to sandbox (``ros2nb-grade``'s options).

Runs on the instructor's host.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Optional

#: Seconds one cell may run before its kernel is interrupted (the next cell still runs).
CELL_TIMEOUT_S = 120
#: Seconds one notebook may take in all; then its sandbox is stopped.
NOTEBOOK_TIMEOUT_S = 600
#: CPU seconds all the processes of one notebook's run may use together; then its sandbox is
#: stopped.  About three times what the course's heaviest notebook uses beside two busy CPUs,
#: so that a thread that loops without waiting costs the class little (docs/decisions.md,
#: "A flood fails fast"; benchmarks/notebook_cpu.py measures the course's notebooks).
NOTEBOOK_CPU_S = 40
#: Seconds the judge may take for one notebook.
JUDGE_TIMEOUT_S = 600
#: Notebooks graded at the same time: one more than the CPUs (a notebook often waits).
JOBS = (os.cpu_count() or 1) + 1


@dataclass(frozen=True)
class Settings:
    """How to grade: the limits, whether to sandbox, and the seed of the judges' drawn inputs
    (:mod:`ros2nb.checks.drawn`; None: each judge draws its own).  ``notebook_cpu`` (CPU
    seconds; None: no limit) applies only in a sandbox."""

    cell_timeout: int
    notebook_timeout: int
    sandboxed: bool
    seed: Optional[int] = None
    notebook_cpu: Optional[float] = NOTEBOOK_CPU_S
