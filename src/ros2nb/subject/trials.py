"""The subject's commands for notebooks 06, 07 and 09: the learner's worker, rooms, plot and
QoS endpoints.

Part of :mod:`ros2nb.subject` (a mixin of :class:`ros2nb.subject.commands.Subject`).  Each
command makes something of the learner's run (their executor spinning their Worker, nodes
started with their arguments, an endpoint with their profile); the judge watches it over ROS
itself, and where the learner's code drives code the course gave them, the course's own
version of it tells the judge what happened (:mod:`.shown`).  A reply names the parts only so
that the judge can say why what it saw went wrong.
"""

from __future__ import annotations

import threading
import time
from typing import Any, Optional

from rclpy.duration import Duration
from rclpy.executors import Executor
from rclpy.node import Node
from rclpy.qos import QoSProfile
from std_msgs.msg import Float32, Int32

from ..endpoints import node_endpoints
from ..explain.exceptions import describe_error
from ..explain.ros_settings import zero_depth_refused
from ..runtime.rates import callback_groups
from ..subject_interface import (PlotShown, QosAcked, QosEndpoint, RoomNodes, Worker,
                                 WorkerStop)
from ..subject_replies import (CallbackFailure, PlotWitnessed, QosMade, Reply, RoomsMade,
                               WorkerSpun, WorkerStopped)
from .replies import described, encode
from .shown import Shown, plot_redraw, worker_callbacks

#: The node that makes an endpoint with the learner's QoS profile (notebook 09).
QOS_NODE = 'qos_answer'
#: Wall-clock seconds one spin of the learner's executor waits for work (notebook 06).
SPIN_ROUND_S = 0.05


