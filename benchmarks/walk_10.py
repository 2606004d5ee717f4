#!/usr/bin/env python3
"""Notebook 10's recording check after a failed attempt, as a learner runs it, in a real kernel.

``python benchmarks/walk_10.py [--runs N] [--import-again] [--gc-off]``: a workspace caught up
to notebook 10 whose monitor lacks 08's part 4 (its ``TemperatureMonitor()`` raises
half-built); the context cell, ``record_hour``'s cell and ``check_recording`` (fails for the
part); 08's part 4 written, ``record_hour``'s cell (with ``--import-again`` the context cell
first) and the check again (a sensor of the first try still runs); ``ros2nb.stop()`` and the
check.  Python's collector is left to itself (``--gc-off``: held off in the kernel from the
start), unlike the test of the walk, which runs it once the new monitor runs
(``tests/test_earlier_notebooks.py``).  Prints each check's line and the kernel's CPU-s, run
by run.  With main's code on ``PYTHONPATH`` it shows what the walk met before.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ros2nb.temporary import owned_folder

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / 'tests'))
from kernels import (CATCH_UP_10, CHECK_RECORDING_10, CONTEXT_10, PARTS_04,  # noqa: E402
                     PARTS_08, RECORD_HOUR_10, Kernel, monitor)

from ros2nb.course import SUBSCRIBER_FILE as SUBSCRIBER  # noqa: E402

CPU = 'import os; print(sum(os.times()[:2]))'


def line(cell) -> str:
    """What a check's cell said: its one error line, or its first line printed."""
    return cell.error[1][-1] if cell.error else cell.stdout.strip().splitlines()[0]


def walk(import_again: bool, gc_off: bool) -> None:
    ws = owned_folder('ros2nb-walk-10-') / 'ws'
    kernel = Kernel(ws)
    try:
        kernel.run(CATCH_UP_10)
        (ws / SUBSCRIBER).write_text(monitor({**PARTS_08, 4: PARTS_04[4]}))
        kernel.run(CONTEXT_10)
        kernel.run(RECORD_HOUR_10)
        if gc_off:
            kernel.run('import gc; gc.disable()')
        said = [line(kernel.run(CHECK_RECORDING_10))]
        (ws / SUBSCRIBER).write_text(monitor(PARTS_08))
        if import_again:
            kernel.run(CONTEXT_10)
        kernel.run(RECORD_HOUR_10)
        said.append(line(kernel.run(CHECK_RECORDING_10)))
        kernel.run('ros2nb.stop()')
        said.append(line(kernel.run(CHECK_RECORDING_10)))
        cpu = float(kernel.run(CPU).stdout)
    finally:
        kernel.close()
    for number, text in enumerate(said, start=1):
        print(f'  check {number}: {text[:160]}')
    print(f'  kernel: {cpu:.1f} CPU-s', flush=True)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=1)
    parser.add_argument('--import-again', action='store_true')
    parser.add_argument('--gc-off', action='store_true')
    args = parser.parse_args()
    for run in range(1, args.runs + 1):
        print(f'run {run}:')
        walk(args.import_again, args.gc_off)


if __name__ == '__main__':
    main()
