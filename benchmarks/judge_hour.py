#!/usr/bin/env python3
"""What a simulated hour on the judge's clock costs: notebook 03's hidden hour check.

``python benchmarks/judge_hour.py [--hours N]`` makes the workspace notebook 03 leaves
(the course's solution, written by ``catch_up``), then runs ``check_sensor_hour`` N times in
one judge (this process, as ``tests/corpora.py`` grades): each is 3600 steps of the judge's
``/clock``, one reading and one log line each.  It prints, per hour, the wall seconds, the
judge's CPU seconds (this process) and the machine's busy CPU seconds (the subject's share
included).  Run it on an otherwise idle machine: every process's CPU counts.
"""

from __future__ import annotations

import argparse
import resource
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / 'tests'))
from grading_profile import busy_cpu_s  # noqa: E402


def own_cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--hours', type=int, default=3)
    hours = parser.parse_args().hours
    from judging import judging_env
    from ros2nb import checks, course
    from ros2nb.judge_interface import captured
    from ros2nb.judge.session import Session
    print('| hour | wall s | judge CPU-s | machine busy CPU-s | verdict |')
    print('|---|---|---|---|---|')
    with tempfile.TemporaryDirectory() as tmp, judging_env(Path(tmp)) as workspace:
        course.catch_up(4)  # the workspace as notebook 03 leaves it
        session = Session(workspace)
        try:
            for hour in range(1, hours + 1):
                wall, judge, busy = time.monotonic(), own_cpu_s(), busy_cpu_s()
                outcome = captured(lambda: checks.run_check('check_sensor_hour', session))
                print(f'| {hour} | {time.monotonic() - wall:.2f} | {own_cpu_s() - judge:.2f} '
                      f'| {busy_cpu_s() - busy:.2f} | '
                      f'{"passed" if outcome.passed else (outcome.message or "")[:60]} |')
        finally:
            session.close()
    return 0


if __name__ == '__main__':
    sys.exit(main())
