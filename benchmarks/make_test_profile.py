#!/usr/bin/env python3
"""Where ``make test``'s CPU goes while it runs: each process charged to the test that started it.

``python benchmarks/make_test_profile.py [--top N]`` runs ``make test`` in this checkout
with a pytest plugin (:mod:`timing_plugin`) that logs when each test starts and ends in each
pytest process (xdist's workers, the two nbval passes), and meanwhile reads every new
process's CPU time and parent from ``/proc`` every 50 ms.  A process is charged to the test
its pytest process was running when it started, through its parents (kernels, judges,
subjects, sandboxes, colcon); a pytest process's own CPU to the test that used it.  It
prints the wall seconds, the CPU seconds and summed wall seconds of each test file, the N
costliest tests, and the CPU no test started (an image's containers, for one).

Unlike ``benchmarks/test_profile.py`` (each file alone), this is the run itself, files side
by side as ``make test`` schedules them.  ``make test`` is CPU-bound on two cores and its
workers end within seconds of each other, so these seconds are what a cut must lower.  Run
it on an otherwise idle machine: every process started meanwhile is counted.  Linux only.
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from ros2nb.temporary import temporary_folder

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from grading_profile import Sampler, busy_cpu_s  # noqa: E402
from timing_plugin import LOG_ENV  # noqa: E402


class Family(Sampler):
    """:class:`grading_profile.Sampler` that also keeps each process's parent and when it
    was first seen: ``(pid, start ticks) -> (parent pid, first seen, CPU seconds)``."""

    def __init__(self) -> None:
        super().__init__()
        self.family: dict[tuple[str, str], tuple[str, float, float]] = {}

    def read_stat(self, key: tuple[str, str], stat: list[str]) -> None:
        # the parent when first seen: an orphan's parent becomes 1 (or a subreaper) later
        parent, seen, _cpu = self.family.get(key, (stat[1], time.monotonic(), 0.0))
        self.family[key] = (parent, seen, self.seen[key][1])


def during(tests: list[tuple[float, float, str]], seen: float) -> str | None:
    """The test running at ``seen``; else the next one to start (nbval starts a notebook's
    kernel before its first cell), else the last one."""
    for start, end, name in tests:
        if start <= seen <= end:
            return name
    later = [(start, name) for start, _end, name in tests if start > seen]
    return min(later)[1] if later else (tests[-1][2] if tests else None)


def charged(sampler: Family, spans: dict[int, list[tuple[float, float, str]]]
            ) -> tuple[collections.Counter, collections.Counter]:
    """CPU seconds per test id, and per kind of process (:func:`grading_profile.kind_of`)
    of what no test started."""
    by_pid = collections.defaultdict(list)
    for key, (parent, seen, cpu) in sampler.family.items():
        kind = sampler.seen.get(key, ('other', 0.0))[0]
        by_pid[int(key[0])].append((seen, int(parent), cpu, kind))

    def runner_of(pid: int, seen: float) -> int | None:
        for _hop in range(64):
            if pid in spans:
                return pid
            older = [life for life in by_pid.get(pid, []) if life[0] <= seen + 0.1]
            if not older:
                return None
            pid = max(older)[1]
        return None

    per_test, unclaimed = collections.Counter(), collections.Counter()
    for pid, lives in by_pid.items():
        for seen, parent, cpu, kind in lives:
            if pid in spans:
                continue  # a pytest process: its own CPU is charged per test below
            runner = runner_of(parent, seen)
            test = during(spans.get(runner, []), seen) if runner else None
            if test is None:
                unclaimed[kind] += cpu
            else:
                per_test[test] += cpu
    return per_test, unclaimed


def read_log(path: Path) -> tuple[dict[int, list[tuple[float, float, str]]], collections.Counter,
                                   dict[str, float]]:
    """Each pytest process's tests as (start, end, id), their own CPU and wall seconds."""
    spans, own, wall, started = collections.defaultdict(list), collections.Counter(), {}, {}
    for line in path.read_text().splitlines():
        entry = json.loads(line)
        key = (entry['pid'], entry['test'])
        if entry['event'] == 'start':
            started[key] = entry
        elif key in started:
            first = started.pop(key)
            spans[entry['pid']].append((first['t'], entry['t'], entry['test']))
            own[entry['test']] += entry['cpu'] - first['cpu']
            wall[entry['test']] = entry['t'] - first['t']
    return spans, own, wall


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--top', type=int, default=25, help='tests to list (default 25)')
    parser.add_argument('--output', type=Path, default=None,
                        help="a file for make test's own output (default: none kept)")
    parser.add_argument('--every-test', type=Path, default=None,
                        help='a file for the CPU and wall seconds of every test, one a line')
    parser.add_argument('command', nargs='*', default=['make', '--no-print-directory', 'test'],
                        help='what to run instead of make test (after --), e.g. '
                             '-- .venv/bin/python -m pytest tests/test_isolation.py')
    options = parser.parse_args()
    top = options.top
    root = HERE.parent
    with temporary_folder('profile') as tmp:
        log = Path(tmp) / 'tests.jsonl'
        env = dict(os.environ, PYTEST_ADDOPTS='-p timing_plugin', **{LOG_ENV: str(log)},
                   PYTHONPATH=os.pathsep.join(filter(None, [str(HERE),
                                                            os.environ.get('PYTHONPATH')])))
        with Family() as sampler:
            busy, started = busy_cpu_s(), time.monotonic()
            with open(options.output or os.devnull, 'w') as output:
                done = subprocess.run(options.command, cwd=root, env=env, stdout=output,
                                      stderr=subprocess.STDOUT)
            wall, busy = time.monotonic() - started, busy_cpu_s() - busy
        spans, own, walls = read_log(log) if log.exists() else ({}, collections.Counter(), {})
    per_test, unclaimed = charged(sampler, spans)
    per_test.update(own)
    files, file_wall = collections.Counter(), collections.Counter()
    for test, cpu in per_test.items():
        files[test.split('::')[0]] += cpu
        file_wall[test.split('::')[0]] += walls.get(test, 0.0)
    print(f'{" ".join(options.command)} exited {done.returncode} after {wall:.0f} s; the '
          f'machine was busy {busy:.0f} CPU-s, {sum(per_test.values()):.0f} of them charged '
          'to a test')
    print(f'{"CPU-s":>8} {"wall-s":>7}  test file (wall: its tests\' seconds, summed)')
    for name, cpu in files.most_common():
        print(f'{cpu:8.1f} {file_wall[name]:7.1f}  {name}')
    if options.every_test:
        options.every_test.write_text(''.join(
            f'{cpu:.2f}\t{walls.get(test, 0.0):.2f}\t{test}\n'
            for test, cpu in per_test.most_common()))
    print(f'\n{"CPU-s":>8} {"wall-s":>7}  the {top} costliest tests')
    for test, cpu in per_test.most_common(top):
        print(f'{cpu:8.1f} {walls.get(test, 0.0):7.1f}  {test[:150]}')
    print(f'\n{"CPU-s":>8} {"processes":>9}  kind (every process seen, charged or not)')
    for kind, seconds, processes in sampler.by_kind()[:top]:
        print(f'{seconds:8.1f} {processes:9d}  {kind}')
    print(f'\nno test started {sum(unclaimed.values()):.1f} CPU-s: ' + ', '.join(
        f'{kind} {cpu:.1f}' for kind, cpu in unclaimed.most_common(6)))
    return done.returncode


if __name__ == '__main__':
    sys.exit(main())
