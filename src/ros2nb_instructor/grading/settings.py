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
#: stopped, and the note says which cells did not run.  At least four times what the course's
#: heaviest honest notebook uses on a slow, busy machine, room for a learner who explores, and
#: still a bound on a thread that loops without waiting (docs/decisions.md, "Room for honest
#: exploration"; benchmarks/notebook_cpu.py measures the course's notebooks).
NOTEBOOK_CPU_S = 80
#: Seconds the judge may take for one notebook.
JUDGE_TIMEOUT_S = 600
#: CPU seconds the judge of one notebook and the processes that run the learner's code for it
#: may use together; then its sandbox is stopped and the cells not yet checked score nothing.
#: At least four times what the course's heaviest notebook costs its judge on a busy machine
#: (docs/decisions.md, "Every judge's CPU bounded"; benchmarks/notebook_cpu.py measures it).
JUDGE_CPU_S = 60
#: Notebooks graded at the same time: one more than the CPUs (a notebook often waits).
JOBS = (os.cpu_count() or 1) + 1


@dataclass(frozen=True)
class Settings:
    """How to grade: the limits, whether to sandbox, and the seed of the judges' drawn inputs
    (:mod:`ros2nb.checks.drawn`; None: each judge draws its own).  ``notebook_cpu`` (CPU
    seconds; None: no limit) applies only in a sandbox; ``judge_cpu`` (the same for each
    notebook's judge) wherever the host can make a cgroup, else per process."""

    cell_timeout: int
    notebook_timeout: int
    sandboxed: bool
    seed: Optional[int] = None
    notebook_cpu: Optional[float] = NOTEBOOK_CPU_S
    judge_cpu: Optional[float] = JUDGE_CPU_S
