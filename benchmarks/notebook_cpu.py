#!/usr/bin/env python3
"""CPU seconds of each of the course's notebooks while it is graded, against the limits per
notebook run (``NOTEBOOK_CPU_S``) and per notebook's judge (``JUDGE_CPU_S``).

``python benchmarks/notebook_cpu.py [--learners N] [--corpus] [--burners B] [--share K]``
grades, with ``ros2nb-grade`` in its sandboxes, a class of ``N`` learners (default 2) who each
handed in the course's solutions, and with ``--corpus`` every learner of
``tests/corpus_honest.py`` too (each its one notebook, written in a style of its own), beside
``B`` processes that keep a CPU busy each (default 0; 2 is the busy machine the guide asks
tests to hold on), the grading (and only it) held to ``1/K`` of a core with ``--share K``
(a cgroup's CPU quota, as a hub's pod is: 6 for a sixth).  Meanwhile it reads the CPU time
of every process under the grader from ``/proc`` (every 50 ms) and sums it per notebook: the
run (the sandboxed runner, its kernel and whatever the kernel started, such as colcon) and
the judge (with its subjects).  It prints the largest run and judge of each notebook, then
how many times the heaviest of each fits in its limit.  Needs what grading needs (root and
bubblewrap); Linux only.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

from ros2nb.temporary import temporary_folder

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


def cpu_share(share: int) -> Path:
    """A new cgroup whose tasks share ``1/share`` of one core (cgroup v1 ``cpu``, else v2)."""
    for parent, quota in ((Path('/sys/fs/cgroup/cpu'), 'cpu.cfs_quota_us'),
                          (Path('/sys/fs/cgroup'), 'cpu.max')):
        if (parent / quota).exists() or (parent / 'cgroup.controllers').exists():
            group = parent / f'ros2nb-bench-{os.getpid()}'
            group.mkdir()
            if quota == 'cpu.max':
                (group / quota).write_text(f'{100_000 // share} 100000')
            else:
                (group / 'cpu.cfs_period_us').write_text('100000')
                (group / quota).write_text(str(100_000 // share))
            return group
    sys.exit('no cgroup with a CPU quota can be made here (root, cgroup v1 cpu or v2)')


def class_folder(folder: Path, learners: int, corpus: bool) -> None:
    """``learners`` who handed in the solutions, and the honest corpus's learners."""
    for n in range(learners):
        shutil.copytree(ROOT / 'solutions', folder / f'learner{n + 1}',
                        ignore=shutil.ignore_patterns('.*'))
    if corpus:
        sys.path.insert(0, str(ROOT / 'tests'))
        from corpora import NOTEBOOKS, submission
        from corpus_honest import HONEST
        for n, learner in enumerate(HONEST):
            (folder / f'honest{n:02d}').mkdir(parents=True)
            (folder / f'honest{n:02d}' / NOTEBOOKS[learner.notebook].name).write_text(
                json.dumps(submission(learner)))


def handed(folder: Path) -> set[tuple[str, str]]:
    """(learner, notebook number) of every notebook in the class ``folder``."""
    return {(p.parent.name, p.name[:2]) for p in folder.glob('*/*.ipynb')}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--learners', type=int, default=2)
    parser.add_argument('--corpus', action='store_true', help='add the honest corpus')
    parser.add_argument('--burners', type=int, default=0)
    parser.add_argument('--share', type=int, default=0, help='grade on 1/K of a core')
    options = parser.parse_args()
    from ros2nb_instructor.grading.judging.settings import JUDGE_CPU_S, NOTEBOOK_CPU_S
    group = cpu_share(options.share) if options.share else None
    burners = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
               for _ in range(options.burners)]
    try:
        with temporary_folder('notebook-cpu') as tmp:
            class_folder(Path(tmp) / 'class', options.learners, options.corpus)
            started = time.monotonic()
            tasks = group and (group / 'tasks' if (group / 'tasks').exists()
                               else group / 'cgroup.procs')
            enter = f'echo $$ > {tasks}; ' if tasks else ''
            proc = subprocess.Popen(['sh', '-c', f'{enter}exec "$@"', 'sh', GRADE,
                                     f'{tmp}/class', '--out', f'{tmp}/grading'],
                                    stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
            with TreeCpu(proc.pid) as cpu:
                output, _ = proc.communicate()
            wall = time.monotonic() - started
            short = [row for row in (Path(tmp) / 'grading' / 'grades.csv').read_text()
                     .splitlines()[1:] if 'TOTAL' not in row and
                     (row.split(',')[0], row.split(',')[1][:2]) in handed(Path(tmp) / 'class')
                     and row.split(',')[2] != row.split(',')[3]] \
                if proc.returncode == 0 else []
    finally:
        for burner in burners:
            burner.kill()
        if group:
            group.rmdir()
    if proc.returncode != 0:
        sys.exit(f'ros2nb-grade exited {proc.returncode}: {output[-800:]}')
    noted = [line for line in output.splitlines() if line.endswith(')') and ': ' in line]
    print(f'handed-in notebooks below full marks: {short or "none"}')
    print('notes: ' + ('\n'.join(noted) if noted else 'none'))
    largest: dict[tuple[str, str], float] = {}
    for (_learner, part, notebook), seconds in per_notebook(cpu).items():
        largest[(notebook, part)] = max(largest.get((notebook, part), 0.0), seconds)
    print(f'{options.learners} learners{" and the honest corpus" if options.corpus else ""} '
          f'beside {options.burners} busy CPUs'
          f'{f", on 1/{options.share} of a core" if options.share else ""}: {wall:.0f} s wall, '
          f'{sum(cpu.seen.values()):.0f} CPU-s in all')
    print('| notebook | run CPU-s (largest) | judge CPU-s (largest) |\n|---|---|---|')
    for notebook in sorted({nb for nb, _part in largest}):
        print(f'| {notebook} | {largest.get((notebook, "run"), 0):.1f} '
              f'| {largest.get((notebook, "judge"), 0):.1f} |')
    heaviest = max(s for (_nb, kind), s in largest.items() if kind == 'run')
    print(f'heaviest run: {heaviest:.1f} CPU-s; the limit, {NOTEBOOK_CPU_S} CPU-s, '
          f'is {NOTEBOOK_CPU_S / heaviest:.1f} times it')
    margins = {nb: JUDGE_CPU_S[nb] / s for (nb, kind), s in largest.items() if kind == 'judge'}
    tightest = min(margins, key=margins.__getitem__)
    print(f'tightest judge: {tightest}, {largest[(tightest, "judge")]:.1f} CPU-s; its limit, '
          f'{JUDGE_CPU_S[tightest]} CPU-s, is {margins[tightest]:.1f} times it')
    return 0


if __name__ == '__main__':
    sys.exit(main())
