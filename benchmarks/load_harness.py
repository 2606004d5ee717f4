#!/usr/bin/env python3
"""Whether a verdict depends on the machine's load: every learner graded idle and starved.

``python benchmarks/load_harness.py [--share 0.1667] [--burners 2] [--jobs 6] [--seed N]
[--only honest,wrong,class] [--out DIR]``

The honest and the wrong corpus (``tests/corpus_honest.py``, ``tests/corpus_wrong.py``, each
learner's notebook through the judge's own grading command, as ``tests/corpora.py`` grades
it) and the sample class (``tests/grading_samples.py``, through ``ros2nb-grade`` with its
sandboxes) are graded twice, with one seed of the drawn inputs, so that every check draws the
same inputs both times:

1. on the machine as it is (run it on an idle machine);
2. beside ``--burners`` CPU burners (``python3 -c 'while True: pass'``), each judge with its
   subjects, and each of the class's sandboxes, held to ``--share`` of one CPU by a cgroup
   quota (the grader's ``--cpu-share``: a sixth of a core is a small pod of a hub).

Then every verdict that differs is printed: a part that passed once and failed once, or failed
with another line (a learner's line must be the same word for word); for the class also a
score, a note or a failed check's line in a feedback page.  The exit code is 1 when one
differs.  Each pass's wall seconds and the CPU seconds of all it started (this process is
their subreaper, as ``tests/run_counted.py`` is for ``make test``) are printed and kept in
``DIR/report.json``.  Needs root (the cgroup quota) and bubblewrap (the class); Linux only.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import ctypes
import html
import json
import os
import re
import resource
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Iterator, Optional

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / 'tests'))
from ros2nb.temporary import temporary_folder  # noqa: E402
PR_SET_CHILD_SUBREAPER = 36  # linux/prctl.h
CORPORA = ROOT / 'tests' / 'corpora.py'
GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
#: A failed check's line in a feedback page (nbconvert writes the error's ``ename: evalue``).
FAILED_LINE = re.compile(r'\b(CheckFailed|LearnerCodeError|NotDecided|GradingError): ([^\n<]*)')
#: What a pass graded: learner (or ``class/<learner>/<notebook>``) -> what it made of them.
Verdicts = dict[str, object]


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _reap_orphans() -> None:
    while True:
        try:
            if os.waitpid(-1, os.WNOHANG)[0] == 0:
                return
        except ChildProcessError:
            return


@contextlib.contextmanager
def burners(count: int) -> Iterator[None]:
    """``count`` processes that each keep a CPU busy while the block runs."""
    running = [subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(count)]
    try:
        yield
    finally:
        for process in running:
            process.kill()
            process.wait()


def corpus_names(which: list[str]) -> list[str]:
    """The learners of the corpora named (``honest``, ``wrong``), in order."""
    from corpus_honest import HONEST
    from corpus_wrong import WRONG
    chosen = {'honest': HONEST, 'wrong': WRONG}
    return [learner.name for name in which if name in chosen for learner in chosen[name]]


#: CPU seconds of each check (``notebook-part``) of the corpora, the most any learner's took,
#: in the pass that ran last: what the CPU limit of one check must leave room for.
CHECK_CPU_S: dict[str, float] = {}


def grade_corpus(names: list[str], seed: int, share: Optional[float], jobs: int) -> Verdicts:
    """Each learner's results, ``jobs`` judges at a time (one ``tests/corpora.py`` each)."""
    CHECK_CPU_S.clear()

    def one(name: str) -> tuple[str, object]:
        argv = [sys.executable, str(CORPORA), '--json', '--seed', str(seed),
                *(['--cpu-share', str(share)] if share else []), name]
        done = subprocess.run(argv, capture_output=True, text=True, cwd=ROOT)
        lines = [line for line in done.stdout.splitlines() if line.startswith('{')]
        if not lines:
            return name, {'error': (done.stderr.strip().splitlines() or ['no output'])[-1]}
        found = json.loads(lines[-1])
        for part, cpu_s in found.get('cpu_s', {}).items():
            if isinstance(cpu_s, (int, float)):
                key = f'{name[:2]}-{part}'
                CHECK_CPU_S[key] = max(CHECK_CPU_S.get(key, 0.0), cpu_s)
        return name, found['results'] or {'error': found['error']}

    with ThreadPoolExecutor(jobs) as pool:
        return dict(pool.map(one, names))


