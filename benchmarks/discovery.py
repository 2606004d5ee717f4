#!/usr/bin/env python3
"""How long a new node takes to appear in a running judge's graph, with and without the
course's Fast DDS profile (``ros2nb.domains.DISCOVERY_PROFILE``).

``python benchmarks/discovery.py [--starts N] [--runs R]`` runs R judges of each kind, one
after another, each in a fresh process of its own (Fast DDS reads its profile once per
process): the judge's node (:class:`ros2nb.judge.observer.Observer`) watches N processes
started one after another, each making one node and leaving ROS cleanly, as a check's
subjects do (``tests/nodes.py``'s ``join_times``).  It prints, per judge, the seconds from
each node being made to the judge seeing it.  Every process runs with
``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``, as in a learner's kernel.  Run it on an
otherwise idle machine.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
KINDS = ('course profile', 'Fast DDS default')


def judge(kind: str, starts: int) -> None:
    """In a process of its own: one judge of ``kind``; print its join times as JSON."""
    sys.path.insert(0, str(HERE.parent / 'tests'))
    from ros2nb import domains
    if kind == 'Fast DDS default':  # what every process of the course had before the profile
        domains.use_discovery_profile = lambda: None  # type: ignore[assignment]  # DDS own
        os.environ.pop(domains.PROFILE_ENV, None)
    from nodes import join_times

    from ros2nb.judge.observer import Observer
    from ros2nb.judge.subjects import subject_env
    observer = Observer()
    try:
        print(json.dumps(join_times(observer, starts, subject_env())))
    finally:
        observer.close()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--starts', type=int, default=8)
    parser.add_argument('--runs', type=int, default=3)
    parser.add_argument('--judge', choices=KINDS, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.judge:
        judge(args.judge, args.starts)
        return 0
    env = dict(os.environ, ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    print('| profile | run | seconds until each new node was seen | slowest |')
    print('|---|---|---|---|')
    for run in range(1, args.runs + 1):
        for kind in KINDS:
            done = subprocess.run([sys.executable, __file__, '--judge', kind, '--starts',
                                   str(args.starts)], env=env, capture_output=True, text=True,
                                  check=True)
            times = json.loads(done.stdout.strip().splitlines()[-1])
            print(f'| {kind} | {run} | {" ".join(f"{t:.2f}" for t in times)} '
                  f'| {max(times):.2f} |')
    return 0


if __name__ == '__main__':
    sys.exit(main())
