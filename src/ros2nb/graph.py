"""The ROS graph as the ``ros2 node`` / ``ros2 topic`` verbs show it, from inside the kernel.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

These verbs read the graph through the kernel's hidden node ``/_ros2nb``, the way
ros2cli reads it through its daemon, and print what the CLI prints.  They always run
in the kernel (even when a real ``ros2`` is on PATH) because ``topic_echo`` and
``topic_hz`` must share the kernel's simulated clock.
"""

from __future__ import annotations

import difflib
import importlib
import math
import statistics
import time
from typing import Any, Optional

from rclpy.qos import (DurabilityPolicy, QoSPresetProfiles, QoSProfile,
                       ReliabilityPolicy)

from .errors import Ros2nbError, UsageError
from .runtime import QUIET_SUBSCRIPTION, current_runtime

#: Topics every ROS 2 process has; they are never reported as unmatched.
INFRASTRUCTURE_TOPICS = ('/rosout', '/parameter_events', '/clock')
#: Longest time echo/hz wait for messages by default (seconds, simulated or wall-clock).
DEFAULT_WAIT_S = 10.0


def type_name(msg_type: Any) -> str:
    """The ROS name of a message class (or of an instance of it), e.g. ``std_msgs/msg/Float32``."""
    cls = msg_type if isinstance(msg_type, type) else type(msg_type)
    return f'{cls.__module__.split(".")[0]}/msg/{cls.__name__}'


def node_endpoints(node: Any) -> list[tuple[str, str, str]]:
    """A node's own publishers and subscriptions: ``(kind, topic, type)``, topics resolved.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through the checks).
    """
    return [(kind, node.resolve_topic_name(e.topic_name), type_name(e.msg_type))
            for kind, entities in (('publisher', node.publishers),
                                   ('subscription', node.subscriptions))
            for e in entities]


def _hidden(name: str) -> bool:
    return any(part.startswith('_') for part in name.split('/') if part)


def _resolve(topic: str) -> str:
    return current_runtime().node.resolve_topic_name(topic)


def node_list(*, all: bool = False) -> list[str]:
    """Print and return the running nodes' names, like ``ros2 node list``.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param all: also show hidden nodes (names starting with ``_``), like ``--all``.
    :return: fully qualified node names, sorted.
    :raises Ros2nbError: if ROS is not up (run ``ros2nb.start()``).
    """
    names = sorted({(ns.rstrip('/') + '/' + name) for name, ns in
                    current_runtime().node.get_node_names_and_namespaces()})
    names = [n for n in names if all or not _hidden(n)]
    for name in names:
        print(name)
    return names


def _topics() -> dict[str, list[str]]:
    return {name: types for name, types in current_runtime().node.get_topic_names_and_types()
            if not _hidden(name)}


def unmatched_topics() -> list[str]:
    """Return one line per topic whose two sides do not meet.

    A topic with publishers but no subscriptions (or the reverse), as a typo such as
    ``temprature`` in one node makes, with the closest other topic name; and a topic used
    with two message types (a ``Float32`` publisher and a ``Float64`` subscription never
    exchange a message).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`topic_list`).

    :return: human-readable notes, empty when every topic is matched.
    """
    node = current_runtime().node
    notes = []
    topics = _topics()
    others = [n for n in topics if n not in INFRASTRUCTURE_TOPICS]
    for name in sorted(others):
        if len(topics[name]) > 1:
            owners: dict[str, set[str]] = {t: set() for t in topics[name]}
            for info in [*node.get_publishers_info_by_topic(name),
                         *node.get_subscriptions_info_by_topic(name)]:
                if not _hidden(info.node_name):  # nodes not discovered yet stay unnamed
                    owners.setdefault(info.topic_type, set()).add(info.node_name)
            uses = [f'{t} ({", ".join(sorted(o))})' if o else t for t, o in sorted(owners.items())]
            notes.append(f'{name} is used with {len(topics[name])} message types: '
                         f'{", ".join(uses)}; both sides must use the same type')
            continue
        pubs, subs = node.count_publishers(name), node.count_subscribers(name)
        note = (f'{name} has {pubs} publisher(s) but no subscription' if pubs and not subs else
                f'{name} has {subs} subscription(s) but no publisher' if subs and not pubs else '')
        if note:
            close = difflib.get_close_matches(name, [o for o in others if o != name], n=1)
            notes.append(note + (f': is it a typo of {close[0]}?' if close else ''))
    return notes


def _print_unmatched() -> None:
    for note in unmatched_topics():
        print(f'Note: {note}')


def topic_list(*, show_types: bool = False) -> list[str]:
    """Print and return the topics in the graph, like ``ros2 topic list [-t]``.

    Afterwards it points out topics with publishers but no subscriptions (or the reverse).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param show_types: also print each topic's type, like ``-t``.
    :return: topic names, sorted.
    :raises Ros2nbError: if ROS is not up.
    """
    topics = _topics()
    for name in sorted(topics):
        print(f'{name} [{", ".join(topics[name])}]' if show_types else name)
    _print_unmatched()
    return sorted(topics)


