"""The judge's own ROS node: it sees the graph, hears messages and logs, asks nodes.

Part of the judge (:mod:`ros2nb.judge`): every verdict comes from what this node observes
itself over ROS, on the judge's own domain, stamped with the judge's own clock
(:attr:`Observer.now_ns`, moved on only by :class:`ros2nb.judge.clock.JudgeClock`); a
subject's word only says how long to wait.
"""

from __future__ import annotations

import collections
import contextlib
import math
import threading
import time
from typing import AbstractSet, Any, Callable, Optional

import rclpy
from rcl_interfaces.msg import Log
from rcl_interfaces.srv import ListParameters
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from rclpy.signals import SignalHandlerOptions

from .. import domains
from ..judge_interface import ARRIVAL_TIMEOUT_S, JUDGE_NODES, Heard, Line
from ..errors import NotDecided
from ..patience import LOOK_S, Patience, wait_for_work
from ..runtime import QUIET_SUBSCRIPTION, node_serving_nothing
from ..runtime.services import call_until_answered
from .floods import Floods


#: Longest wait of the judge's spin thread for work (s); None: until work comes, or
#: :meth:`Observer.close` wakes it.  rclpy's ``spin_once`` could only end at its timeout, so
#: an idle judge kept waking for nothing, and a wait with a timeout costs rclpy a timer of its
#: own, which the spin thread pays for in every wait of a simulated hour (docs/decisions.md).
SPIN_WAIT_S: Optional[float] = None
#: Bytes of an endpoint's gid that name its participant (the DDS GUID prefix): one per
#: process that brought ROS up.
PARTICIPANT_PREFIX_BYTES = 12
#: What the judge's subscriptions keep: every message, reliably (a check counts them all).
EVERY_MESSAGE = QoSProfile(history=HistoryPolicy.KEEP_ALL, reliability=ReliabilityPolicy.RELIABLE)
#: /rosout as ``ros2 topic echo /rosout`` hears it: reliable, and what live nodes logged
#: shortly before the judge matched them (rcl keeps each node's last lines).
ROSOUT_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.TRANSIENT_LOCAL)


class _GivenUp(Exception):
    """The processes a wait attended to had their patience (:meth:`Observer.spins`)."""


