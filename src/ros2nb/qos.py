"""QoS trials: what a subscription with a given profile really receives, over real DDS.

Introduced in ``09-qos.ipynb``.  Each trial makes a publisher and a subscription of its own
on a private rclpy context (the kernel's nodes and executor are not touched), on this
process's ROS domain and a topic of its own, and reports the ``std_msgs/Int32`` numbers
0, 1, 2, ... that reached the subscription's callback.  The trials are deterministic: the
publisher finishes before the subscription's callback runs (a burst before spinning), and
waiting ends on a state (every message acknowledged, the endpoints matched), never on a
guessed time.  A burst *while* spinning loses a number that changes from run to run.

The checks of notebook 09 run the same trials on the learner's profiles.  Whether two
profiles can talk is rclpy's to say (:func:`incompatibility`, with ``qos_check_compatible``,
which knows every DDS rule), on the profiles as discovery reports them for both endpoints
(:func:`discovered`), as ``ros2 topic info --verbose`` shows them.
"""

from __future__ import annotations

import itertools
import os
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

import rclpy
from rclpy.context import Context
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import SingleThreadedExecutor
from rclpy.qos import QoSProfile
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import Int32

from . import domains
from .errors import Ros2nbError
from .qos_profiles import describe, endpoint_lines, incompatibility, policy_name
from .runtime import node_serving_nothing

#: ``describe`` and ``policy_name`` are the notebook's (09) ways to print a profile and the
#: policy an incompatible-QoS event names; the checks name the others.
__all__ = ['Deliveries', 'burst', 'burst_while_spinning', 'describe', 'discovered',
           'endpoint_lines', 'incompatibility', 'late_joiner', 'pair', 'policy_name']

#: Seconds a trial waits for discovery (matching) and acknowledgements; the wait ends as
#: soon as the state is reached, so only a very busy machine or a mismatch costs this long.
MATCH_TIMEOUT_S = 30.0
#: Seconds one spin waits for a message; a drain ends after one such empty wait.
IDLE_S = 0.05
_topics = itertools.count()


def discovered(node: Any, topic: str, kind: str, *, seconds: float = MATCH_TIMEOUT_S,
               wait: Optional[Callable[[float], None]] = None) -> list[Any]:
    """The endpoints of ``topic`` of one kind (``'publisher'`` or ``'subscription'``), as
    discovery reports them to ``node`` (each with its node's name and its QoS profile, as
    ``ros2 topic info --verbose`` shows them); waits until there is one, up to ``seconds``.

    :param wait: how to wait a moment (default ``time.sleep``); a node that is spun by the
        caller passes a spin.
    :return: the endpoints' infos (empty when none appeared in time).
    """
    find = node.get_publishers_info_by_topic if kind == 'publisher' \
        else node.get_subscriptions_info_by_topic
    deadline = time.monotonic() + seconds
    while True:
        found = list(find(topic))
        if found or time.monotonic() > deadline:
            return found
        (wait or time.sleep)(0.01)


@dataclass
class Deliveries:
    """What one trial's subscription received.

    :ivar received: the numbers its callback got, in order.
    :ivar matched: whether publisher and subscription matched (were compatible).
    :ivar incompatible: rclpy's incompatible-QoS event info, when it fired (else None).
    :ivar event_s: seconds from creating the subscription to that event (wall clock).
    :ivar explanation: :func:`incompatibility` of the two profiles, when they do not match.
    :ivar endpoints: both endpoints as ``ros2 topic info --verbose`` shows them (lines).
    """

    received: list[int] = field(default_factory=list)
    matched: bool = False
    incompatible: Any = None
    event_s: Optional[float] = None
    explanation: Optional[str] = None
    endpoints: list[str] = field(default_factory=list)


