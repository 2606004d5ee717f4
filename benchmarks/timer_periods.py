#!/usr/bin/env python3
"""What notebook 03's checks see of a timer a little off its period, and what they cost.

``python benchmarks/timer_periods.py [PERIOD ...]`` (default ``1.0 0.99 1.02 2.0``) writes the
course's sensor with ``PUBLISH_PERIOD_S`` set to each period into a workspace that notebook
03 left, and runs the constructor's check, the callback's and the hidden hour on it in one
judge (this process, as ``tests/corpora.py`` grades).  It prints, per period and check, the
arrival times of the first readings on the judge's clock (seconds after the run began), the
verdict, the wall seconds and the CPU seconds of the judge and its subjects (every process
carrying this run's marker in its environment, read from ``/proc`` every 50 ms).  With the
interpreter of an older checkout's ``src`` on ``PYTHONPATH`` it measures that checkout.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import uuid
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / 'tests'))
from sampling import Sampling  # noqa: E402

TICKS_PER_S = os.sysconf('SC_CLK_TCK')
CHECKS = ('check_sensor_constructor', 'check_sensor_callback', 'check_sensor_hour')


class MarkedCpu(Sampling):
    """CPU seconds of every process whose environment holds ``marker`` (this one's children
    inherit it), read every 50 ms: other processes of a shared machine are left out."""

    def __init__(self, marker: str) -> None:
        super().__init__(0.05)
        self._marker = marker.encode()
        self.seen: dict[tuple[str, str], float] = {}

    def sample(self) -> None:
        for pid in os.listdir('/proc'):
            try:
                if not pid.isdigit() or self._marker not in \
                        Path(f'/proc/{pid}/environ').read_bytes():
                    continue
                stat = Path(f'/proc/{pid}/stat').read_text().rsplit(')', 1)[1].split()
            except OSError:  # ended meanwhile, or not ours
                continue
            self.seen[(pid, stat[19])] = (int(stat[11]) + int(stat[12])) / TICKS_PER_S

    def total(self) -> float:
        self.sample()
        return sum(self.seen.values())


def marked() -> str:
    """Put a marker of this run into this process's environment (its children inherit it)."""
    value = uuid.uuid4().hex
    os.environ['ROS2NB_BENCH_MARK'] = value
    return f'ROS2NB_BENCH_MARK={value}'


def main(periods: list[str]) -> int:
    marker = marked()
    from judging import judge_session
    from ros2nb import checks, course
    from ros2nb.checks import sensor_runs
    from ros2nb.judge_interface import captured
    seen: list[list[float]] = []
    real_run = sensor_runs.run_sensor

    def run(judge, sensor, seconds, **options):  # type: ignore[no-untyped-def]  # passed on
        result = real_run(judge, sensor, seconds, **options)
        seen.append([t for t, _value in result.readings])
        return result

    sensor_runs.run_sensor = run
    print('| period s | check | first readings (s on the judge\'s clock) | verdict | wall s '
          '| CPU-s |')
    print('|---|---|---|---|---|---|')
    with tempfile.TemporaryDirectory() as tmp, MarkedCpu(marker) as cpu, \
            judge_session(Path(tmp), 4) as session:
        file = session.workspace / course.PUBLISHER_FILE
        reference = file.read_text()
        for period in periods:
            file.write_text(reference.replace('PUBLISH_PERIOD_S = 1.0 ',
                                              f'PUBLISH_PERIOD_S = {period} '))
            session.drop(('file', course.PUBLISHER_FILE))
            for name in CHECKS:
                seen.clear()
                wall, used = time.monotonic(), cpu.total()
                outcome = captured(lambda: checks.run_check(name, session))
                verdict = 'passed' if outcome.passed else (outcome.message or '')[:70]
                first = ', '.join(f'{t:g}' for t in (seen[0][:4] if seen else []))
                print(f'| {period} | {name[6:]} | {first} | {verdict} | '
                      f'{time.monotonic() - wall:.1f} | {cpu.total() - used:.1f} |')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:] or ['1.0', '0.99', '1.02', '2.0']))
