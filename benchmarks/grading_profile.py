#!/usr/bin/env python3
"""Where grading's CPU time goes: the sample class graded once, its CPU seconds by process kind.

``python benchmarks/grading_profile.py [LEARNER ...]`` builds the sample class of
``tests/grading_samples.py`` (every learner, or only those named), grades it with
``ros2nb-grade`` in its sandboxes, and meanwhile reads every new process's CPU time from
``/proc`` (user + system, every 50 ms, the last reading of each process kept).  It prints the
wall seconds, the machine's busy CPU seconds over the run (``/proc/stat``: this and anything
else running), and the CPU seconds of each kind of process (kernels, subjects, judges, the
runners, nbgrader, colcon and ``setup.py``, the learners' own programs) with their counts.

Run it on an otherwise idle machine: every process started meanwhile is counted.  A
process that lives less than 50 ms is missed, so the kinds add up to a little less than the
busy total.  Needs what grading needs (root and bubblewrap); Linux only.
"""

from __future__ import annotations

import collections
import os
import subprocess
import sys
import time
from pathlib import Path

from ros2nb.temporary import temporary_folder

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / 'tests'))
from grading_samples import EXPECTED, build  # noqa: E402
from sampling import Sampling  # noqa: E402

GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
TICKS_PER_S = os.sysconf('SC_CLK_TCK')
SAMPLE_S = 0.05
#: Process kinds, by a word of their command line (the first that matches names it).
KINDS = ('sandboxed.runner', 'ipykernel', 'ros2nb.subject', 'ros2nb.judge', 'colcon',
         'setup.py', 'nbgrader', 'ros2nb-grade', 'temperature_publisher',
         'temperature_subscriber', 'bwrap', 'pytest', 'jupyterhub', 'chromium')


def kind_of(argv: list[str]) -> str:
    """The kind of a process, from its command line (``other: PROGRAM`` when none matches)."""
    line = ' '.join(argv)
    # chromium rewrites its argv[0] into one long line of options: its first word names it
    program = Path(argv[0].split(' ')[0]).name[:40] if argv and argv[0] else ''
    return next((kind for kind in KINDS if kind in line),
                f'other: {program}' if program else 'other')


def busy_cpu_s() -> float:
    """CPU seconds the whole machine has been busy (not idle, not waiting for I/O)."""
    fields = [int(v) for v in Path('/proc/stat').read_text().split('\n', 1)[0].split()[1:]]
    return (sum(fields) - fields[3] - fields[4]) / TICKS_PER_S


class Sampler(Sampling):
    """Every process that starts after it: its kind and its CPU seconds, read every 50 ms."""

    def __init__(self) -> None:
        super().__init__(SAMPLE_S)
        self.before = set(os.listdir('/proc'))
        self.seen: dict[tuple[str, str], tuple[str, float]] = {}

    def sample(self) -> None:
        for pid in os.listdir('/proc'):
            if pid.isdigit() and pid not in self.before:
                self._read(pid)

    def _read(self, pid: str) -> None:
        try:
            stat = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
            argv = Path(f'/proc/{pid}/cmdline').read_text().split('\0')[:-1]
        except OSError:  # ended meanwhile
            return
        key = (pid, stat[19])  # a pid is reused: its start time tells the processes apart
        known = self.seen.get(key)
        kind = kind_of(argv) if argv else (known[0] if known else 'other')  # a zombie has none
        self.seen[key] = (kind, (int(stat[11]) + int(stat[12])) / TICKS_PER_S)
        self.read_stat(key, stat)

    def read_stat(self, key: tuple[str, str], stat: list[str]) -> None:
        """What a subclass keeps of a process's ``/proc/PID/stat`` fields (after the name),
        read once per sample with the rest: nothing here."""

    def by_kind(self) -> list[tuple[str, float, int]]:
        """(kind, CPU seconds, processes), most CPU first."""
        seconds, count = collections.Counter(), collections.Counter()
        for kind, cpu in self.seen.values():
            seconds[kind] += cpu
            count[kind] += 1
        return [(kind, s, count[kind]) for kind, s in seconds.most_common()]


def main(learners: list[str]) -> int:
    unknown = sorted(set(learners) - set(EXPECTED))
    if unknown:
        print(f'no such learner in tests/grading_samples.py: {", ".join(unknown)}')
        return 2
    with temporary_folder('profile') as tmp:
        root = Path(tmp)
        decoy = root / 'elsewhere' / 'gradebook.db'
        decoy.parent.mkdir()
        decoy.write_bytes(b'not a gradebook')
        folder = build(root / 'class', grading_out=root / 'grading', submissions=root / 'class',
                       decoy_gradebook=decoy, home_file=root / 'home-file',
                       forged=root / 'forged.txt')
        for learner in folder.iterdir():
            if learners and learner.name not in learners:
                subprocess.run(['rm', '-rf', str(learner)], check=True)
        with Sampler() as sampler:
            busy, started = busy_cpu_s(), time.monotonic()
            done = subprocess.run([GRADE, str(folder), '--out', str(root / 'grading')],
                                  capture_output=True, text=True)
            wall, busy = time.monotonic() - started, busy_cpu_s() - busy
    if done.returncode != 0:
        print(f'ros2nb-grade exited {done.returncode}: {(done.stdout + done.stderr)[-800:]}')
        return 1
    count = len(learners) or len(EXPECTED)
    print(f'{count} learners graded in {wall:.0f} s; the machine was busy {busy:.0f} CPU-s')
    print(f'{"CPU-s":>8} {"processes":>9}  kind')
    for kind, seconds, processes in sampler.by_kind():
        if seconds >= 0.05:
            print(f'{seconds:8.1f} {processes:9d}  {kind}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
