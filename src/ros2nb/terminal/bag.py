"""``ros2 bag record/info/play``: topics kept in an MCAP bag that real ROS 2 tools open.

Introduced in ``10-record-and-replay.ipynb``.  A bag is a rosbag2 folder: ``metadata.yaml``
(what rosbag2 reads first: topics, types, counts, times) and one ``.mcap`` file of the
messages, serialized as they travelled (CDR).  The folder is written and read by the
``rosbags`` library (Jazzy's message definitions, rosbag2's metadata version 9), so
``ros2 bag info``, Foxglove and ``mcap`` open it too.

- :func:`bag_record` subscribes with the kernel's hidden node (``raw=True``: the bytes as
  they arrived, nothing decoded) and stamps each message with the kernel's clock, so on
  simulated time the same seed gives the same bag.
- :func:`bag_play` publishes a bag's messages again, in order, on simulated time: before
  each message the kernel's clock (``/clock``) moves on by the gap the bag recorded, and the
  wall clock waits so that ``rate`` simulated seconds pass per wall second at most.  Its
  publishers keep every message (KEEP_ALL), and the nodes run after each one, so nothing is
  lost however high the rate.
- :func:`bag_info` prints what ``ros2 bag info`` prints.

With a real ``ros2`` on PATH (a ROS 2 install) they run ``ros2 bag`` instead, on the kernel's
domain.  Needs Python 3.11 or newer (``rosbags`` needs ``apsw``).
"""

from __future__ import annotations

import datetime
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Any, Final, Optional, Sequence

import yaml
from rclpy.duration import Duration
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

if sys.version_info >= (3, 11):  # rosbags' apsw has no wheel for 3.10
    from rosbags import rosbag2, typesys
else:  # pragma: no cover - Python 3.10: every verb says it needs 3.11
    rosbag2 = typesys = None

from .. import working
from ..errors import Ros2nbError, UsageError
from ..runtime import QUIET_SUBSCRIPTION, current_runtime
from .echo import message_type
from .run import node_process_env
from .topic import resolve

#: The storage every bag of the course uses (rosbag2's default since Iron).
STORAGE_ID = 'mcap'
#: Topics whose type ROS itself fixes, known before any node publishes them: every node logs
#: on /rosout, so a recording of it may start before the node that will log (notebook 10
#: records a replay's statuses before replay() adds the monitor, as ros2 bag record would).
ROS_TOPIC_TYPES: Final = {'/rosout': 'rcl_interfaces/msg/Log'}
#: rosbag2's metadata version written (Jazzy's rosbag2 writes and reads 9).
METADATA_VERSION: Final = 9
#: What replay and recording keep: every message (a burst never overflows a queue).
#: Wall-clock seconds a player waits for its subscriptions to match, or for their acks.
MATCH_WAIT_S = 2.0
KEEP_ALL = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
#: /rosout is played as its nodes offer it (transient local, as ``ros2 bag play`` replays
#: each topic with its recorded profile): whoever listens to /rosout hears the old lines.
LATCHED = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)


def needs_python() -> None:
    """:raises Ros2nbError: on Python 3.10, in one line (rosbags needs apsw, 3.11 or newer)."""
    if rosbag2 is None:
        raise Ros2nbError('Bags need Python 3.11 or newer (rosbags needs apsw); this kernel runs '
                          f'Python {sys.version_info[0]}.{sys.version_info[1]}.')


def typestore() -> Any:
    """rosbags' Jazzy typestore: message definitions and their type hashes as Jazzy's."""
    needs_python()
    return typesys.get_typestore(typesys.Stores.ROS2_JAZZY)


def _real_ros2() -> Optional[str]:
    return shutil.which('ros2')


def _bag_path(name: Any) -> Path:
    if not isinstance(name, (str, os.PathLike)) or not str(name).strip():
        raise UsageError("Name the bag's folder, e.g. bag_record('hour', '/temperature').")
    return Path(name).expanduser()


