#!/usr/bin/env python3
"""Where ``make test``'s CPU goes: each test file (and each nbval pass) run alone, its CPU by kind.

``python benchmarks/test_profile.py [FILE ...]`` runs ``pytest FILE`` for every file of
``tests/`` (or those named, ``test_x.py`` or ``tests/test_x.py``; ``solutions`` and
``notebooks`` name the two nbval passes), one after the other, each in one pytest process,
and meanwhile reads every new process's CPU time from ``/proc``
(:class:`grading_profile.Sampler`).  It prints, per file, the wall seconds, the CPU seconds
of every process started (pytest's own included) and the three kinds that took most; then
the total.  ``make test`` is CPU-bound on two cores (its wall
time is its CPU time over the cores it gets), so the total is what a cut must lower.

The sampled CPU-s count every process started meanwhile, the test's or not: run it on an
otherwise idle machine.  The own CPU-s count only the test's processes, as ``make test``
counts a step's (tests/run_counted.py): what they and their descendants used once reaped,
orphans included (this process adopts them, ``PR_SET_CHILD_SUBREAPER``).  On a machine others
share, the own CPU-s are the number to compare.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(1, str(ROOT / 'tests'))
from grading_profile import Sampler, busy_cpu_s  # noqa: E402
from run_counted import adopt_orphans, reaped_cpu_s  # noqa: E402

NBVAL = {
    'solutions': ['--nbval', 'solutions', '--nbval-current-env', '--nbval-sanitize-with',
                  'tests/sanitize.cfg'],
    'notebooks': ['--nbval-lax', 'notebooks', '--nbval-current-env'],
}


def profile(name: str) -> tuple[float, float, float, list[tuple[str, float, int]], int]:
    """Run one file (or nbval pass) alone: wall s, busy CPU s, own CPU s, CPU by kind,
    pytest's exit code."""
    arguments = NBVAL.get(name, [f'tests/{Path(name).name}'])  # test_x.py or tests/test_x.py
    with Sampler() as sampler:
        busy, own, started = busy_cpu_s(), reaped_cpu_s(), time.monotonic()
        done = subprocess.run([sys.executable, '-m', 'pytest', '-q',
                               *arguments], cwd=ROOT, capture_output=True, text=True)
        wall, busy = time.monotonic() - started, busy_cpu_s() - busy
        own = reaped_cpu_s() - own
    return wall, busy, own, sampler.by_kind(), done.returncode


def main(names: list[str]) -> int:
    if any(name.startswith('-') for name in names):
        print(__doc__)
        return 0 if names == ['--help'] else 2
    names = names or [*sorted(p.name for p in (ROOT / 'tests').glob('test_*.py')), *NBVAL]
    adopt_orphans()
    sys.stdout.reconfigure(line_buffering=True)
    print('| file | wall s | CPU-s (processes) | own CPU-s | busy CPU-s | most CPU-s, by kind '
          '| exit |')
    print('|---|---|---|---|---|---|---|')
    total_cpu = total_wall = total_own = 0.0
    for name in names:
        wall, busy, own, kinds, code = profile(name)
        cpu = sum(seconds for _, seconds, _ in kinds)
        total_cpu, total_wall, total_own = total_cpu + cpu, total_wall + wall, total_own + own
        top = ', '.join(f'{kind} {seconds:.0f} ({count})' for kind, seconds, count in kinds[:3])
        print(f'| {name} | {wall:.0f} | {cpu:.0f} ({sum(c for *_, c in kinds)}) | {own:.0f} '
              f'| {busy:.0f} | {top} | {code} |')
    print(f'| total | {total_wall:.0f} | {total_cpu:.0f} | {total_own:.0f} | | | |')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
