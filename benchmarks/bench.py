#!/usr/bin/env python3
"""``make bench``: how ros2nb compares with bare rclpy, and how fast grading is, in one run.

Every figure is the median of ``--reps`` fresh runs (default 5), with the spread (fastest
and slowest), measured in one run on this machine, the peers interleaved so that whatever
else the machine does falls on both alike.

1. One simulated hour of the course's sensor, recorded: ros2nb (as notebook 03 does it) and
   a bare rclpy program doing the same work (benchmarks/peers.py); their ratio (bare's
   seconds over ros2nb's: 1.0 is as fast as bare rclpy) and ros2nb's speed in real time.
   Then the same hour in a real Jupyter kernel, where a learner runs it.
2. From starting the sensor to the first reading heard: in a kernel's runtime, and as two
   separate processes (what ``ros2 run`` starts).
3. Grading, in seconds per notebook: one learner who handed in every notebook complete
   (every cell runs, every check passes) and one who handed them in untouched (not
   attempted: not run, 0 and a note), each graded alone with ``ros2nb-grade`` in its
   sandboxes, nbgrader's set-up and feedback included.

Targets (issue "Fast and steady"): simulated hour >= 0.9 x bare rclpy and >= 1000x real
time; grading <= 10 s per notebook for a complete learner.

4. An idle runtime: a kernel's between cells (two nodes on simulated time) and a bare
   rclpy program's blocked in ``spin()``, in per cent of one CPU (dozens of kernels and
   judges sit idle at once in a class or in ``make test``).

5. Interrupting a kernel (the Stop button) during a wall-clock spin: seconds until the
   cell ends (target: under 1 s).

6. Only when asked (``--only class``): a whole class of ``--learners`` complete learners
   graded at once (``ros2nb-grade``'s default jobs), minutes in all and seconds per notebook;
   then the same class through a local Dask scheduler and two workers (``dask worker
   --nworkers 1 --nthreads 1``, ``--scheduler``), with the CPU seconds of each (every process
   each run started, the scheduler and workers included): their difference per learner is
   what the engine costs.  Two workers on two cores show that cost, not a speed-up.

Usage: ``make bench`` or
``python benchmarks/bench.py [--reps N] [--only sim|first|grading|idle|interrupt]``;
``make bench BENCH_ARGS='--only class --learners 30'`` for a class.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Iterator

from ros2nb.temporary import temporary_folder

ROOT = Path(__file__).resolve().parent.parent
PEERS = Path(__file__).resolve().parent / 'peers.py'
SIMULATED_S = 3600
#: The instructor's grading command, as the course's venv installs it.
GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
sys.path.insert(0, str(ROOT / 'tests'))
from dask_cluster import local_cluster  # noqa: E402 - the tests' cluster: Dask's own CLI


def peer(what: str, key: str = 'seconds') -> float:
    """What one fresh run of ``peers.py WHAT`` reports: wall seconds, or ``cpu_seconds``."""
    done = subprocess.run([sys.executable, str(PEERS), what], capture_output=True, text=True,
                          timeout=600)
    if done.returncode != 0:
        sys.exit(f'{what} failed: {done.stderr.strip()[-500:]}')
    return json.loads(done.stdout.strip().splitlines()[-1])[key]


def both(what: str) -> tuple[float, float]:
    """Wall and CPU seconds of one fresh run of ``peers.py WHAT``."""
    done = subprocess.run([sys.executable, str(PEERS), what], capture_output=True, text=True,
                          timeout=600)
    if done.returncode != 0:
        sys.exit(f'{what} failed: {done.stderr.strip()[-500:]}')
    reply = json.loads(done.stdout.strip().splitlines()[-1])
    return reply['seconds'], reply['cpu_seconds']


def grading_seconds_per_notebook(folder: str) -> float:
    """Grade one learner who handed in every notebook of ``folder``; seconds per notebook."""
    notebooks = sorted((ROOT / folder).glob('*.ipynb'))
    with temporary_folder('bench') as tmp:
        learner = Path(tmp) / 'class' / 'learner'
        learner.mkdir(parents=True)
        for notebook in notebooks:
            shutil.copy2(notebook, learner / notebook.name)
        started = time.perf_counter()
        done = subprocess.run([GRADE, str(learner.parent), '--out', str(Path(tmp) / 'grading')],
                              capture_output=True, text=True, timeout=1800)
        elapsed = time.perf_counter() - started
    if done.returncode != 0:
        sys.exit(f'grading {folder}/ failed: {done.stdout[-500:]}{done.stderr[-500:]}')
    return elapsed / len(notebooks)


#: cgroup v1's CPU accounting: a group's processes and all they start are counted, the
#: sandboxes too (they make groups of their own for pids and memory only).
CPUACCT = Path('/sys/fs/cgroup/cpuacct')


@contextlib.contextmanager
def cpu_counted() -> Iterator[list[float]]:
    """This process (and whatever it starts meanwhile) in a cpuacct group of its own; once
    the block ends, ``[seconds]`` holds their CPU seconds, or nan where no group can be made
    (rusage would miss the sandboxes: their processes are never waited for by ours)."""
    counted = [float('nan')]
    group = CPUACCT / f'ros2nb-bench-{os.getpid()}'
    try:
        group.mkdir()
        (group / 'cgroup.procs').write_text(str(os.getpid()))
    except OSError:
        yield counted
        return
    try:
        yield counted
    finally:
        counted[0] = int((group / 'cpuacct.usage').read_text()) / 1e9
        (CPUACCT / 'cgroup.procs').write_text(str(os.getpid()))
        with contextlib.suppress(OSError):
            group.rmdir()


def grade_class(learners: int, workers: int = 0) -> tuple[float, float, int, str]:
    """Grade ``learners`` learners who each handed in the complete notebooks: on this machine,
    or (``workers`` > 0) through a Dask scheduler and that many one-thread workers on loopback.

    :return: wall seconds in all (the cluster's start and stop included), CPU seconds of
        every process started, notebooks graded, and how many scored full marks (``k of n``).
    """
    notebooks = sorted((ROOT / 'solutions').glob('*.ipynb'))
    with temporary_folder('bench') as tmp:
        for number in range(1, learners + 1):
            learner = Path(tmp) / 'class' / f'learner{number:02d}'
            learner.mkdir(parents=True)
            for notebook in notebooks:
                shutil.copy2(notebook, learner / notebook.name)
        argv = [GRADE, str(Path(tmp) / 'class'), '--out', str(Path(tmp) / 'grading')]
        started = time.perf_counter()
        with cpu_counted() as cpu, (local_cluster(Path(tmp) / 'cluster', workers) if workers
                                    else contextlib.nullcontext()) as cluster:
            subprocess.run(argv + (['--scheduler', cluster.address] if cluster else []),
                           capture_output=True, timeout=7200)
        elapsed = time.perf_counter() - started
        with open(Path(tmp) / 'grading' / 'grades.csv', newline='') as stream:
            totals = [r for r in csv.DictReader(stream) if r['notebook'] == 'TOTAL']
    full = sum(1 for r in totals if float(r['score']) == float(r['max_score']))
    return elapsed, cpu[0], learners * len(notebooks), f'{full} of {learners}'


def interleaved(measures: dict[str, callable], reps: int) -> dict[str, list[float]]:
    """Run every measure once per round, ``reps`` rounds; return the seconds of each."""
    times: dict[str, list[float]] = {name: [] for name in measures}
    for _ in range(reps):
        for name, measure in measures.items():
            times[name].append(measure())
    return times


def row(label: str, seconds: list[float], note: str = '') -> str:
    median = statistics.median(seconds)
    return (f'| {label} | {median:.2f} | {min(seconds):.2f}–{max(seconds):.2f} | '
            f'{len(seconds)} | {note} |')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--reps', type=int, default=5)
    parser.add_argument('--only', choices=('sim', 'first', 'grading', 'idle', 'interrupt',
                                           'class'))
    parser.add_argument('--learners', type=int, default=30, help='class size for --only class')
    args = parser.parse_args()
    sys.stdout.reconfigure(line_buffering=True)  # each row as measured: a run cut short keeps it
    print('| measure | median s | spread s | runs | |\n|---|---|---|---|---|')
    if args.only in (None, 'sim'):
        runs = interleaved({'ros2nb': lambda: both('sim-hour-ros2nb'),
                            'bare': lambda: both('sim-hour-bare'),
                            'kernel': lambda: both('sim-hour-kernel')}, args.reps)
        wall = {k: [w for w, _ in v] for k, v in runs.items()}
        cpu = {k: [c for _, c in v] for k, v in runs.items()}
        ours, bare = (statistics.median(wall[k]) for k in ('ros2nb', 'bare'))
        print(row('simulated hour, ros2nb', wall['ros2nb'],
                  f'{SIMULATED_S / ours:.0f}x real time (target >= 1000x)'))
        print(row('simulated hour, bare rclpy', wall['bare'],
                  f'{SIMULATED_S / bare:.0f}x real time'))
        print(f'| speed ratio, bare seconds / ros2nb seconds | {bare / ours:.2f} | | | '
              'target >= 0.9 |')
        ours_cpu, bare_cpu = (statistics.median(cpu[k]) for k in ('ros2nb', 'bare'))
        print(row('simulated hour, ros2nb, CPU s of the process', cpu['ros2nb']))
        print(row('simulated hour, bare rclpy, CPU s of the process', cpu['bare']))
        print(f'| CPU ratio, bare / ros2nb | {bare_cpu / ours_cpu:.2f} | | | less '
              'sensitive to a busy machine than wall time |')
        print(row('simulated hour in a Jupyter kernel, the cell', wall['kernel'],
                  f'{SIMULATED_S / statistics.median(wall["kernel"]):.0f}x real time'))
        print(row('simulated hour in a Jupyter kernel, CPU s of the kernel', cpu['kernel'],
                  "every thread: ipykernel's output thread too"))
    if args.only in (None, 'first'):
        first = interleaved({'kernel': lambda: peer('first-message-kernel'),
                             'processes': lambda: peer('first-message-processes')}, args.reps)
        print(row('first message, in a kernel', first['kernel'],
                  'the sensor publishes every 1 s'))
        print(row('first message, two processes', first['processes'],
                  'process start and discovery included'))
    if args.only in (None, 'grading'):
        graded = interleaved({'complete': lambda: grading_seconds_per_notebook('solutions'),
                              'untouched': lambda: grading_seconds_per_notebook('notebooks')},
                             args.reps)
        print(row('grading, complete learner, per notebook', graded['complete'],
                  'target <= 10 s'))
        print(row('grading, untouched learner, per notebook', graded['untouched']))
    if args.only in (None, 'idle'):
        idle = interleaved({'kernel': lambda: 100 * both('idle-kernel')[1],
                            'bare': lambda: 100 * both('idle-bare')[1]}, args.reps)
        print(row('idle kernel, two nodes on simulated time, % of one CPU', idle['kernel'],
                  'between cells'))
        print(row('idle bare rclpy, the same nodes in spin(), % of one CPU', idle['bare']))
    if args.only in (None, 'interrupt'):
        stopped = interleaved({'kernel': lambda: peer('interrupt-kernel')}, args.reps)
        print(row('Stop during a wall-clock spin, interrupt to the cell\'s end (kernel)',
                  stopped['kernel'],
                  'target < 1 s (a timed test would fail on a busy machine)'))
    if args.only == 'class':
        runs = {}
        for label, workers in (('here', 0), ('Dask, 2 workers', 2)):
            elapsed, cpu, count, full = runs[label] = grade_class(args.learners, workers)
            print(f'| a class of {args.learners} complete learners, {label} | {elapsed:.0f} | '
                  f'| 1 | {elapsed / 60:.1f} min, {elapsed / count:.1f} s per notebook, '
                  f'{cpu:.0f} CPU-s; {full} with the highest total |')
        (wall_here, cpu_here, *_), (wall_dask, cpu_dask, *_) = runs.values()
        print(f'| Dask\'s overhead per learner, CPU-s (wall s) | '
              f'{(cpu_dask - cpu_here) / args.learners:.2f} | | 1 | '
              f'{(wall_dask - wall_here) / args.learners:.2f} s of wall time per learner |')


if __name__ == '__main__':
    main()