class Recording:
    """A bag being recorded by :func:`bag_record`; :meth:`stop` closes it (also ``with``)."""

    def __init__(self, path: Path, topics: dict[str, str]) -> None:
        self.path = path
        self.counts = dict.fromkeys(topics, 0)
        self._rt = current_runtime()
        self._process: Optional[subprocess.Popen[bytes]] = None
        self._subscriptions: list[Any] = []
        self._writer: Any = None
        if ros2 := _real_ros2():
            self._process = subprocess.Popen(
                [ros2, 'bag', 'record', '-o', str(path), '-s', STORAGE_ID,
                 '--use-sim-time', *topics], env=node_process_env(os.environ))
            return
        store = typestore()
        self._writer = rosbag2.Writer(path, version=METADATA_VERSION,
                                      storage_plugin=rosbag2.StoragePlugin.MCAP)
        self._writer.open()
        with self._rt.exclusive():
            for topic, type_name in topics.items():
                connection = self._writer.add_connection(topic, type_name, typestore=store)
                self._subscriptions.append(self._rt.node.create_subscription(
                    message_type(type_name), topic, self._keeper(topic, connection), KEEP_ALL,
                    raw=True, event_callbacks=QUIET_SUBSCRIPTION))

    def _keeper(self, topic: str, connection: Any) -> Any:
        def keep(data: bytes) -> None:
            stamp = self._rt.sim_now_ns if self._rt.sim_time else time.time_ns()
            self._writer.write(connection, stamp, data)
            self.counts[topic] += 1
        return keep

    def stop(self) -> dict[str, int]:
        """Stop recording and close the bag (``Ctrl+C`` for ``ros2 bag record``); say what it holds.

        Safe to call twice.

        :return: messages recorded per topic.
        """
        if self._process is not None:
            self._process.send_signal(signal.SIGINT)
            self._process.wait()
            self._process = None
        if self._writer is not None:
            with self._rt.exclusive():
                self._rt.drain()
                for subscription in self._subscriptions:
                    self._rt.node.destroy_subscription(subscription)
            self._writer.close()
            self._writer = None
            total = sum(self.counts.values())
            print(f'Recorded {total} messages into {self.path.name}/: '
                  + ', '.join(f'{topic} {n}' for topic, n in self.counts.items()) + '.')
        return dict(self.counts)

    def __enter__(self) -> 'Recording':
        return self

    def __exit__(self, *exc: Any) -> None:
        self.stop()


def bag_record(output: Any, *topics: str) -> Recording:
    """Record topics into a new MCAP bag, like ``ros2 bag record -o OUTPUT TOPIC...``.

    Recording runs while the nodes run (:func:`ros2nb.spin`) until :meth:`Recording.stop`
    (or the end of a ``with`` block).  Each message is stamped with the kernel's clock
    (simulated time in a simulated-time kernel).

    Introduced in ``10-record-and-replay.ipynb``.

    :param output: the bag's folder; it must not exist yet.
    :param topics: topic names, e.g. ``'/temperature'``, ``'/rosout'``; each must have a
        publisher already (its type is taken from the graph), but ``/rosout``, whose type
        is ROS's own.
    :return: the running recording.
    :raises UsageError: for no topics, a topic that is not a name, a folder that exists,
        or a topic nobody publishes (yet: a subscription alone does not count).
    """
    path = _bag_path(output)
    if not topics:
        raise UsageError("Name the topics to record, e.g. bag_record('hour', '/temperature').")
    wrong = [t for t in topics if not isinstance(t, str) or not t.strip()]
    if wrong and isinstance(wrong[0], os.PathLike):  # the folder among the topics
        raise UsageError("bag_record takes the bag's folder first, then the topics in quotes: "
                         "bag_record(bag_path, '/temperature', '/rosout').")
    if wrong:
        raise UsageError(f'Topics are names in quotes, e.g. \'/temperature\' (got {wrong[0]!r}).')
    if path.exists():
        raise UsageError(f"Output folder '{path}' already exists: choose another name, or "
                         'delete the old bag first.')
    types = {}
    graph = current_runtime().node
    for topic in topics:
        name = resolve(topic)
        # its publishers' type only: a subscription (a check listening) publishes nothing
        published = sorted({info.topic_type for info in graph.get_publishers_info_by_topic(name)})
        if not published and name in ROS_TOPIC_TYPES:
            published = [ROS_TOPIC_TYPES[name]]
        if not published:
            raise UsageError(f'{name} has no publisher in the ROS graph yet: add the node that '
                             'publishes it before recording (topic_list() shows the topics).')
        types[name] = published[0]
    return Recording(path, types)


