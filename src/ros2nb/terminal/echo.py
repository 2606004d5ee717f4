"""``ros2 topic echo/hz`` and a tiny ``ros2 bag record``, on the kernel's own clock.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (``record`` in notebook 03).  They
subscribe with the kernel's hidden node, so on simulated time they run on the same
simulated clock as the nodes they listen to, and the same seed gives the same output.
"""

from __future__ import annotations

import importlib
import math
import statistics
import time
from typing import Any, Callable, Optional, Protocol

from rclpy.qos import DurabilityPolicy, QoSPresetProfiles, QoSProfile, ReliabilityPolicy

from .. import working
from ..errors import Ros2nbError, UsageError
from ..runtime import QUIET_SUBSCRIPTION, current_runtime
from .topic import did_you_mean, graph_topics, resolve

#: Longest time echo/hz wait for messages by default (seconds, simulated or wall-clock).
DEFAULT_WAIT_S = 10.0


class MessageClass(Protocol):
    """A message class rosidl generated (``std_msgs.msg.Float32``), as the terminal verbs use it."""

    __name__: str

    def get_fields_and_field_types(self) -> dict[str, str]: ...


def message_type(type_name: str) -> MessageClass:
    """Import a message class from its ROS name, e.g. ``'std_msgs/msg/Float32'``.

    :raises Ros2nbError: if the name is malformed or the package is not installed.
    """
    parts = type_name.split('/')
    if len(parts) != 3:
        raise Ros2nbError(f"The passed message type '{type_name}' is invalid; "
                          "use the form package/msg/Type, e.g. std_msgs/msg/Float32.")
    try:
        return getattr(importlib.import_module(f'{parts[0]}.{parts[1]}'), parts[2])
    except (ImportError, AttributeError):
        raise Ros2nbError(f"The message type '{type_name}' is invalid or not installed "
                          f"(pip package ros-jazzy-{parts[0].replace('_', '-')}).") from None


def to_yaml(msg: Any, indent: int = 0) -> str:
    """Render a message the way ``ros2 topic echo`` does (YAML, one field per line)."""
    pad = '  ' * indent
    lines = []
    for field in msg.get_fields_and_field_types():
        value = getattr(msg, field)
        if hasattr(value, 'get_fields_and_field_types'):
            lines.append(f'{pad}{field}:')
            lines.append(to_yaml(value, indent + 1))
        elif isinstance(value, str):
            lines.append(f"{pad}{field}: '{value}'")
        elif isinstance(value, bool):
            lines.append(f'{pad}{field}: {str(value).lower()}')
        elif isinstance(value, (list, tuple)) or hasattr(value, 'tolist'):
            items = list(value)
            lines.append(f'{pad}{field}:' + ('' if items else ' []'))
            lines.extend(f'{pad}- {item!r}' for item in items)
        else:
            lines.append(f'{pad}{field}: {value!r}')
    return '\n'.join(lines)


def _echo_qos(topic: str) -> QoSProfile:
    """The CLI's choice: sensor-data QoS, upgraded when every publisher offers more."""
    qos = QoSPresetProfiles.SENSOR_DATA.value
    qos = QoSProfile(history=qos.history, depth=qos.depth, reliability=qos.reliability,
                     durability=qos.durability)
    offered = [info.qos_profile for info in
               current_runtime().node.get_publishers_info_by_topic(topic)]
    if offered and all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered):
        qos.reliability = ReliabilityPolicy.RELIABLE
    if offered and all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered):
        qos.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return qos


def _topic_type(name: str, msg_type: Optional[str]) -> MessageClass:
    """The message class to subscribe with: ``msg_type``, else the type the graph shows."""
    if msg_type is None:
        types = graph_topics().get(name)
        if not types:
            raise Ros2nbError(f'WARNING: topic [{name}] does not appear to be published yet. '
                              'Could not determine the type for the passed topic: start its '
                              'publisher first, or pass msg_type="std_msgs/msg/Float32".'
                              + did_you_mean(name))
        msg_type = types[0]
    return message_type(msg_type)


def _collect(name: str, cls: MessageClass, count: int, timeout: float,
             sim_time: Optional[bool], on_message: Callable[[Any], None], *,
             show_logs: bool = True) -> int:
    """Subscribe to topic ``name`` on the kernel's node; run until ``count`` messages or
    ``timeout``."""
    rt = current_runtime()
    received = 0

    def callback(msg: Any) -> None:
        nonlocal received
        if received < count:
            received += 1
            on_message(msg)

    use_sim = rt.sim_time if sim_time is None else bool(sim_time)
    with rt.exclusive():
        subscription = rt.node.create_subscription(cls, name, callback, _echo_qos(name),
                                                   event_callbacks=QUIET_SUBSCRIPTION)
    try:
        with rt.clock(use_sim):
            if use_sim:
                rt.advance_sim_time(timeout, until=lambda: received >= count,
                                    on_step=lambda: rt.print_pending(show_logs=show_logs))
            else:
                deadline = time.monotonic() + timeout
                while received < count and time.monotonic() < deadline:
                    time.sleep(0.05)
                    rt.print_pending(show_logs=show_logs)
    finally:
        with rt.exclusive():
            rt.node.destroy_subscription(subscription)
    rt.print_pending(show_logs=show_logs)
    return received