class Observer:
    """The judge's own ROS node on the judge's domain: graph, messages, logs, probes."""

    def __init__(self) -> None:
        self.domain_id = domains.domain_id()
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.node = node_serving_nothing(JUDGE_NODES, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.changed = threading.Condition()
        #: The judge's clock now (ns); what arrives is stamped with it.
        self.now_ns = 0
        #: Every /rosout line heard, in order of arrival.
        self.logs: list[Line] = []
        #: /rosout lines heard per logger.
        self.log_counts: collections.Counter[str] = collections.Counter()
        #: Messages heard per watched topic, in order of arrival.
        self.heard: dict[str, list[Heard]] = {}
        #: What the learner's code sends beyond any node of the course, and its one line.
        self.floods = Floods(self)
        self._quiet: Optional[Node] = None
        self._stop = False
        #: Held while a message is taken: by the spin thread, or by :meth:`take_stale`.
        self._taking = threading.Lock()
        #: The processes whose work the judge waits for (its subjects and the learner's
        #: programs, given by the session): every wait of the judge's lasts while they work.
        self.attending: Callable[[], list[int]] = list
        self._thread = threading.Thread(target=self._spin, name='ros2nb-judge', daemon=True)
        self._thread.start()
        #: What the judge hears the learner's code send on: /rosout and the watched topics.
        on_log: Any = self._on_log  # with the message's info: rclpy passes it to two arguments
        self._hearing = [self.node.create_subscription(Log, '/rosout', on_log, ROSOUT_QOS,
                                                       event_callbacks=QUIET_SUBSCRIPTION)]

    def _spin(self) -> None:
        """Run the node's callbacks until :meth:`close` (which wakes the wait at once)."""
        while not self._stop:
            with contextlib.suppress(Exception):  # as spin_once: a callback's error is dropped
                handler = self.executor.wait_for_ready_callbacks(
                    timeout_sec=SPIN_WAIT_S, condition=self._stopping)[0]
                with self._taking:  # rcl takes from a subscription in one thread at a time
                    handler()

    def _stopping(self) -> bool:
        return self._stop

    def _on_log(self, msg: Log, info: Any) -> None:
        with self.changed:
            if self.floods.stale(info) or self.floods.count('/rosout', msg.name):
                return
            self.logs.append(Line(self.now_ns, msg.name, msg.level, msg.msg))
            self.log_counts[msg.name] += 1
            self.changed.notify_all()

    def watch(self, topic: str, msg_type: Any,
              keep: Callable[[Any], Any] = lambda msg: msg.data) -> list[Heard]:
        """Hear every ``msg_type`` message on ``topic`` from now on; return the list they go to.

        Reliable, keeping every message; each is kept as ``keep(msg)`` with the judge's time
        of arrival.  Watching a topic twice returns the same list (the first ``keep`` stays).
        """
        if topic not in self.heard:
            self.heard[topic] = store = []

            def noted(msg: Any, info: Any) -> None:
                with self.changed:
                    if self.floods.stale(info) or self.floods.count(topic, topic):
                        return
                    store.append(Heard(self.now_ns, keep(msg)))
                    self.changed.notify_all()

            note: Any = noted  # with the message's info, as on_log
            self._hearing.append(self.node.create_subscription(
                msg_type, topic, note, EVERY_MESSAGE, event_callbacks=QUIET_SUBSCRIPTION))
        return self.heard[topic]

    def take_stale(self) -> None:
        """Take what the judge's subscriptions hold that stopped processes sent
        (:meth:`~ros2nb.judge.floods.Floods.stale`), serialised, until a history holds no
        more of it: a flood's backlog, gone before the next check, not read in the spin
        thread beside it.  A message sent since goes to its callback, as the spin thread's do.
        """
        for subscription in list(self._hearing):
            while True:
                with self._taking, subscription.handle:
                    taken = subscription.handle.take_message(subscription.msg_type, True)
                if taken is None:
                    break
                raw, info = taken
                if not self.floods.stale(info):
                    subscription.callback(deserialize_message(raw, subscription.msg_type), info)
                    break

    def quiet_node(self) -> Node:
        """A node of the judge's that no thread spins: what its subscriptions receive waits in
        their history until the judge takes it (nothing taken before it asks)."""
        if self._quiet is None:
            self._quiet = node_serving_nothing(f'{JUDGE_NODES}_taker', context=self.context)
        return self._quiet

    def counts(self) -> tuple[dict[str, int], dict[str, int]]:
        """Messages heard so far per watched topic, and /rosout lines per logger."""
        with self.changed:
            return ({t: len(v) for t, v in self.heard.items()}, dict(self.log_counts))

    def wait_until(self, condition: Callable[[], bool], seconds: float) -> bool:
        """Wait until ``condition()`` holds (looked at whenever something arrives), while the
        processes the judge attends to work towards it: False once they had ``seconds``
        (:func:`~ros2nb.patience.wait_for_work`: of their work, or of their idle waiting).

        :raises Flooded: when a flood was found (:class:`~ros2nb.judge.floods.Floods`), at once.
        """
        met = wait_for_work(lambda: self.floods.line is not None or condition(),
                            self.attending(), seconds, look=self._wait_briefly)
        self.floods.raise_any()
        return met

    def settle(self, cpu_s: float) -> None:
        """Wait, the clock standing still, until the processes the judge attends to sit idle
        (one look of :class:`~ros2nb.patience.Patience`), or have worked ``cpu_s`` CPU seconds.

        What a thread of the learner's sends meanwhile without waiting for a timer counts
        towards a flood in the same window, however fast or busy the machine: a flood is
        found by the work the flooder did, not by how many clock steps passed meanwhile.

        :raises Flooded: at once, when a flood was found.
        """
        patience = Patience(self.attending(), cpu_s)  # idle time counts from now
        while not self._wait_briefly(lambda: self.floods.line is not None, LOOK_S):
            if patience.exhausted():
                break
        self.floods.raise_any()

    def _wait_briefly(self, condition: Callable[[], bool], seconds: float) -> bool:
        """Wait until ``condition()`` holds, at most ``seconds`` on the wall clock."""
        deadline = time.monotonic() + seconds
        with self.changed:
            while not condition():
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self.changed.wait(min(left, 0.05))
        return True

    def lines_of(self, logger: str, start: int = 0) -> list[str]:
        """Log lines of one logger received so far, from position ``start`` on."""
        with self.changed:
            return [line.text for line in self.logs[start:] if line.name == logger]

    def endpoints(self, name: str, namespace: str, expected: list[tuple[str, str, str]],
                  seconds: float = ARRIVAL_TIMEOUT_S) -> list[tuple[str, str, str]]:
        """The node's publishers and subscriptions as the ROS graph shows them.

        Waits until one process's node ``namespace/name`` holds at least ``expected`` (what
        the subject said it made) or ``seconds`` pass.  Read from the endpoints DDS
        discovered, topic by topic, and grouped by the process (participant) that owns
        them: a node of that name the graph still lists after its process ended, with
        none of its endpoints left, hides nothing.

        :return: ``(kind, topic, type)`` triples, ``kind`` being ``'publisher'`` or
            ``'subscription'``, sorted, without ROS's own topics.
        :raises NotDecided: when ``seconds`` pass first (the line says what was seen).
        """
        want = {tuple(e) for e in expected}
        owners: dict[bytes, set[tuple[str, str, str]]] = {}
        found: set[tuple[str, str, str]] = set()

        def covered() -> bool:
            nonlocal owners, found
            owners = self._endpoints_by_process(name, namespace)
            # The process whose node holds what the subject made (exactly, if one does: an
            # earlier subject's node of that name may linger a moment after its process).
            covering = sorted((e for e in owners.values() if want <= e), key=len)
            found = covering[0] if covering else max(owners.values(), key=len, default=set())
            return want <= found

        if not wait_for_work(covered, self.attending(), seconds):
            # not the learner's mistake: say what happened
            raise NotDecided(self._unseen(name, len(owners), want, found, seconds))
        return sorted(e for e in found if e[1] not in ('/rosout', '/parameter_events', '/clock'))

    def _endpoint_infos(self) -> list[tuple[str, str, Any]]:
        """Every topic endpoint DDS discovered on the domain: ``(kind, topic, info)``.

        Read again when the graph changed under a read (a topic gone between two calls);
        empty only when five reads in a row failed so.
        """
        for _attempt in range(5):
            found: list[tuple[str, str, Any]] = []
            try:
                for topic, _types in self.node.get_topic_names_and_types():
                    for kind, infos in (
                            ('publisher', self.node.get_publishers_info_by_topic(topic)),
                            ('subscription', self.node.get_subscriptions_info_by_topic(topic))):
                        found.extend((kind, topic, info) for info in infos)
            except Exception:  # noqa: BLE001 - the graph changed meanwhile: read it again
                time.sleep(0.02)
                continue
            return found
        return []

    def _endpoints_by_process(self, name: str, namespace: str
                              ) -> dict[bytes, set[tuple[str, str, str]]]:
        """Endpoints of the nodes ``namespace/name``, by the participant that owns them."""
        owners: dict[bytes, set[tuple[str, str, str]]] = {}
        for kind, topic, info in self._endpoint_infos():
            if info.node_name == name and info.node_namespace == namespace:
                owner = bytes(info.endpoint_gid[:PARTICIPANT_PREFIX_BYTES])
                owners.setdefault(owner, set()).add((kind, topic, info.topic_type))
        return owners

    def _unseen(self, name: str, processes: int, want: AbstractSet[tuple[str, ...]],
                found: AbstractSet[tuple[str, ...]], seconds: float) -> str:
        """Why the graph never showed what a subject said its node made, in one line."""
        if processes > 1:
            return (f'{processes} programs have a node named {name} on the grader\'s ROS domain '
                    f'{self.domain_id}, so the grader cannot tell yours apart (another program '
                    'on this machine uses that domain)')
        missing = ', '.join(f'{kind} on {topic}' for kind, topic, _ in sorted(want - found))
        shown = ', '.join(f'{kind} on {topic}' for kind, topic, _ in sorted(found)) or 'nothing'
        return (f'the grader could not see the {missing} of {name} in the ROS graph (it saw '
                f'{shown})')

    def spins(self, name: str, namespace: str = '/', seconds: float = ARRIVAL_TIMEOUT_S) -> bool:
        """True once the node ``name`` answers a call of its ``list_parameters`` service.

        Every rclpy node serves its parameters while it spins, and only then: an answer
        proves that the process got past creating the node and into its spin.  False when no
        answer came in ``seconds`` (or the node serves no parameters).
        """
        service = f'{namespace.rstrip("/")}/{name}/list_parameters'
        client = self.node.create_client(ListParameters, service)
        patience = Patience(self.attending(), seconds)

        def given_up() -> None:
            self.floods.raise_any()
            if patience.exhausted():
                raise _GivenUp

        try:
            while not client.wait_for_service(timeout_sec=0.1):
                given_up()
            # Asked again now and then: a request goes only to the servers discovered when
            # it is sent (a node of that name that just ended may be one of them).
            return call_until_answered(lambda: client.call_async(ListParameters.Request()),
                                       lambda f, s: self._wait_briefly(f.done, s),
                                       math.inf, between=given_up) is not None
        except _GivenUp:
            return False
        finally:
            self.node.destroy_client(client)

    def live_nodes(self) -> set[tuple[str, str]]:
        """The ``(name, namespace)`` of every node on the domain that owns a publisher or a
        subscription now.

        Every rclpy node publishes ``/parameter_events``, so a node that owns none is not
        running: it is what the ROS graph keeps listing when a process ended while
        its last discovery message was still on its way (ros2/ros2#1413: the name stays,
        its publishers and subscriptions are gone).  Such a node would otherwise pass for the
        next subject's.
        """
        return {(info.node_name, info.node_namespace) for _kind, _topic, info
                in self._endpoint_infos()}

    def has_node(self, name: str) -> bool:
        """True when a running node called ``name`` (any namespace) is on the domain."""
        return any(n == name for n, _ns in self.live_nodes())

    def count_endpoints(self, name: str, namespace: str, kind: str, topic: str) -> int:
        """How many ``kind`` endpoints (``'publisher'`` or ``'subscription'``) the node
        ``namespace/name`` owns on ``topic`` now, as DDS discovered them: the most one
        process owns (a node of that name an earlier process left may linger a moment)."""
        counts: dict[bytes, int] = {}
        for found, on, info in self._endpoint_infos():
            if found == kind and on == topic and info.node_name == name \
                    and info.node_namespace == namespace:
                owner = bytes(info.endpoint_gid[:PARTICIPANT_PREFIX_BYTES])
                counts[owner] = counts.get(owner, 0) + 1
        return max(counts.values(), default=0)

    def close(self) -> None:
        self._stop = True
        self.executor.wake()
        self._thread.join()
        self.executor.shutdown()
        if self._quiet is not None:
            self._quiet.destroy_node()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
