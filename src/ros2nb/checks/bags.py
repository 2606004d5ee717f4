"""The bags of notebook 10's checks: the check's own bags, and the bags a learner's function wrote.

Part of :mod:`ros2nb.checks` (used by :mod:`.lesson10`, introduced in
``10-record-and-replay.ipynb``).  In a judge every bag the check reads is its own copy, taken
once the learner's code is done, and every bag it gives the learner's code is written where
no subject can reach, then handed over.
"""

from __future__ import annotations

import contextlib
import math
import random
import shutil
from pathlib import Path
from typing import Any, Iterator, Optional

from .. import course
from ..temporary import owned_folder, temporary_folder
from ..terminal import bag

from ..judge_interface import Judge

#: Topics of the recording: the readings, and /rosout where the monitor's statuses go.
TEMPERATURE, ROSOUT = '/' + course.TOPIC, course.ROSOUT_TOPIC
#: Readings in the bags the check writes itself (parts 2 and 3), one second apart.
CHECK_READINGS_COUNT = 60
#: The logger of the /rosout line in the check's own bags: a replay must not play it.
CHECK_LOGGER = 'bag_check'

def check_readings_c(seed: Optional[int] = None) -> list[float]:
    """Readings for a bag of the check's own: a walk through all three statuses, two
    decimals, new each time (``seed``, drawn for the run by :func:`.drawn.chooser`, makes
    them repeat)."""
    chooser = random.Random(seed)
    phase = chooser.uniform(0, 2 * math.pi)
    return [round(22.0 + 6.5 * math.sin(k / 7.0 + phase) + chooser.uniform(-0.2, 0.2), 2)
            for k in range(CHECK_READINGS_COUNT)]


@contextlib.contextmanager
def fresh_path(judge: Optional[Judge], name: str) -> Iterator[Path]:
    """A bag folder that does not exist yet, in a folder of the judge's that the subjects it
    starts meanwhile may write (:meth:`ros2nb.judge.session.Session.fresh_folder`; None: in
    the kernel's temporary folder, named for this process); removed with what the learner's
    function put beside it once the check is done."""
    if judge is not None:
        with judge.fresh_folder('ros2nb-bag-') as given:
            yield given / name
        return
    folder = owned_folder('ros2nb-bag-')
    try:
        yield folder / name
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def read_back(judge: Optional[Judge], path: Path) -> Iterator[Path]:
    """The bag the learner's function wrote at ``path``, to read: in the judge, its own copy
    (links refused), taken once the function is done."""
    if judge is None:
        yield path
        return
    with judge.taken_back(path) as copy:
        yield copy


@contextlib.contextmanager
def check_bag(judge: Optional[Judge], name: str, readings: list[float]) -> Iterator[Path]:
    """The check's own bag of ``readings``, as a folder ``name`` the learner's function may
    read; removed once the check is done.

    The judge writes it in a temporary folder of its own that no subject sees, then hands
    a copy over (:meth:`ros2nb.judge.Session.hand_over`): it never writes to a path in the
    folder subjects may write, where the learner's code could have put a link.
    """
    if judge is None:
        with fresh_path(None, name) as path:
            write_check_bag(path, readings)
            yield path
        return
    with temporary_folder('bag') as private:
        write_check_bag(Path(private) / name, readings)
        files = {f'{name}/{f.name}': f.read_bytes() for f in (Path(private) / name).iterdir()}
    folder = judge.hand_over('ros2nb-bag-', files)
    try:
        yield folder / name
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def write_check_bag(path: Path, readings: list[float]) -> None:
    """A bag of the check's own: ``readings`` on /temperature 1 s apart, and a /rosout line."""
    store = bag.typestore()
    float32 = store.types[course.MESSAGE_TYPE]
    log = store.types['rcl_interfaces/msg/Log']
    stamp = store.types['builtin_interfaces/msg/Time']
    writer = bag.rosbag2.Writer(path, version=bag.METADATA_VERSION,
                                storage_plugin=bag.rosbag2.StoragePlugin.MCAP)
    with writer:
        readings_topic = writer.add_connection(TEMPERATURE, course.MESSAGE_TYPE, typestore=store)
        logs = writer.add_connection(ROSOUT, 'rcl_interfaces/msg/Log', typestore=store)
        line = log(stamp=stamp(sec=0, nanosec=0), level=20, name=CHECK_LOGGER, msg='recorded',
                   file='', function='', line=0)
        writer.write(logs, 500_000_000, store.serialize_cdr(line, 'rcl_interfaces/msg/Log'))
        for k, value in enumerate(readings, start=1):
            writer.write(readings_topic, k * 1_000_000_000,
                         store.serialize_cdr(float32(data=value), course.MESSAGE_TYPE))


def bag_messages(path: Path, topic: str) -> list[tuple[int, Any]]:
    """(stamp ns, decoded message) of one topic of a bag, read by the check itself."""
    store = bag.typestore()
    with bag.rosbag2.Reader(path) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        return [(stamp, store.deserialize_cdr(raw, connection.msgtype))
                for connection, stamp, raw in reader.messages(chosen)]