def topic_echo(topic: str, msg_type: Optional[str] = None, *, count: int = 1,
               timeout: float = DEFAULT_WAIT_S, sim_time: Optional[bool] = None) -> list[Any]:
    """Print ``count`` messages from a topic as YAML, like ``ros2 topic echo --times N``.

    Log lines of the running nodes produced meanwhile are printed in order with them.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param topic: topic name.
    :param msg_type: e.g. ``'std_msgs/msg/Float32'``; ``None`` takes it from the graph.
    :param count: number of messages to print (at least 1).
    :param timeout: give up after this many seconds (simulated or wall-clock).
    :param sim_time: as for :func:`ros2nb.spin`.
    :return: the messages received (fewer than ``count`` if the timeout ran out).
    :raises Ros2nbError: if the topic's type cannot be determined or is not installed.
    :raises UsageError: if ``count`` is less than 1.
    """
    if count < 1:
        raise UsageError(f'count must be 1 or more (got {count!r}).')
    messages: list[Any] = []

    def show(msg: Any) -> None:
        messages.append(msg)
        current_runtime().emit(to_yaml(msg) + '\n---')

    name = resolve(topic)
    got = _collect(name, _topic_type(name, msg_type), count, timeout, sim_time, show)
    if got < count:
        publishers = current_runtime().node.count_publishers(name)
        hint = ('is the topic name spelled the same in both nodes?' if publishers else
                f'{name} has no publisher.' + (did_you_mean(name) or ' Is the publisher running?'))
        print(f'Received {got} of {count} messages in {timeout:g} s: {hint}')
    return messages


def topic_hz(topic: str, msg_type: Optional[str] = None, *, window: int = 10,
             timeout: float = DEFAULT_WAIT_S, sim_time: Optional[bool] = None) -> float:
    """Measure a topic's publishing rate, like ``ros2 topic hz --window N``.

    On simulated time the rate is in messages per simulated second.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param topic: topic name.
    :param msg_type: as for :func:`topic_echo`.
    :param window: number of intervals to average (at least 1).
    :param timeout: give up after this many seconds.
    :param sim_time: as for :func:`ros2nb.spin`.
    :return: average rate in Hz; ``nan`` when fewer than two messages arrived.
    :raises Ros2nbError: as :func:`topic_echo`.
    """
    if window < 1:
        raise UsageError(f'window must be 1 or more (got {window!r}).')
    rt = current_runtime()
    use_sim = rt.sim_time if sim_time is None else bool(sim_time)
    stamps: list[float] = []

    def stamp(_msg: Any) -> None:
        stamps.append(rt.sim_now_ns / 1e9 if use_sim else time.monotonic())

    name = resolve(topic)
    _collect(name, _topic_type(name, msg_type), window + 1, timeout, use_sim, stamp)
    if len(stamps) < 2:
        print(f'No rate: fewer than two messages on {name} in {timeout:g} s.')
        return math.nan
    gaps = [b - a for a, b in zip(stamps, stamps[1:])]
    rate = 1.0 / statistics.fmean(gaps)
    print(f'average rate: {rate:.3f}')
    print(f'\tmin: {min(gaps):.3f}s max: {max(gaps):.3f}s '
          f'std dev: {statistics.pstdev(gaps):.5f}s window: {len(gaps)}')
    return rate


def record(topic: str, seconds: float, msg_type: Optional[str] = None, *, field: str = 'data',
           sim_time: Optional[bool] = None) -> tuple[list[float], list[float]]:
    """Record one field of a topic for ``seconds``, like a tiny ``ros2 bag record``.

    The nodes' log lines are not printed (an hour of them would fill the notebook);
    one line says how many messages were recorded.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param topic: topic name.
    :param seconds: how long to record (simulated or wall-clock seconds).
    :param msg_type: as for :func:`topic_echo`.
    :param field: the message field to keep, e.g. ``'data'``.
    :param sim_time: as for :func:`ros2nb.spin`.
    :return: ``(times_s, values)``: arrival times in seconds since the recording
        started, and the field's values; two lists of equal length.
    :raises Ros2nbError: as :func:`topic_echo`, or if the message has no such field.
    """
    rt = current_runtime()
    use_sim = rt.sim_time if sim_time is None else bool(sim_time)
    start_s = rt.sim_now_ns / 1e9 if use_sim else time.monotonic()
    times: list[float] = []
    values: list[float] = []

    def keep(msg: Any) -> None:
        now = rt.sim_now_ns / 1e9 if use_sim else time.monotonic()
        times.append(now - start_s)
        values.append(getattr(msg, field))
        working.say(f'{len(values)} messages in {now - start_s:.0f} of {seconds:g} s')

    name = resolve(topic)
    cls = _topic_type(name, msg_type)
    fields = cls.get_fields_and_field_types()
    if field not in fields:  # checked here: raised in the callback it would only be logged
        raise Ros2nbError(f'{cls.__name__} has no field {field!r}; its fields are '
                          f'{", ".join(fields)}.')
    with working.shown(f'recording {name}'):
        _collect(name, cls, 2 ** 62, seconds, use_sim, keep, show_logs=False)
    print(f'Recorded {len(values)} messages from {name} over {seconds:g} s.')
    return times, values
