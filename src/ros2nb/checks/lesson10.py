"""Checks of notebook 10, record and replay: the bag on disk and what a replay delivers.

Part of :mod:`ros2nb.checks`.  The learner writes three functions.  In the kernel they are
called there; the judge calls them from the learner's answer cells in a subject (ROS up on
simulated time there too).  The verdict never comes from what they report: the check reads
the bag folder itself with ``rosbags`` (metadata, types, counts, the statuses in the
monitor's log messages), watches what a replay delivers with a ROS subscription of its own
(the judge's node, or in the kernel a subscription of the check's), and compares what the
reading function returns with a bag the check wrote itself.
"""

from __future__ import annotations

import contextlib
import io
import math
import re
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator, Optional

from rcl_interfaces.msg import Log

from .. import course
from ..errors import CheckFailed
from ..runtime import current_runtime
from ..terminal import bag
from .answers import answer_results, decoded
from .base import ARRIVAL_TIMEOUT_S, AnswerRef, call_learner, current_judge, learner_error, passed
from .dispatch import in_judge

#: Topics of the recording: the readings, and /rosout where the monitor's statuses go.
TEMPERATURE, ROSOUT = '/' + course.TOPIC, course.ROSOUT_TOPIC
#: The monitor's log line, as notebook 04 writes it.
STATUS_LINE = re.compile(r'Temperature: (-?[\d.]+)C - Status: (\w+)')
#: Readings of the bags the check writes itself (parts b and c): a walk through all statuses.
CHECK_READINGS = [round(22.0 + 6.5 * math.sin(k / 7.0), 2) for k in range(60)]
#: Rate the check replays at (simulated s per wall s): fast, and below what play reaches.
CHECK_RATE = 100.0


@contextlib.contextmanager
def _fresh_path(name: str) -> Iterator[Path]:
    """A bag folder that does not exist yet, in the judge's scratch folder or a temporary
    one; removed with what the learner's function put beside it once the check is done."""
    parent = str(current_judge().scratch) if in_judge() else None
    folder = Path(tempfile.mkdtemp(prefix='ros2nb-bag-', dir=parent))
    try:
        yield folder / name
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def _check_bag(name: str) -> Iterator[Path]:
    """The check's own bag of :data:`CHECK_READINGS`, as a folder ``name`` the learner's
    function may read; removed once the check is done.

    The judge writes it in a temporary folder of its own that no subject sees, then hands
    a copy over (:meth:`ros2nb.judge.Session.hand_over`): it never writes to a path in the
    folder subjects may write, where the learner's code could have put a link.
    """
    if not in_judge():
        with _fresh_path(name) as path:
            write_check_bag(path, CHECK_READINGS)
            yield path
        return
    with tempfile.TemporaryDirectory(prefix='ros2nb-bag-') as private:
        write_check_bag(Path(private) / name, CHECK_READINGS)
        files = {f'{name}/{f.name}': f.read_bytes() for f in (Path(private) / name).iterdir()}
    folder = current_judge().hand_over('ros2nb-bag-', files)
    try:
        yield folder / name
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _call(function: Any, label: str, *args: Any) -> Any:
    """Call the learner's function (in the kernel, or from source in a subject)."""
    if isinstance(function, AnswerRef):
        # The monitor the learner stops at the end keeps its /rosout lines for the judge.
        current_judge().answer_subject(function).request('keep_stopped_nodes')
        encoded = [{'path': str(a)} if isinstance(a, Path) else a for a in args]
        output = answer_results(function, [encoded])[0]
        if 'error' in output:
            raise learner_error(label, output['error'])
        return _plain(output['result'])
    with contextlib.redirect_stdout(io.StringIO()):  # the verdict is the check's line alone
        return call_learner(function, *args)


def _plain(result: dict) -> Any:
    """A subject's encoded value as plain Python (lists of lists and numbers kept)."""
    if result['type'] in ('list', 'tuple'):
        return [_plain(item) for item in result['value']]
    return decoded({'result': result}, '')


def _messages(path: Path, topic: str) -> list[tuple[int, Any]]:
    """(stamp ns, decoded message) of one topic of a bag, read by the check itself."""
    store = bag.typestore()
    with bag.rosbag2.Reader(path) as reader:
        chosen = [c for c in reader.connections if c.topic == topic]
        return [(stamp, store.deserialize_cdr(raw, connection.msgtype))
                for connection, stamp, raw in reader.messages(chosen)]


def _statuses(logs: list[tuple[str, str]]) -> list[tuple[float, str]]:
    """(reading, status) of every status line the monitor logged."""
    found = []
    for name, text in logs:
        match = STATUS_LINE.fullmatch(text) if name == course.MONITOR_NODE else None
        if match:
            found.append((float(match.group(1)), match.group(2)))
    return found


