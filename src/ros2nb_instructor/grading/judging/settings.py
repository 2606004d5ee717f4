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
#: CPU seconds one check of each notebook (by its number) may use, the judge's and the
#: processes' that run the learner's code for it, counted from the line the judge prints as
#: the check begins; then the judge is stopped, and the cells it had not checked score
#: nothing.  Counted per check, not per notebook: which check of a heavy notebook meets a
#: limit shared by all of them would depend on how much the earlier ones cost on the day
#: (a slow flood's main() point did).  At least 2.5 times the heaviest honest check of that
#: notebook, at a sixth of a CPU beside two CPU burners, and never under 30: a loop that
#: logs hundreds of lines a reading, under the flood limit, costs the class at most this in
#: each check it floods (docs/decisions.md, "Every judge's CPU bounded";
#: benchmarks/load_harness.py measures the checks).
JUDGE_CPU_S = {'00': 30, '01': 30, '02': 30, '03': 40, '04': 30, '05': 60, '06': 30,
               '07': 30, '08': 30, '09': 30, '10': 55}
#: Notebooks graded at the same time: one more than the CPUs (a notebook often waits).
JOBS = (os.cpu_count() or 1) + 1


@dataclass(frozen=True)
class Settings:
    """How to grade: the limits, whether to sandbox, and the seed of the judges' drawn inputs
    (:mod:`ros2nb.checks.drawn`; None: each judge draws its own).  ``notebook_cpu`` (CPU
    seconds; None: no limit) applies only in a sandbox; ``judge_cpu`` (the same for each
    check of a notebook's judge; None: :data:`JUDGE_CPU_S`) wherever the host can make a
    cgroup; ``cpu_share``, the CPUs each sandbox may use at most (a CPU quota,
    :class:`~ros2nb_instructor.grading.sandbox.running.Limits`; None: what the machine gives)."""

    cell_timeout: int
    notebook_timeout: int
    sandboxed: bool
    seed: Optional[int] = None
    notebook_cpu: Optional[float] = NOTEBOOK_CPU_S
    judge_cpu: Optional[float] = None
    cpu_share: Optional[float] = None

    def judge_cpu_for(self, notebook: str) -> float:
        """The CPU seconds one check of ``notebook`` (``NN-title``) may use."""
        if self.judge_cpu is not None:
            return self.judge_cpu
        return JUDGE_CPU_S.get(notebook[:2], max(JUDGE_CPU_S.values()))