def _reader(path: Path) -> Any:
    metadata(path)
    needs_python()
    return rosbag2.Reader(path)


def metadata(name: Any) -> dict[str, Any]:
    """A bag's ``metadata.yaml`` as rosbag2 wrote it (``rosbag2_bagfile_information``).

    :raises Ros2nbError: when the folder has no metadata.yaml.
    """
    path = _bag_path(name)
    if not (path / 'metadata.yaml').is_file():
        raise Ros2nbError(f"'{path}' is not a bag: a bag is a folder with a metadata.yaml "
                          '(bag_record writes one).')
    return yaml.safe_load((path / 'metadata.yaml').read_text())['rosbag2_bagfile_information']


def _stamp(ns: int) -> str:
    when = datetime.datetime.fromtimestamp(ns / 1e9, tz=datetime.timezone.utc)
    return f'{when:%b %d %Y %H:%M:%S}.{ns % 1_000_000_000:09d} ({ns / 1e9:.9f})'


def _size(path: Path) -> str:
    size = float(sum(f.stat().st_size for f in path.iterdir() if f.is_file()))
    for unit in ('B', 'KiB', 'MiB', 'GiB'):
        if size < 1024 or unit == 'GiB':
            return f'{size:.1f} {unit}'
        size /= 1024
    return ''


def bag_info(name: Any) -> dict[str, int]:
    """Print what a bag holds, like ``ros2 bag info NAME``.

    Introduced in ``10-record-and-replay.ipynb``.

    :return: messages per topic.
    :raises Ros2nbError: when the folder is no bag.
    """
    path = _bag_path(name)
    if ros2 := _real_ros2():
        subprocess.run([ros2, 'bag', 'info', str(path)], check=False,
                       env=node_process_env(os.environ))
    with _reader(path) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        files = sorted(f.name for f in path.iterdir() if f.suffix == f'.{STORAGE_ID}')
        if ros2:
            return counts
        print(f'Files:             {files[0] if files else ""}')
        for more in files[1:]:
            print(f'                   {more}')
        print(f'Bag size:          {_size(path)}')
        print(f'Storage id:        {metadata(path)["storage_identifier"]}')
        print(f'ROS Distro:        {reader.ros_distro or "unknown"}')
        info = metadata(path)
        start, duration = (info['starting_time']['nanoseconds_since_epoch'],
                           info['duration']['nanoseconds'])
        print(f'Duration:          {duration / 1e9:.9f}s')
        print(f'Start:             {_stamp(start)}')
        print(f'End:               {_stamp(start + duration)}')
        print(f'Messages:          {reader.message_count}')
        for index, c in enumerate(reader.connections):
            label = 'Topic information: ' if index == 0 else ' ' * 19
            print(f'{label}Topic: {c.topic} | Type: {c.msgtype} | Count: {c.msgcount} | '
                  f'Serialization Format: {c.ext.serialization_format}')
    return counts


def _check_rate(rate: Any) -> float:
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not rate > 0:
        raise UsageError(f'rate must be a number above 0, simulated seconds per wall second '
                         f'(1.0: as recorded; got {rate!r}).')
    return float(rate)


