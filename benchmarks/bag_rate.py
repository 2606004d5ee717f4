"""Notebook 10's figures: one simulated hour recorded into a bag, its size, and replay speed.

Run: ``.venv/bin/python benchmarks/bag_rate.py [REPEATS]``.  The course's reference sensor
and monitor (seed 10, as the notebook) run one simulated hour while ``ros2nb.bag_record``
keeps ``/temperature`` and ``/rosout``; then ``ros2nb.bag_play`` replays the readings into a
new monitor as fast as it can (rate 1e9), and at rate 600 (the notebook's).  Prints the bag's
size, the wall seconds of each step, simulated seconds and messages per wall second.
"""

from __future__ import annotations

import contextlib
import io
import random
import sys
import time
from pathlib import Path

import ros2nb
from ros2nb.terminal.files import import_file
from ros2nb.temporary import owned_folder

REFERENCE = Path(ros2nb.__file__).parent / 'reference'
HOUR_S = 3600


def _quiet(call, *args, **kwargs):
    with contextlib.redirect_stdout(io.StringIO()):
        return call(*args, **kwargs)


def main(repeats: int) -> None:
    _quiet(ros2nb.start, sim_time=True)
    pub = import_file(REFERENCE / 'temperature_publisher.py')
    sub = import_file(REFERENCE / 'temperature_subscriber.py')
    folder = owned_folder('ros2nb-bench-bag-')
    bag = folder / 'hour'
    random.seed(10)
    _quiet(ros2nb.add, pub.TemperatureSensor())
    _quiet(ros2nb.add, sub.TemperatureMonitor())
    started = time.monotonic()
    with _quiet(ros2nb.bag_record, bag, '/temperature', '/rosout') as recording:
        _quiet(ros2nb.spin, HOUR_S, show_logs=False)
        _quiet(recording.stop)
    recorded = time.monotonic() - started
    _quiet(ros2nb.stop)
    size = sum(f.stat().st_size for f in bag.iterdir())
    counts = _quiet(ros2nb.bag_info, bag)
    print(f'record: {HOUR_S} simulated s in {recorded:.1f} wall s; bag {size / 2**20:.2f} MiB '
          f'({size} bytes): {counts}')
    for rate in (1e9, 600):
        for _ in range(repeats):
            _quiet(ros2nb.add, sub.TemperatureMonitor())
            started = time.monotonic()
            played = _quiet(ros2nb.bag_play, bag, rate=rate, topics=['/temperature'])
            wall = time.monotonic() - started
            _quiet(ros2nb.stop)
            n = played['/temperature']
            print(f'play rate {rate:g}: {n} messages, {HOUR_S - 1} simulated s in {wall:.2f} wall '
                  f's: {(HOUR_S - 1) / wall:.0f} simulated s/s, {n / wall:.0f} messages/s')
    ros2nb.shutdown()


if __name__ == '__main__':
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 3)