def _bag_verdict(path: Path, label: str) -> dict[str, int]:
    """The bag's own facts, or the one line saying what is wrong with it."""
    if not path.is_dir():
        raise CheckFailed(f'{label} wrote no bag at the path it was given: pass bag_path to '
                          'bag_record as its output.')
    info = bag.metadata(path)
    if info.get('storage_identifier') != bag.STORAGE_ID:
        raise CheckFailed(f'The bag is stored as {info.get("storage_identifier")}, not mcap: '
                          'record it with ros2nb.bag_record.')
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    for topic, why in ((TEMPERATURE, 'the readings'), (ROSOUT, "the monitor's statuses")):
        if topic not in topics:
            raise CheckFailed(f'The bag holds {", ".join(topics) or "no topic"} but not {topic} '
                              f'({why}): record both {TEMPERATURE} and {ROSOUT}.')
    kind = topics[TEMPERATURE]['topic_metadata']['type']
    if kind != course.MESSAGE_TYPE:
        raise CheckFailed(f'{TEMPERATURE} is recorded as {kind}, expected {course.MESSAGE_TYPE}.')
    return {t: v['message_count'] for t, v in topics.items()}


def _recording(record_hour: Any) -> str:
    with _fresh_path('hour') as path:
        return _recording_in(path, record_hour)


def _recording_in(path: Path, record_hour: Any) -> str:
    label = f'{record_hour.__name__}(bag_path)'
    _call(record_hour, label, path)
    if not in_judge():
        return _recording_verdict(path, label)
    if not path.is_dir():
        _bag_verdict(path, label)  # the line for "no bag at all"
    # The bag lies where subjects may write: the judge reads its own copy, links refused.
    with current_judge().taken_back(path) as copy:
        return _recording_verdict(copy, label)


def _recording_verdict(path: Path, label: str) -> str:
    """What the bag at ``path`` holds, against an hour of the sensor and the monitor."""
    counts = _bag_verdict(path, label)
    readings = [float(m.data) for _s, m in _messages(path, TEMPERATURE)]
    hour = round(course.RECORD_S / course.PUBLISH_PERIOD_S)
    if counts[TEMPERATURE] != hour or len(readings) != hour:
        raise CheckFailed(f'The bag holds {counts[TEMPERATURE]} readings on {TEMPERATURE}; one '
                          f'simulated hour of the sensor is {hour}: add both nodes, then record '
                          f'while spinning {course.RECORD_S:g} s.')
    statuses = _statuses([(m.name, m.msg) for _s, m in _messages(path, ROSOUT)])
    if len(statuses) != hour:
        raise CheckFailed(f'The bag holds {len(statuses)} status lines of '
                          f'{course.MONITOR_NODE} on {ROSOUT}, expected {hour}, one per '
                          'reading: add your monitor before recording, and keep it running.')
    return (f'the bag is MCAP with metadata.yaml: {hour} readings ({course.MESSAGE_TYPE}) and '
            f'{hour} statuses of {course.MONITOR_NODE} on {ROSOUT}.')


def check_recording(record_hour: Any) -> None:
    """Check part 1 of notebook 10: one simulated hour recorded into an MCAP bag.

    Calls your function with a folder that does not exist yet, then reads the bag there
    itself: MCAP storage with a ``metadata.yaml``, 3600 ``std_msgs/msg/Float32`` readings on
    ``/temperature`` and 3600 status lines of ``temperature_monitor`` on ``/rosout``.

    Introduced in ``10-record-and-replay.ipynb``.

    :param record_hour: your function (no parentheses).
    :raises CheckFailed: naming what the bag lacks.
    """
    passed(_recording(record_hour))


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
        line = log(stamp=stamp(sec=0, nanosec=0), level=20, name='bag_check', msg='recorded',
                   file='', function='', line=0)
        writer.write(logs, 500_000_000, store.serialize_cdr(line, 'rcl_interfaces/msg/Log'))
        for k, value in enumerate(readings, start=1):
            writer.write(readings_topic, k * 1_000_000_000,
                         store.serialize_cdr(float32(data=value), course.MESSAGE_TYPE))


class _Watch:
    """What the check's own ROS node hears during a replay: the monitor's log lines."""

    def __init__(self) -> None:
        if in_judge():
            judge = current_judge()
            # Monitors of earlier checks (kept after the learner stopped them, with their
            # /rosout history) leave first: only this replay's monitor can speak below.
            judge.drop_all()
            self.observer = judge.observer
            self.logs, self._close = self.observer.listen_logs()
            return
        self.observer, self.logs = None, []
        self.rt = current_runtime()
        with self.rt.exclusive():
            self.subscription = self.rt.node.create_subscription(
                Log, ROSOUT, lambda m: self.logs.append((m.name, m.msg)), bag.KEEP_ALL)

    def heard(self, expected: int, made: Optional[int] = None) -> list[tuple[str, str]]:
        """Log lines heard since the watch began: waiting for ``expected`` statuses, or for
        the ``made`` lines the monitor made in the subject (so a monitor that logged nothing
        is known at once, not after ``ARRIVAL_TIMEOUT_S``)."""
        if self.observer is not None:
            # A subscription of its own, transient local: the monitor's lines reach it even
            # when it matched the monitor only after the replay (the monitor is kept).
            def arrived() -> bool:
                logs = list(self.logs)
                return (len(_statuses(logs)) >= expected or made is not None
                        and sum(name == course.MONITOR_NODE for name, _ in logs) >= made)

            self.observer.wait_until(arrived, ARRIVAL_TIMEOUT_S)
            self._close()
            return list(self.logs)
        with self.rt.exclusive():
            self.rt.drain()
            self.rt.node.destroy_subscription(self.subscription)
        return self.logs