def grade_class(folder: Path, seed: int, share: Optional[float], jobs: int) -> Verdicts:
    """The sample class graded by ros2nb-grade: each learner's score per notebook, its
    notes, and the failed checks' lines of each feedback page."""
    from grading_samples import build
    root = folder / 'class'
    out = folder / 'grading'
    (folder / 'elsewhere').mkdir(parents=True)
    decoy = folder / 'elsewhere' / 'gradebook.db'
    decoy.write_bytes(b'SQLite format 3\x00' + b'\x00' * 100)
    submissions = build(root, grading_out=out, submissions=root, decoy_gradebook=decoy,
                        home_file=folder / 'home-file', forged=folder / 'forged.txt')
    subprocess.run([GRADE, str(submissions), '--out', str(out), '--seed', str(seed),
                    '--jobs', str(jobs), *(['--cpu-share', str(share)] if share else [])],
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
    found: Verdicts = {}
    if (out / 'grades.csv').exists():
        with open(out / 'grades.csv', newline='') as stream:
            for row in csv.DictReader(stream):
                found[f"class/{row.get('learner')}/{row.get('notebook')}/score"] = \
                    row.get('raw_score')
    if (out / 'notes.json').exists():
        for learner, notes in json.loads((out / 'notes.json').read_text()).get(
                'learners', {}).items():
            found[f'class/{learner}/notes'] = notes
    for page in sorted((out / 'feedback').glob('*/*.html')):
        lines = sorted({f'{kind}: {html.unescape(text).strip()}' for kind, text in
                        FAILED_LINE.findall(page.read_text(errors='replace'))})
        found[f'class/{page.parent.name}/{page.stem}/failed'] = lines
    return found


def graded(which: list[str], seed: int, share: Optional[float], jobs: int
           ) -> tuple[Verdicts, float, float]:
    """One pass: what it made of every learner, its wall and CPU seconds."""
    began, cpu = time.monotonic(), _cpu_seconds()
    verdicts = grade_corpus(corpus_names(which), seed, share, jobs)
    if 'class' in which:
        with temporary_folder('load-harness') as folder:
            verdicts.update(grade_class(Path(folder), seed, share, jobs))
    _reap_orphans()
    return verdicts, time.monotonic() - began, _cpu_seconds() - cpu


def differences(idle: Verdicts, starved: Verdicts) -> list[str]:
    """One line per verdict that is not the same in both passes."""
    lines = []
    for key in sorted(set(idle) | set(starved)):
        a, b = idle.get(key), starved.get(key)
        if isinstance(a, dict) and isinstance(b, dict):
            for part in sorted(set(a) | set(b)):
                if a.get(part) != b.get(part):
                    lines.append(f'{key} {part}:\n    idle:    {a.get(part)}\n'
                                 f'    starved: {b.get(part)}')
        elif a != b:
            lines.append(f'{key}:\n    idle:    {a}\n    starved: {b}')
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--share', type=float, default=1 / 6,
                        help='CPUs each judge or sandbox gets in the starved pass (1/6)')
    parser.add_argument('--burners', type=int, default=2, help='CPU burners beside it (2)')
    parser.add_argument('--jobs', type=int, default=6, help='judges at a time (6)')
    parser.add_argument('--seed', type=int, default=74, help='the drawn inputs\' seed (74)')
    parser.add_argument('--only', default='honest,wrong,class',
                        help='what to grade, of honest, wrong, class')
    parser.add_argument('--out', type=Path, default=ROOT / 'load-harness')
    options = parser.parse_args()
    which = options.only.split(',')
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    options.out.mkdir(parents=True, exist_ok=True)
    idle, idle_wall, idle_cpu = graded(which, options.seed, None, options.jobs)
    idle_checks = dict(CHECK_CPU_S)
    print(f'idle: {len(idle)} verdicts in {idle_wall:.0f} s, {idle_cpu:.0f} CPU-s', flush=True)
    with burners(options.burners):
        starved, wall, cpu = graded(which, options.seed, options.share, options.jobs)
    starved_checks = dict(CHECK_CPU_S)
    print(f'{options.share:.3f} of a CPU each, beside {options.burners} burners: {len(starved)} '
          f'verdicts in {wall:.0f} s, {cpu:.0f} CPU-s (the burners\' not counted)', flush=True)
    differ = differences(idle, starved)
    (options.out / 'report.json').write_text(json.dumps({
        'seed': options.seed, 'share': options.share, 'burners': options.burners,
        'idle': {'wall_s': idle_wall, 'cpu_s': idle_cpu, 'verdicts': idle},
        'starved': {'wall_s': wall, 'cpu_s': cpu, 'verdicts': starved},
        'differ': differ, 'check_cpu_s': {'idle': idle_checks, 'starved': starved_checks}},
        indent=1))
    print('the costliest check of each kind, CPU-s idle / starved (judge and subjects):')
    for check in sorted(set(idle_checks) | set(starved_checks)):
        print(f'  {check}: {idle_checks.get(check, 0):.1f} / {starved_checks.get(check, 0):.1f}')
    print('\n'.join(differ) if differ else 'no verdict differs')
    print(f'{len(differ)} verdicts differ of {len(set(idle) | set(starved))}')
    return 1 if differ else 0


if __name__ == '__main__':
    sys.exit(main())
