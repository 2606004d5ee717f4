#!/usr/bin/env python3
"""How a ``main()`` ends after a shutdown from outside: rclpy's own race, counted.

``python benchmarks/shutdown_race.py [--runs N] [--burners B] [--signal TERM|INT]`` starts the
course's monitor as ``ros2 run`` would, N times with the course's ``main()`` and N times with
the tutorial's (which catches only KeyboardInterrupt), beside B CPU burners; sends the signal
once the program's main thread sits waiting in its spin (:func:`ros2nb.processes.until_waiting`,
as the judge does) and tallies how each run ended: exit code and last line.  The course's
``main()`` should end with 0 every time; when rclpy's signal thread wakes the spin before it
has shut the context down, it ends with ``RCLError: failed to initialize wait set``, which is
why the judge runs such a stop again (``ros2nb.checks.mains.RACE_RUNS``).
"""

from __future__ import annotations

import argparse
import collections
import os
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

from ros2nb import domains
from ros2nb.course import reference_source
from ros2nb.processes import stop_process_group, until_waiting, wait_patiently

#: The course's main() and the tutorial's, as the monitor file ends.
HONEST_MAIN = '''    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C or a shutdown from outside: leave quietly
    finally:
        node.destroy_node()   # the tutorial's subscriber never did this
        rclpy.try_shutdown()  # nor this'''
TUTORIAL_MAIN = '''    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass'''


def endings(program: Path, runs: int, sig: int) -> collections.Counter:
    """How ``runs`` runs of ``program`` ended after ``sig``: (exit code, last line) -> count."""
    env = dict(os.environ, PYTHONUNBUFFERED='1', ROS_DOMAIN_ID=str(domains.domain_id()))
    found: collections.Counter = collections.Counter()
    for _ in range(runs):
        proc = subprocess.Popen([sys.executable, str(program)], env=env, text=True,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                start_new_session=True)
        assert proc.stdout is not None
        proc.stdout.readline()  # its first log line: the node exists and is about to spin
        until_waiting(proc, 10.0)
        os.killpg(proc.pid, sig)
        code = wait_patiently(proc, 20.0)
        if code is None:
            code = stop_process_group(proc)
        lines = [line for line in proc.stdout.read().splitlines() if line.strip()]
        found[code, (lines[-1][:100] if lines and code else '')] += 1
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--runs', type=int, default=30)
    parser.add_argument('--burners', type=int, default=2)
    parser.add_argument('--signal', choices=('TERM', 'INT'), default='TERM')
    args = parser.parse_args()
    sig = getattr(signal, f'SIG{args.signal}')
    source = reference_source('temperature_subscriber.py')
    assert HONEST_MAIN in source
    burners = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])
               for _ in range(args.burners)]
    try:
        with tempfile.TemporaryDirectory() as folder:
            for name, text in (('course', source),
                               ('tutorial', source.replace(HONEST_MAIN, TUTORIAL_MAIN))):
                program = Path(folder) / f'{name}_monitor.py'
                program.write_text(text)
                print(f"{name}'s main(), SIG{args.signal} beside {args.burners} burners:")
                for (code, line), count in endings(program, args.runs, sig).most_common():
                    print(f'  {count:3d} x exit {code} {line}')
    finally:
        for burner in burners:
            burner.kill()
            burner.wait()


if __name__ == '__main__':
    main()