def _replay(replay: Any) -> str:
    with _check_bag('sixty') as path:
        return _replay_in(path, replay)


def _replay_in(path: Path, replay: Any) -> str:
    watch = _Watch()
    _call(replay, f'{replay.__name__}(bag_path, rate)', path, CHECK_RATE)
    made = None  # how many lines the monitor made, when the subject can vouch for them all
    if isinstance(replay, AnswerRef):
        made = current_judge().answer_subject(replay).request(
            'lines_logged', logger=course.MONITOR_NODE)['lines']
    logs = watch.heard(len(CHECK_READINGS), made)
    sent = len(CHECK_READINGS)
    statuses = _statuses(logs)
    expected = [(round(r, 2), course.monitor_status(r)) for r in CHECK_READINGS]
    if not statuses:
        raise CheckFailed(f'{course.MONITOR_NODE} logged no status during the replay: add your '
                          'monitor before bag_play, so it hears the replayed readings.')
    got = [(round(r, 2), s) for r, s in statuses]
    if got != expected:
        raise CheckFailed(f'{course.MONITOR_NODE} logged {len(got)} statuses for the {sent} '
                          f'replayed readings, expected {sent}, one each: add the monitor once, '
                          'before bag_play, and stop it after.')
    return (f'{sent} replayed readings reached {course.MONITOR_NODE}, which logged the '
            f'{sent} statuses the bag\'s readings call for.')


def check_replay(replay: Any) -> None:
    """Check part 2 of notebook 10: a bag replayed into the monitor gives its statuses again.

    Writes a bag of 60 readings of its own, calls ``replay(bag_path, rate)`` and listens
    itself: every reading must arrive on ``/temperature`` and your monitor must log the
    status each one calls for, once.

    Introduced in ``10-record-and-replay.ipynb``.

    :param replay: your function (no parentheses).
    :raises CheckFailed: naming what the replay delivered instead.
    """
    passed(_replay(replay))


def _readings(read_temperatures: Any) -> str:
    with _check_bag('sixty') as path:
        return _readings_in(path, read_temperatures)


def _readings_in(path: Path, read_temperatures: Any) -> str:
    got = _call(read_temperatures, f'{read_temperatures.__name__}(bag_path)', path)
    name = f'{getattr(read_temperatures, "__name__", "your function")}()'
    if not (isinstance(got, (list, tuple)) and len(got) == 2
            and all(isinstance(side, (list, tuple)) for side in got)):
        raise CheckFailed(f'{name} returned {type(got).__name__}; return two lists: '
                          '(times_s, temperatures_c).')
    times, values = (list(side) for side in got)
    sent = len(CHECK_READINGS)
    if len(values) != sent or len(times) != sent:
        raise CheckFailed(f'{name} returned {len(times)} times and {len(values)} readings; the '
                          f'bag holds {sent} on {TEMPERATURE} (and one message on {ROSOUT}: '
                          f'keep only {TEMPERATURE}).')
    want_times = [float(k) for k in range(sent)]
    if not all(isinstance(t, (int, float)) and abs(t - w) < 1e-6
               for t, w in zip(times, want_times)):
        raise CheckFailed(f'{name} returned times {times[:3]}...; expected seconds since the '
                          f'first reading, [0.0, 1.0, 2.0, ...]: (stamp - first stamp) / 1e9.')
    if not all(isinstance(v, (int, float)) and abs(v - w) < 1e-4
               for v, w in zip(values, CHECK_READINGS)):
        raise CheckFailed(f'{name} returned readings {values[:3]}...; expected the messages\' '
                          f'data, {CHECK_READINGS[:3]}...: deserialize each message.')
    return f'{name} returns the {sent} readings of the bag, with their times from 0 s.'


def check_readings(read_temperatures: Callable[..., Any]) -> None:
    """Check part 3 of notebook 10: a bag's readings read back with rosbags.

    Writes a bag of 60 readings one second apart (and one ``/rosout`` line), calls your
    function and compares: times in seconds since the first reading, and every value.

    Introduced in ``10-record-and-replay.ipynb``.

    :param read_temperatures: your function (no parentheses).
    :raises CheckFailed: naming what your function returned instead.
    """
    passed(_readings(read_temperatures))
