#!/usr/bin/env python3
"""How long one learner of the corpora takes to grade, run after run.

``python benchmarks/learner_gradings.py [--learner NAME] [--runs N]`` grades the learner
(default: notebook 03's honest sensor without a timer) N times as the corpora's tests do
(``tests/corpora.py``: the judge's own command in a process of its own) and prints, per run,
the wall seconds, the machine's busy CPU seconds (run it on an otherwise idle machine) and
the parts lost; then the median and the slowest.  A judge that waits for what never comes
shows as a run many times the median's wall time at about the median's CPU time.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from ros2nb.temporary import temporary_folder

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / 'tests'))
from grading_profile import busy_cpu_s  # noqa: E402


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--learner', default='03 twin: no timer')
    parser.add_argument('--runs', type=int, default=10)
    options = parser.parse_args()
    from corpora import every_learner, grade_learner
    from corpus_checks import failed
    learners = every_learner()
    if options.learner not in learners:
        print(f'no learner {options.learner!r} in the corpora: pick one of tests/corpus_*.py')
        return 2
    learner, walls = learners[options.learner], []
    print(f'{options.learner}: | run | wall s | busy CPU-s | lost |')
    for run in range(1, options.runs + 1):
        began, cpu = time.monotonic(), busy_cpu_s()
        with temporary_folder('bench') as root:
            lost = sorted(failed(grade_learner(learner, Path(root))))
        walls.append(time.monotonic() - began)
        print(f'| {run} | {walls[-1]:.1f} | {busy_cpu_s() - cpu:.1f} | '
              f'{", ".join(lost) or "nothing"} |', flush=True)
    print(f'median {statistics.median(walls):.1f} s, slowest {max(walls):.1f} s')
    return 0


if __name__ == '__main__':
    sys.exit(main())