class _Trial:
    """A private context on this process's domain, one node, one executor."""

    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context, domain_id=domains.domain_id(),
                   signal_handler_options=SignalHandlerOptions.NO)
        self.nodes = [node_serving_nothing(name, context=self.context, enable_rosout=False)
                      for name in ('qos_trial_publisher', 'qos_trial_subscription')]
        self.executor = SingleThreadedExecutor(context=self.context)
        for node in self.nodes:
            self.executor.add_node(node)
        self.topic = f'/ros2nb_qos_trial_{os.getpid()}_{next(_topics)}'
        self.out = Deliveries()

    def publisher(self, profile: QoSProfile) -> Any:
        # The publisher's side of an incompatible pair is reported by the subscription's event:
        # a callback of its own keeps rclpy from logging a warning of its own as well.
        events = PublisherEventCallbacks(incompatible_qos=lambda info: None)
        return self.nodes[0].create_publisher(Int32, self.topic, profile, event_callbacks=events)

    def subscription(self, profile: QoSProfile) -> Any:
        started = time.monotonic()

        def on_incompatible(info: Any) -> None:
            if self.out.incompatible is None:
                self.out.incompatible, self.out.event_s = info, time.monotonic() - started

        def on_message(msg: Int32) -> None:
            self.out.received.append(msg.data)

        events = SubscriptionEventCallbacks(incompatible_qos=on_incompatible)
        return self.nodes[1].create_subscription(Int32, self.topic, on_message, profile,
                                                 event_callbacks=events)

    def wait_matched(self, publisher: Any) -> bool:
        """Spin (events only arrive so) until matched or the incompatible event fired."""
        deadline = time.monotonic() + MATCH_TIMEOUT_S
        while time.monotonic() < deadline:
            if publisher.get_subscription_count() >= 1:
                self.out.matched = True
                return True
            if self.out.incompatible is not None:
                return False
            self.executor.spin_once(timeout_sec=0.01)
        return False

    def drain(self) -> None:
        """Run callbacks until one wait of :data:`IDLE_S` brings nothing new."""
        while True:
            before = len(self.out.received)
            self.executor.spin_once(timeout_sec=IDLE_S)
            if len(self.out.received) == before:
                self.executor.spin_once(timeout_sec=IDLE_S)
                if len(self.out.received) == before:
                    return

    def close(self) -> None:
        self.executor.shutdown()
        for node in self.nodes:
            node.destroy_node()
        rclpy.try_shutdown(context=self.context)


def _trial(body: Callable[[_Trial], None]) -> Deliveries:
    trial = _Trial()
    try:
        body(trial)
        return trial.out
    finally:
        trial.close()


def _discovered_incompatibility(node: Any, topic: str) -> Optional[str]:
    """:func:`incompatibility` of the first publisher and subscription of ``topic`` with
    their profiles as discovery reports them (the middleware's defaults filled in)."""
    publishers = discovered(node, topic, 'publisher')
    subscriptions = discovered(node, topic, 'subscription')
    if not publishers or not subscriptions:
        return None
    return incompatibility(publishers[0].qos_profile, subscriptions[0].qos_profile)


def _publish(publisher: Any, count: int) -> None:
    for number in range(count):
        publisher.publish(Int32(data=number))
    publisher.wait_for_all_acked()


def _require_profile(profile: Any, what: str) -> None:
    if not isinstance(profile, QoSProfile):
        raise Ros2nbError(f'{what} must be a QoSProfile, not {type(profile).__name__}: '
                          'build one with QoSProfile(depth=..., ...).')


def burst(subscription_qos: QoSProfile, *, count: int = 30,
          publisher_qos: Optional[QoSProfile] = None) -> Deliveries:
    """Publish ``count`` numbers in a burst, then let the subscription's callback run.

    The subscription is matched first; the whole burst is published and acknowledged before
    its callback runs once (a slow subscriber), so what it gets is what its history kept.

    Introduced in ``09-qos.ipynb``.

    :param subscription_qos: the subscription's profile.
    :param count: messages in the burst (numbers 0 to count-1).
    :param publisher_qos: default reliable, volatile, keep last ``count``.
    :return: the deliveries; ``received`` e.g. ``[29]`` at depth 1.
    :raises Ros2nbError: when a profile is not a QoSProfile.
    """
    publisher_qos = publisher_qos or QoSProfile(depth=count)
    _require_profile(subscription_qos, 'The subscription\'s profile')
    _require_profile(publisher_qos, 'The publisher\'s profile')

    def body(trial: _Trial) -> None:
        publisher = trial.publisher(publisher_qos)
        trial.subscription(subscription_qos)
        if trial.wait_matched(publisher):
            _publish(publisher, count)
            trial.drain()
        else:
            trial.out.explanation = _discovered_incompatibility(trial.nodes[1], trial.topic) \
                or incompatibility(publisher_qos, subscription_qos)

    return _trial(body)


