#!/usr/bin/env python3
"""How long :class:`ros2nb.patience.Patience` takes to give up on a program, beside burners.

``python benchmarks/idle_threads.py [--burners B] [--limit S] [--runs N]`` shares one CPU
between B burners and, in turn, two programs: an idle one whose dozen threads each wake
twenty times a second (as a subject's Fast DDS threads do), and a starved worker (one
thread of the lowest scheduling class in an endless loop, beside the same dozen idle
threads).  For each it prints when Patience gave up (the idle program should be given up
after about S seconds of its idling; the worker, working however slowly, never within the
cut of 10 x S), with the watched program's CPU seconds and its threads' summed seconds on
the run queue meanwhile.  Nothing of the course runs but Patience.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time

from ros2nb.patience import Patience, _threads, tree_cpu_seconds

#: The program: a dozen threads that wake 20 times a second; with ``work``, a worker too.
PROGRAM = """
import os, sys, threading, time
os.sched_setaffinity(0, {int(sys.argv[1])})
os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
def tick():
    while True:
        time.sleep(0.05)
for _ in range(12):
    threading.Thread(target=tick, daemon=True).start()
print('up', flush=True)
if sys.argv[2] == 'work':
    while True:
        pass
time.sleep(3600)
"""
#: Where a run stops waiting for Patience (times the limit).
CUT = 10


def queued_s(pid: int) -> float:
    """The summed seconds the threads of ``pid`` stood on the run queue so far."""
    return sum(thread.queued_s for thread in _threads(pid).values())


def run(kind: str, cpu: int, limit: float) -> str:
    """One program watched until Patience gives up or the cut; a line that says how it went."""
    program = subprocess.Popen([sys.executable, '-c', PROGRAM, str(cpu), kind],
                               stdout=subprocess.PIPE, text=True)
    try:
        assert program.stdout is not None and program.stdout.readline() == 'up\n'
        began, cpu0, queued0 = time.monotonic(), tree_cpu_seconds(program.pid), queued_s(
            program.pid)
        patience = Patience(program.pid, limit, started=began)
        while not (gave_up := patience.exhausted()) and time.monotonic() - began < CUT * limit:
            time.sleep(0.1)
        wall = time.monotonic() - began
        return (f'{kind:>4}: {"given up" if gave_up else "still waited on"} at {wall:5.1f} s '
                f'(limit {limit} s; {tree_cpu_seconds(program.pid) - cpu0:.2f} CPU-s, '
                f'{queued_s(program.pid) - queued0:.2f} s on the run queue in all)')
    finally:
        program.kill()
        program.wait()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--burners', type=int, default=3)
    parser.add_argument('--limit', type=float, default=2.0)
    parser.add_argument('--runs', type=int, default=3)
    options = parser.parse_args()
    cpu = min(os.sched_getaffinity(0))
    burners = [subprocess.Popen([sys.executable, '-c', f'import os\nos.sched_setaffinity(0, '
                                 f'{{{cpu}}})\nwhile True: pass'])
               for _ in range(options.burners)]
    try:
        for _ in range(options.runs):
            for kind in ('idle', 'work'):
                print(run(kind, cpu, options.limit), flush=True)
    finally:
        for burner in burners:
            burner.kill()
            burner.wait()


if __name__ == '__main__':
    main()