class Trials:
    """Commands of notebooks 06 and 09; the state lives in :class:`~.process.Subject`."""

    namespace: dict[str, Any]
    rooms: list[Node]
    node: Optional[Node]
    _spun: Optional[tuple[Node, Executor, threading.Thread, threading.Event,
                          list[CallbackFailure], Shown]]
    _qos: Optional[tuple[Node, Any]]
    _plot_shown: Optional[Shown] = None

    def _runtime(self) -> Any:  # provided by Subject
        raise NotImplementedError

    # ------------------------------------------------------------ notebook 06
    def worker(self, command: Worker) -> WorkerSpun:
        """Call the learner's ``name()`` for ``(node, executor)``, put the course's callbacks
        (:func:`.shown.worker_callbacks`, telling ``topic`` with ``token``) on the Worker's two
        timers, in the callback groups the learner chose, and spin the learner's executor on the
        wall clock in a thread until :meth:`worker_stop`; the judge watches ``topic``.

        ``work_s``: how long the course's slow callback works (s, wall clock); ``seconds``:
        how long to wait, at most, for the judge's subscription to match.
        """
        function = self.namespace.get(command.name)
        if not callable(function):
            return WorkerSpun(ok=False, undefined=True)
        self._runtime()  # rclpy initialised, on this subject's domain
        try:
            made = function()
        except BaseException as error:
            return WorkerSpun(ok=False, error=described(error))
        if not (isinstance(made, tuple) and len(made) == 2 and isinstance(made[0], Node)
                and isinstance(made[1], Executor)):
            return WorkerSpun(ok=False, returned=encode(made))
        node, executor = made
        facts: dict[str, Any] = {'name': node.get_name(), 'executor': type(executor).__name__,
                                 'threads': getattr(executor, '_num_threads', None),
                                 'groups': callback_groups(node)}
        timers = sorted(node.timers, key=lambda timer: timer.timer_period_ns)
        if len(timers) < 2:
            return WorkerSpun(ok=False, timers=len(timers), **facts)
        shown = Shown(command.topic, command.token)
        if not shown.reaches_judge(command.seconds):
            shown.close()
            return WorkerSpun(ok=False, unmatched=True, **facts)
        # the slowest timer is slow_work's, the quickest heartbeat's (part 3: 0.5 s, 0.1 s)
        timers[-1].callback, timers[0].callback = worker_callbacks(shown, command.work_s)
        executor.add_node(node)
        stop = threading.Event()
        failures: list[CallbackFailure] = []

        def spin() -> None:
            while not stop.is_set():
                try:
                    executor.spin_once(timeout_sec=SPIN_ROUND_S)
                except BaseException as error:  # the learner's executor may raise anything
                    failures.append(CallbackFailure(callback=f'{type(node).__name__} callback',
                                                    **describe_error(error)))
                    return

        thread = threading.Thread(target=spin, name='ros2nb-subject-worker', daemon=True)
        self._spun = (node, executor, thread, stop, failures, shown)
        thread.start()
        return WorkerSpun(ok=True, **facts)

    def worker_stop(self, command: WorkerStop) -> WorkerStopped:
        """Stop spinning the learner's worker; the first failure of its callbacks, if any."""
        if self._spun is None:
            return WorkerStopped(ok=True)
        node, executor, thread, stop, failures, shown = self._spun
        self._spun = None
        stop.set()
        thread.join()
        executor.shutdown(timeout_sec=5)
        node.destroy_node()
        shown.close()
        return WorkerStopped(ok=True, failure=failures[0] if failures else None)

    # ------------------------------------------------------------ notebook 07
    def plot_shown(self, command: PlotShown) -> PlotWitnessed:
        """Put the course's ``redraw()`` (:func:`.shown.plot_redraw`, telling ``topic`` with
        ``token``) in place of the given one on the class of the node made last, and wait (at
        most ``seconds``) for the judge's subscription on ``topic`` to match."""
        if self.node is None:
            return PlotWitnessed(ok=False)
        if self._plot_shown is not None:
            self._plot_shown.close()
        self._plot_shown = shown = Shown(command.topic, command.token)
        setattr(type(self.node), 'redraw', plot_redraw(shown))  # the learner's class, not Node
        return PlotWitnessed(ok=shown.reaches_judge(command.seconds), shown=shown.told)

    def room_nodes(self, command: RoomNodes) -> RoomsMade:
        """A stand-in sensor and monitor, each started with ``arguments`` (as ``--ros-args``)."""
        self._runtime()
        made: list[Node] = []
        try:
            for name, kind in (('temperature_sensor', 'publisher'),
                               ('temperature_monitor', 'subscription')):
                node = Node(name, cli_args=[str(a) for a in command.arguments],
                            use_global_arguments=False, start_parameter_services=False)
                if kind == 'publisher':
                    node.create_publisher(Float32, 'temperature', 10)
                else:
                    node.create_subscription(Float32, 'temperature', lambda msg: None, 10)
                made.append(node)
        except BaseException as error:
            for node in made:
                node.destroy_node()
            return RoomsMade(ok=False, error=described(error))
        self.rooms.extend(made)
        return RoomsMade(ok=True, nodes=[(n.get_name(), n.get_namespace(), node_endpoints(n))
                                         for n in made])

    # ------------------------------------------------------------ notebook 09
    def qos_endpoint(self, command: QosEndpoint) -> QosMade:
        """Make a ``kind`` ('subscription' or 'publisher') of Int32 on ``topic`` with the
        profile the learner's ``name()`` returns, and say its history and depth (discovery
        does not carry them).  A subscription takes nothing; a publisher publishes ``numbers``
        (the judge's) at once."""
        function = self.namespace.get(command.name)
        if not callable(function):
            return QosMade(ok=False, undefined=True)
        self._runtime()
        try:
            with zero_depth_refused():
                profile = function()
        except BaseException as error:
            return QosMade(ok=False, error=described(error))
        if not isinstance(profile, QoSProfile):
            return QosMade(ok=False, returned=encode(profile))
        node = Node(QOS_NODE, start_parameter_services=False)
        topic, kind, numbers = command.topic, command.kind, command.numbers
        try:
            if kind == 'subscription':
                endpoint: Any = node.create_subscription(Int32, topic, lambda msg: None, profile)
            else:
                endpoint = node.create_publisher(Int32, topic, profile)
                for number in numbers:
                    endpoint.publish(Int32(data=int(number)))
        except BaseException as error:
            node.destroy_node()
            return QosMade(ok=False, error=described(error))
        self._qos = (node, endpoint)
        return QosMade(ok=True, history=int(profile.history), depth=int(profile.depth))

    def qos_acked(self, command: QosAcked) -> Reply:
        """Wait (at most ``seconds``) until the judge's late joiner matched this publisher and
        acknowledged the burst."""
        if self._qos is None:
            return Reply(ok=False)
        _, publisher = self._qos
        # the judge's joiner matched on its side: wait
        deadline = time.monotonic() + command.seconds
        while publisher.get_subscription_count() < 1 and time.monotonic() < deadline:
            time.sleep(0.01)  # for this side too, or nothing waits to be acknowledged yet
        left = max(0.0, deadline - time.monotonic())
        return Reply(ok=bool(publisher.wait_for_all_acked(Duration(seconds=left))))
