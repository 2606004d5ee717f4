#!/usr/bin/env python3
"""What one learner costs a server: a learner's kernel idle and busy, for the sizing table.

``python benchmarks/sizing.py`` starts a real Jupyter kernel as the notebooks do
(``ros2nb.start(sim_time=True)``, the course's sensor and monitor handed over), and reads
from ``/proc`` the memory (PSS: each shared page divided among the processes sharing it,
so the figures add up across learners) and the CPU of the kernel and every process it
started:

- idle: between cells, for ``--idle-s`` seconds (default 30): MiB, and % of one CPU;
- busy: one simulated hour of the two nodes (``ros2nb.spin(3600)``, as notebooks 03 and 10
  run it): peak MiB, CPU seconds and wall seconds;
- a check: notebook 03's ``check_sensor_callback()`` (its judge and subjects are the
  kernel's children): peak MiB, CPU seconds and wall seconds.

docs/classroom-server.md turns these, with ``make bench``'s grading seconds per notebook,
into its sizing table.  Linux only.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from jupyter_client.manager import start_new_kernel

from ros2nb.patience import tree_cpu_seconds, tree_pids
from sampling import Sampling


def pss_mib(pids: list[int]) -> float:
    total = 0
    for pid in pids:
        try:
            for line in Path(f'/proc/{pid}/smaps_rollup').read_text().splitlines():
                if line.startswith('Pss:'):
                    total += int(line.split()[1])
        except OSError:
            continue
    return total / 1024


class Peak(Sampling):
    """The largest PSS of a process tree while the block runs (read every 0.2 s)."""

    def __init__(self, pid: int) -> None:
        super().__init__(0.2)
        self.pid, self.mib = pid, 0.0

    def sample(self) -> None:
        self.mib = max(self.mib, pss_mib(tree_pids(self.pid)))


def run(client, code: str) -> None:
    reply = client.execute_interactive(code, timeout=600, output_hook=lambda msg: None)
    if reply['content']['status'] != 'ok':
        raise SystemExit(f'the cell failed: {code!r}: {reply["content"].get("evalue")}')


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--idle-s', type=float, default=30.0)
    args = parser.parse_args()
    workspace = Path(tempfile.mkdtemp()) / 'ws'
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
    env['ROS2NB_WORKSPACE'] = str(workspace)
    manager, client = start_new_kernel(kernel_name='python3', env=env)
    try:
        pid = manager.provisioner.process.pid
        run(client, 'import ros2nb\n_ = ros2nb.start(sim_time=True)\n'
                    'ros2nb.create_workspace(allow_outside_course=True)\nros2nb.course.catch_up(5)\n'
                    'pub = ros2nb.import_file(ros2nb.course.PUBLISHER_FILE)\n'
                    'sub = ros2nb.import_file(ros2nb.course.SUBSCRIBER_FILE)\n'
                    'ros2nb.add(pub.TemperatureSensor()); ros2nb.add(sub.TemperatureMonitor())')
        time.sleep(5)
        before, started = tree_cpu_seconds(pid), time.monotonic()
        time.sleep(args.idle_s)
        idle_pct = 100 * (tree_cpu_seconds(pid) - before) / (time.monotonic() - started)
        print(f'idle kernel (two nodes, between cells): {pss_mib(tree_pids(pid)):.0f} MiB PSS, '
              f'{idle_pct:.1f} % of one CPU')
        for label, code in (('busy kernel: one simulated hour of both nodes',
                             '_ = ros2nb.spin(3600, show_logs=False)'),
                            ("a check from the kernel (notebook 03's check_sensor_callback)",
                             'ros2nb.stop()\nros2nb.checks.check_sensor_callback()')):
            before, started = tree_cpu_seconds(pid), time.monotonic()
            with Peak(pid) as peak:
                run(client, code)
            used = tree_cpu_seconds(pid) - before
            print(f'{label}: peak {peak.mib:.0f} MiB PSS, {used:.1f} CPU-s '
                  f'(children that ended are counted once reaped), '
                  f'{time.monotonic() - started:.1f} s wall')
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


if __name__ == '__main__':
    main()
