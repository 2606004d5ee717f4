#!/usr/bin/env python3
"""CPU seconds of each of the course's notebooks while it is graded, against the limit per
notebook run (``NOTEBOOK_CPU_S``).

``python benchmarks/notebook_cpu.py [--learners N] [--burners B]`` grades, with
``ros2nb-grade`` in its sandboxes, a class of ``N`` learners (default 2) who each handed in the
course's solutions, beside ``B`` processes that keep a CPU busy each (default 0; 2 is the
busy machine the guide asks tests to hold on).  Meanwhile it reads the CPU time of every
process under the grader from ``/proc`` (every 50 ms) and sums it per notebook: the run (the
sandboxed runner, its kernel and whatever the kernel started, such as colcon) and the judge
(with its subjects).  It prints the largest run and judge of each notebook, then how many
times the heaviest run fits in the limit.  Needs what grading needs (root and bubblewrap);
Linux only.
"""

from __future__ import annotations

import argparse
import collections
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
from sampling import TreeCpu  # noqa: E402

GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
#: A run's and a judge's scratch folders name the notebook: ``run-in-03-...``, ``judge-in-03-...``.
PART = re.compile(r'/(run|judge)-in-(\d\d)-')


def per_notebook(cpu: TreeCpu) -> dict[tuple[str, str], float]:
    """CPU seconds per (learner scratch, 'run' or 'judge', notebook number), from the
    nearest ancestor whose command line names a run or a judge folder."""
    totals: collections.Counter = collections.Counter()
    for (pid, _start), seconds in cpu.seen.items():
        seen, at = set(), pid
        while at in cpu.command and at not in seen:
            seen.add(at)
            found = PART.search(cpu.command[at])
            if found:
                learner = cpu.command[at][:found.start()].rsplit('/', 1)[-1]
                totals[(learner, found.group(1), found.group(2))] += seconds
                break
            at = cpu.parent[at]
    return totals


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--learners', type=int, default=2)
    parser.add_argument('--burners', type=int, default=0)
    options = parser.parse_args()
    from ros2nb_instructor.grading.settings import NOTEBOOK_CPU_S
    burners = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
               for _ in range(options.burners)]
    try:
        with tempfile.TemporaryDirectory(prefix='ros2nb-notebook-cpu-') as tmp:
            for n in range(options.learners):
                shutil.copytree(ROOT / 'solutions', Path(tmp) / 'class' / f'learner{n + 1}',
                                ignore=shutil.ignore_patterns('.*'))
            started = time.monotonic()
            proc = subprocess.Popen([GRADE, f'{tmp}/class', '--out', f'{tmp}/grading'],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            with TreeCpu(proc.pid) as cpu:
                output, _ = proc.communicate()
            wall = time.monotonic() - started
    finally:
        for burner in burners:
            burner.kill()
    if proc.returncode != 0:
        sys.exit(f'ros2nb-grade exited {proc.returncode}: {output[-800:]}')
    largest: dict[tuple[str, str], float] = {}
    for (_learner, part, notebook), seconds in per_notebook(cpu).items():
        largest[(notebook, part)] = max(largest.get((notebook, part), 0.0), seconds)
    print(f'{options.learners} learners beside {options.burners} busy CPUs: {wall:.0f} s wall, '
          f'{sum(cpu.seen.values()):.0f} CPU-s in all')
    print('| notebook | run CPU-s (largest) | judge CPU-s (largest) |\n|---|---|---|')
    for notebook in sorted({nb for nb, _part in largest}):
        print(f'| {notebook} | {largest.get((notebook, "run"), 0):.1f} '
              f'| {largest.get((notebook, "judge"), 0):.1f} |')
    heaviest = max(s for (_nb, part), s in largest.items() if part == 'run')
    print(f'heaviest run: {heaviest:.1f} CPU-s; the limit, {NOTEBOOK_CPU_S} CPU-s, '
          f'is {NOTEBOOK_CPU_S / heaviest:.1f} times it')
    return 0


if __name__ == '__main__':
    sys.exit(main())
