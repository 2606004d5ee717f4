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
NOTEBOOK_CPU_S = 140
#: Seconds the judge may take for one notebook.
JUDGE_TIMEOUT_S = 600
#: CPU seconds the judge of each notebook (by its number) may use with the processes that run
#: the learner's code for it; then it is stopped, and the cells it had not checked score
#: nothing.  At least 2.3 times the heaviest honest judge of that notebook on a slow, busy
#: machine, and never under 30: a judge's cost is its notebook's (05 builds the package again
#: and again, 03 drives an hour), and a loop that logs hundreds of lines a reading, under the
#: flood limit, costs the class no more than its notebook's limit (docs/decisions.md, "Every
#: judge's CPU bounded"; benchmarks/notebook_cpu.py measures them).
JUDGE_CPU_S = {'00': 30, '01': 30, '02': 30, '03': 60, '04': 35, '05': 125, '06': 30,
               '07': 30, '08': 30, '09': 30, '10': 55}
#: Notebooks graded at the same time: one more than the CPUs (a notebook often waits).
JOBS = (os.cpu_count() or 1) + 1


@dataclass(frozen=True)
class Settings:
    """How to grade: the limits, whether to sandbox, and the seed of the judges' drawn inputs
    (:mod:`ros2nb.checks.drawn`; None: each judge draws its own).  ``notebook_cpu`` (CPU
    seconds; None: no limit) applies only in a sandbox; ``judge_cpu`` (the same for each
    notebook's judge; None: :data:`JUDGE_CPU_S`) wherever the host can make a cgroup, else
    per process."""

    cell_timeout: int
    notebook_timeout: int
    sandboxed: bool
    seed: Optional[int] = None
    notebook_cpu: Optional[float] = NOTEBOOK_CPU_S
    judge_cpu: Optional[float] = None

    def judge_cpu_for(self, notebook: str) -> float:
        """The CPU seconds the judge of ``notebook`` (``NN-title``) may use."""
        if self.judge_cpu is not None:
            return self.judge_cpu
        return JUDGE_CPU_S.get(notebook[:2], max(JUDGE_CPU_S.values()))
