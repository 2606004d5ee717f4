#!/usr/bin/env python3
"""What a judge's subject costs to start: started afresh, and forked from the fork server.

``python benchmarks/subject_start.py [--subjects N]`` starts N subjects one after another in
each way (:class:`ros2nb.judge.subjects.SubjectProcess`); each runs one cell that starts
rclpy and a node, then quits.  It prints the machine's busy CPU seconds per subject (the
judge's own share included) and the wall seconds, for each way.  Afresh is what a
sandboxed subject is (a sandbox command in front, here ``env``); forked is what every later
unsandboxed subject of a judge is (``ros2nb.subject.forked``), the fork server's own start
included.  Run it on an otherwise idle machine: every process's CPU counts.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from grading_profile import busy_cpu_s  # noqa: E402

from ros2nb.judge.subjects import SUBJECT_PREFIX_ENV, SubjectProcess  # noqa: E402
from ros2nb.subject_interface import ExecCells  # noqa: E402

CELL = 'import rclpy\nfrom rclpy.node import Node\nrclpy.init()\nnode = Node("started")\n'


def run(count: int, folder: Path) -> tuple[float, float]:
    """Start ``count`` subjects one after another: busy CPU-s and wall s per subject."""
    busy, began = busy_cpu_s(), time.monotonic()
    for _ in range(count):
        subject = SubjectProcess(folder)
        reply = subject.request(ExecCells(sources=[CELL]))
        assert reply.cell_errors == [], reply
        subject.close()
    return (busy_cpu_s() - busy) / count, (time.monotonic() - began) / count


def measure(count: int) -> None:
    """Print the table (run with ``python -c``: a judge run from a script file never forks
    its subjects, :func:`ros2nb.subject.forked.forkable`)."""
    with tempfile.TemporaryDirectory() as folder:
        os.environ[SUBJECT_PREFIX_ENV] = json.dumps(['env'])
        afresh = run(count, Path(folder))
        del os.environ[SUBJECT_PREFIX_ENV]
        forked = run(count, Path(folder))  # the first of this process was started above
    print('| subject | busy CPU-s each | wall s each |')
    print('|---|---|---|')
    for name, (cpu, wall) in (('started afresh', afresh), ('forked', forked)):
        print(f'| {name} | {cpu:.3f} | {wall:.3f} |')


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--subjects', type=int, default=20)
    count = parser.parse_args().subjects
    here = str(Path(__file__).resolve().parent)
    return subprocess.call([sys.executable, '-c', f'import sys\nsys.path.insert(0, {here!r})\n'
                            f'import subject_start\nsubject_start.measure({count})'])


if __name__ == '__main__':
    sys.exit(main())
