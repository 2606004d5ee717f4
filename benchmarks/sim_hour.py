#!/usr/bin/env python3
"""Benchmark: wall time of one simulated hour of notebook 03 (sensor + recording).

Runs the course's reference publisher on simulated time for 3600 s, exactly as
03-write-the-publisher.ipynb records it for the plot, three times, and prints the wall
time of each run and the median.  Usage: ``make benchmark`` (or run with the venv's python).
"""

from __future__ import annotations

import contextlib
import io
import random
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'src'))

import ros2nb  # noqa: E402
from ros2nb.course import reference_source  # noqa: E402

SIMULATED_S = 3600
RUNS = 3


def one_run(module) -> float:
    with contextlib.redirect_stdout(io.StringIO()):  # the notebook's lines, not the timing
        ros2nb.start(sim_time=True)
    try:
        random.seed(2024)
        with contextlib.redirect_stdout(io.StringIO()):
            ros2nb.add(module.TemperatureSensor())
            started = time.perf_counter()
            _, values = ros2nb.record('temperature', SIMULATED_S)
            elapsed = time.perf_counter() - started
        assert len(values) == SIMULATED_S, len(values)
        return elapsed
    finally:
        ros2nb.shutdown()


def main() -> None:
    scratch = Path(__file__).resolve().parent / '.sim_hour_publisher.py'
    scratch.write_text(reference_source('temperature_publisher.py'))
    try:
        module = ros2nb.import_file(scratch, 'bench_publisher')
        times = [one_run(module) for _ in range(RUNS)]
    finally:
        scratch.unlink()
    for i, seconds in enumerate(times, start=1):
        print(f'run {i}: {SIMULATED_S} simulated s in {seconds:.2f} s wall')
    print(f'median: {statistics.median(times):.2f} s wall for one simulated hour '
          f'({SIMULATED_S / statistics.median(times):.0f}x real time)')


if __name__ == '__main__':
    main()
