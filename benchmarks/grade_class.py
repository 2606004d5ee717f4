#!/usr/bin/env python3
"""Benchmark: time to grade a class (default 30 learners x 6 notebooks) with tools/grade.py.

Every learner submits the six solution notebooks, so every notebook runs in full
(the most work a class can cause, barring time-outs).  Prints the wall time and the
time per notebook.  Usage: ``make benchmark-grading`` or
``python benchmarks/grade_class.py --learners 30 --jobs 2``.
"""

from __future__ import annotations

import argparse
import csv
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--learners', type=int, default=30)
    parser.add_argument('--jobs', type=int, default=2)
    args = parser.parse_args()
    notebooks = sorted((ROOT / 'solutions').glob('*.ipynb'))
    with tempfile.TemporaryDirectory(prefix='ros2nb-grade-bench-') as tmp:
        submissions = Path(tmp) / 'submissions'
        for i in range(1, args.learners + 1):
            learner = submissions / f'learner{i:02d}'
            learner.mkdir(parents=True)
            for notebook in notebooks:
                shutil.copy2(notebook, learner / notebook.name)
        started = time.perf_counter()
        done = subprocess.run([sys.executable, str(ROOT / 'tools' / 'grade.py'), str(submissions),
                               '--out', str(Path(tmp) / 'grading'), f'--jobs={args.jobs}'],
                              capture_output=True, text=True)
        elapsed = time.perf_counter() - started
        with open(Path(tmp) / 'grading' / 'grades.csv', newline='') as stream:
            totals = [row['score'] for row in csv.DictReader(stream) if row['notebook'] == 'TOTAL']
        full = totals.count('18')
        notes = [line for line in done.stdout.splitlines() if '(' in line][:3]
    count = args.learners * len(notebooks)
    print(f'graded {args.learners} learners x {len(notebooks)} notebooks ({count} notebooks, '
          f'{args.jobs} at a time) in {elapsed / 60:.1f} min ({elapsed / count:.1f} s per '
          f'notebook); exit code {done.returncode}; {full} of {args.learners} scored 18/18')
    for line in notes:
        print(f'  note: {line[:300]}')


if __name__ == '__main__':
    main()