def _did_you_mean(topic: str) -> str:
    close = difflib.get_close_matches(topic, [t for t in _topics() if t != topic], n=1)
    return f' Did you mean {close[0]}?' if close else ''


def _unknown_topic(topic: str) -> Ros2nbError:
    hint = _did_you_mean(topic) or ' Check the name with ros2nb.topic_list().'
    return Ros2nbError(f"Unknown topic '{topic}'.{hint}")


def _policy(value: Any) -> str:
    return value.name if hasattr(value, 'name') else str(value)


def _duration(value: Any) -> str:
    nanoseconds = value.nanoseconds if hasattr(value, 'nanoseconds') else int(value)
    # rmw reports "infinite" as the largest representable duration.
    return 'Infinite' if nanoseconds >= 0x7FFFFFFFFFFFFFFF or nanoseconds == 0 else \
        f'{nanoseconds} nanoseconds'


def topic_info(topic: str, *, verbose: bool = False) -> dict[str, int]:
    """Print a topic's type and publisher/subscription counts, like ``ros2 topic info [-v]``.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param topic: topic name, relative (``temperature``) or absolute (``/temperature``).
    :param verbose: also print every endpoint's node and QoS, like ``-v``.
    :return: ``{'publishers': n, 'subscriptions': m}``.
    :raises Ros2nbError: for an unknown topic (with the closest existing name).
    """
    name = _resolve(topic)
    topics = _topics()
    if name not in topics:
        raise _unknown_topic(name)
    node = current_runtime().node
    pubs = node.get_publishers_info_by_topic(name)
    subs = node.get_subscriptions_info_by_topic(name)
    print(f'Type: {", ".join(topics[name])}')
    for label, endpoints in (('Publisher', pubs), ('Subscription', subs)):
        if verbose:
            print()
        print(f'{label} count: {len(endpoints)}')
        if not verbose:
            continue
        for info in sorted(endpoints, key=lambda e: (e.node_namespace, e.node_name)):
            qos = info.qos_profile
            print()
            print(f'Node name: {info.node_name}')
            print(f'Node namespace: {info.node_namespace}')
            print(f'Topic type: {info.topic_type}')
            print(f'Endpoint type: {_policy(info.endpoint_type)}')
            print('QoS profile:')
            print(f'  Reliability: {_policy(qos.reliability)}')
            history = _policy(qos.history)
            print(f'  History (Depth): {history}' if history == 'UNKNOWN' else
                  f'  History (Depth): {history} ({qos.depth})')
            print(f'  Durability: {_policy(qos.durability)}')
            print(f'  Lifespan: {_duration(qos.lifespan)}')
            print(f'  Deadline: {_duration(qos.deadline)}')
            print(f'  Liveliness: {_policy(qos.liveliness)}')
            print(f'  Liveliness lease duration: {_duration(qos.liveliness_lease_duration)}')
    if name not in INFRASTRUCTURE_TOPICS and (not pubs or not subs):
        _print_unmatched()
    return {'publishers': len(pubs), 'subscriptions': len(subs)}


def message_type(type_name: str) -> type:
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


def _topic_type(name: str, msg_type: Optional[str]) -> type:
    """The message class to subscribe with: ``msg_type``, else the type the graph shows."""
    if msg_type is None:
        types = _topics().get(name)
        if not types:
            raise Ros2nbError(f'WARNING: topic [{name}] does not appear to be published yet. '
                              'Could not determine the type for the passed topic: start its '
                              'publisher first, or pass msg_type="std_msgs/msg/Float32".'
                              + _did_you_mean(name))
        msg_type = types[0]
    return message_type(msg_type)


def _collect(name: str, cls: type, count: int, timeout: float,
             sim_time: Optional[bool], on_message, *, show_logs: bool = True) -> int:
    """Subscribe to topic ``name`` on the kernel's node; run until ``count`` messages or ``timeout``."""
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

    name = _resolve(topic)
    got = _collect(name, _topic_type(name, msg_type), count, timeout, sim_time, show)
    if got < count:
        publishers = current_runtime().node.count_publishers(name)
        hint = ('is the topic name spelled the same in both nodes?' if publishers else
                f'{name} has no publisher.' + (_did_you_mean(name) or ' Is the publisher running?'))
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

    name = _resolve(topic)
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

    name = _resolve(topic)
    cls = _topic_type(name, msg_type)
    fields = cls.get_fields_and_field_types()
    if field not in fields:  # checked here: raised in the callback it would only be logged
        raise Ros2nbError(f'{cls.__name__} has no field {field!r}; its fields are '
                          f'{", ".join(fields)}.')
    _collect(name, cls, 2 ** 62, seconds, use_sim, keep, show_logs=False)
    print(f'Recorded {len(values)} messages from {name} over {seconds:g} s.')
    return times, values