def bag_play(name: Any, *, rate: float = 1.0, topics: Optional[Sequence[str]] = None,
             show_logs: bool = False) -> dict[str, int]:
    """Publish a bag's messages again on simulated time, like ``ros2 bag play NAME --clock``.

    Before each message the kernel's simulated clock moves on by the gap recorded in the
    bag (``/clock`` is published, the nodes' timers fire); then the message is published
    (KEEP_ALL, reliable) and the kernel's nodes run until idle, so every one arrives.  At
    most ``rate`` simulated seconds pass per wall-clock second.  (Run by a check's judge,
    the clock is the judge's, and it sets the pace.)

    Introduced in ``10-record-and-replay.ipynb``.

    :param rate: simulated seconds per wall second (``--rate``); 1.0 plays as recorded.
    :param topics: only these topics (``--topics``); ``None`` plays all.
    :param show_logs: print the nodes' log lines (an hour of them is long).
    :return: messages published per topic.
    :raises UsageError: for a rate that is not above 0, or a topic the bag does not hold.
    :raises Ros2nbError: when the folder is no bag, or ROS is not up in a simulated-time kernel.
    """
    path, rate = _bag_path(name), _check_rate(rate)
    rt = current_runtime()
    if not rt.sim_time:
        raise Ros2nbError('bag_play replays on simulated time: start ROS with '
                          'ros2nb.start(sim_time=True).')
    if ros2 := _real_ros2():
        args = ['--topics', *topics] if topics else []
        subprocess.run([ros2, 'bag', 'play', str(path), '--clock', '--rate', str(rate),
                        *args], check=False, env=node_process_env(os.environ))
        return {}
    with _reader(path) as reader, working.shown(f'playing {path.name}'):
        return _play(rt, reader, path, rate, topics, show_logs)


def _wait_matched(node: Any, publishers: Any) -> None:
    """Wait (at most :data:`MATCH_WAIT_S` of the wall clock) until each new publisher has
    matched every subscription the graph shows on its topic, so that the bag's first
    messages reach the monitor started for them (a subscription whose QoS never matches
    costs that wait once)."""
    deadline = time.monotonic() + MATCH_WAIT_S
    for publisher in publishers:
        while time.monotonic() < deadline and \
                publisher.get_subscription_count() < node.count_subscribers(publisher.topic_name):
            time.sleep(0.005)


def _play(rt: Any, reader: Any, path: Path, rate: float, topics: Optional[Sequence[str]],
          show_logs: bool) -> dict[str, int]:
    held = {c.topic: c for c in reader.connections}
    wanted = [resolve(t) for t in topics] if topics else list(held)
    for topic in wanted:
        if topic not in held:
            raise UsageError(f'{path.name} holds no {topic}; it holds {", ".join(held)}.')
    counts = dict.fromkeys(wanted, 0)
    with rt.exclusive():
        publishers = {t: rt.node.create_publisher(message_type(held[t].msgtype), t,
                                                  LATCHED if t == '/rosout' else KEEP_ALL)
                      for t in wanted}
    _wait_matched(rt.node, publishers.values())
    wall0, sim0, first = time.monotonic(), rt.sim_now_ns, None
    try:
        with rt.clock(True):
            for connection, stamp, data in reader.messages([held[t] for t in wanted]):
                first = stamp if first is None else first
                gap_ns = sim0 + stamp - first - rt.sim_now_ns
                if gap_ns > 0:
                    rt.advance_sim_time(gap_ns / 1e9)
                ahead = (stamp - first) / 1e9 / rate - (time.monotonic() - wall0)
                if ahead > 0 and rt.judge_time is None:  # a judge's clock keeps its own pace
                    time.sleep(ahead)
                with rt.exclusive():
                    publishers[connection.topic].publish(data)
                    rt.drain()
                counts[connection.topic] += 1
                working.say(f'{sum(counts.values())} messages played, '
                            f'{(rt.sim_now_ns - sim0) / 1e9:.0f} simulated s')
    finally:
        for publisher in publishers.values():  # the last messages reach every subscription
            publisher.wait_for_all_acked(Duration(seconds=MATCH_WAIT_S))
        with rt.exclusive():
            for publisher in publishers.values():
                rt.node.destroy_publisher(publisher)
    rt.print_pending(show_logs=show_logs)
    print(f'Played {sum(counts.values())} messages from {path.name}/ over '
          f'{(rt.sim_now_ns - sim0) / 1e9:g} simulated s: '
          + ', '.join(f'{t} {n}' for t, n in counts.items()) + '.')
    return counts