def late_joiner(qos: QoSProfile, *, count: int = 20) -> Deliveries:
    """Publish ``count`` numbers with nobody listening; then a subscription joins.

    Publisher and late subscription both use ``qos``.  A transient-local publisher keeps the
    last ``depth`` messages for subscriptions that join later; a volatile one keeps none.

    Introduced in ``09-qos.ipynb``.

    :return: the deliveries; ``received`` e.g. ``[15, 16, 17, 18, 19]`` at depth 5.
    :raises Ros2nbError: when ``qos`` is not a QoSProfile.
    """
    _require_profile(qos, 'The profile')

    def body(trial: _Trial) -> None:
        publisher = trial.publisher(qos)
        for number in range(count):
            publisher.publish(Int32(data=number))
        trial.subscription(qos)
        if trial.wait_matched(publisher):
            publisher.wait_for_all_acked()
            trial.drain()

    return _trial(body)


def pair(publisher_qos: QoSProfile, subscription_qos: QoSProfile, *,
         count: int = 5) -> Deliveries:
    """A publisher and a subscription with two profiles: do they match, what arrives?

    When they are incompatible, rclpy's own incompatible-QoS event fires on the
    subscription (``event_s`` says after how long) and ``explanation`` says why in one line.
    When they match, ``count`` numbers are published one by one, each waited for (a reliable
    subscription gets every one; a best-effort one may miss some on a busy network).

    Introduced in ``09-qos.ipynb``.

    :raises Ros2nbError: when a profile is not a QoSProfile.
    """
    _require_profile(publisher_qos, 'The publisher\'s profile')
    _require_profile(subscription_qos, 'The subscription\'s profile')

    def body(trial: _Trial) -> None:
        publisher = trial.publisher(publisher_qos)
        trial.subscription(subscription_qos)
        matched = trial.wait_matched(publisher)
        graph = trial.nodes[1]
        deadline = time.monotonic() + MATCH_TIMEOUT_S  # both endpoints in the graph
        while (min(graph.count_publishers(trial.topic), graph.count_subscribers(trial.topic)) < 1
               and time.monotonic() < deadline):
            trial.executor.spin_once(timeout_sec=0.01)
        for label, infos in (('Publisher', graph.get_publishers_info_by_topic(trial.topic)),
                             ('Subscription', graph.get_subscriptions_info_by_topic(trial.topic))):
            trial.out.endpoints += [f'{label} count: {len(infos)}', '']
            for info in infos:
                trial.out.endpoints += endpoint_lines(info) + ['']
        if not matched:
            trial.out.explanation = _discovered_incompatibility(graph, trial.topic) \
                or incompatibility(publisher_qos, subscription_qos)
            return
        for number in range(count):
            publisher.publish(Int32(data=number))
            deadline = time.monotonic() + IDLE_S * 4
            while number not in trial.out.received and time.monotonic() < deadline:
                trial.executor.spin_once(timeout_sec=IDLE_S)

    return _trial(body)


def burst_while_spinning(subscription_qos: QoSProfile, *, count: int = 30,
                         callback_s: float = 0.002, gap_s: float = 0.001) -> Deliveries:
    """Publish ``count`` numbers, one every ``gap_s`` s, while a callback taking
    ``callback_s`` s spins in another thread: the subscription takes some while others arrive.

    What is lost depends on how the operating system schedules the two threads: the numbers
    change from run to run (a wall-clock demonstration, never a check).

    Introduced in ``09-qos.ipynb``.

    :raises Ros2nbError: when the profile is not a QoSProfile.
    """
    _require_profile(subscription_qos, 'The subscription\'s profile')

    def body(trial: _Trial) -> None:
        publisher = trial.publisher(QoSProfile(depth=count))
        subscription = trial.subscription(subscription_qos)
        keep = subscription.callback

        def slow(msg: Any) -> None:
            time.sleep(callback_s)
            keep(msg)

        subscription.callback = slow
        if not trial.wait_matched(publisher):
            return
        done = threading.Event()

        def spin() -> None:
            while not done.is_set():
                trial.executor.spin_once(timeout_sec=IDLE_S)

        spinner = threading.Thread(target=spin, daemon=True)
        spinner.start()
        for number in range(count):
            publisher.publish(Int32(data=number))
            time.sleep(gap_s)
        publisher.wait_for_all_acked()
        done.set()
        spinner.join()
        trial.drain()

    return _trial(body)
