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

import inspect
import os
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
from ..patience import wait_for_work
from ..runtime.rates import callback_groups, track_calls
from ..subject_interface import (PlotShown, QosAcked, QosEndpoint, RoomNodes, Worker,
                                 WorkerStop)
from ..subject_replies import (CallbackFailure, PlotWitnessed, QosMade, Reply, RoomsMade,
                               WorkerSpun, WorkerStopped)
from .replies import described, encode
from .shown import Shown, plot_redraw

#: The node that makes an endpoint with the learner's QoS profile (notebook 09).
QOS_NODE = 'qos_answer'
#: Wall-clock seconds one spin of the learner's executor waits for work (notebook 06).
SPIN_ROUND_S = 0.05


def _spin(node: Node, executor: Executor, stop: threading.Event,
          failures: list[CallbackFailure]) -> None:
    """Spin the learner's ``executor`` until ``stop``, its first failure kept (notebook 06)."""
    while not stop.is_set():
        try:
            executor.spin_once(timeout_sec=SPIN_ROUND_S)
        except BaseException as error:  # the learner's executor may raise anything
            failures.append(CallbackFailure(callback=f'{type(node).__name__} callback',
                                            **describe_error(error)))
            return


class Trials:
    """Commands of notebooks 06 and 09; the state lives in :class:`~.process.Subject`."""

    namespace: dict[str, Any]
    rooms: list[Node]
    node: Optional[Node]
    _spun: Optional[tuple[Node, Executor, threading.Thread, threading.Event,
                          list[CallbackFailure], list[Any]]]
    _qos: Optional[tuple[Node, Any]]
    _plot_shown: Optional[Shown] = None

    def _runtime(self) -> Any:  # provided by Subject
        raise NotImplementedError

    # ------------------------------------------------------------ notebook 06
    def worker(self, command: Worker) -> WorkerSpun:
        """Call the learner's ``name()`` for ``(node, executor)`` and spin that executor with
        that node, as it is, on the wall clock, in a thread until :meth:`worker_stop`: once
        the node's service clients have found their servers (``seconds`` at most: a request
        sent before would be lost), for the slow job is the judge's to answer.

        Nothing of the course's runs in the worker: the judge holds its slow job open and
        listens for the heartbeat meanwhile, from outside this process.
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
        timers = list(node.timers)
        facts: dict[str, Any] = {'name': node.get_name(), 'namespace': node.get_namespace(),
                                 'executor': type(executor).__name__,
                                 'threads': getattr(executor, '_num_threads', None),
                                 'groups': callback_groups(node),
                                 'coroutines': [getattr(t.callback, '__name__', '?')
                                                for t in timers
                                                if inspect.iscoroutinefunction(t.callback)]}
        if len(timers) < 2:
            return WorkerSpun(ok=False, timers=len(timers), **facts)
        # Discovery is this process's work: waited for while it works or waits for a CPU, and
        # given up after ``seconds`` of sitting idle (ros2nb.patience), never of a busy machine.
        if not wait_for_work(lambda: all(c.service_is_ready() for c in node.clients),
                             [os.getpid()], command.seconds):
            return WorkerSpun(ok=False, unmatched=True, **facts)
        stop = threading.Event()
        failures: list[CallbackFailure] = []
        calls: list[Any] = []
        for client in node.clients:  # to end, at the stop, a call no executor can answer
            track_calls(client, calls)
        thread = threading.Thread(target=_spin, args=(node, executor, stop, failures),
                                  name='ros2nb-subject-worker', daemon=True)
        executor.add_node(node)
        self._spun = (node, executor, thread, stop, failures, calls)
        thread.start()
        return WorkerSpun(ok=True, **facts)

    def worker_stop(self, command: WorkerStop) -> WorkerStopped:
        """Stop spinning the learner's worker; the first failure of its callbacks, if any."""
        if self._spun is None:
            return WorkerStopped(ok=True)
        node, executor, thread, stop, failures, calls = self._spun
        self._spun = None
        stop.set()
        # A callback that waits for a call's answer its executor can never take (a
        # SingleThreadedExecutor, or every thread of one waiting) returns once it is cancelled.
        for future in list(calls):
            future.cancel()
        thread.join()
        executor.shutdown(timeout_sec=5)
        node.destroy_node()
        return WorkerStopped(ok=True, failure=failures[0] if failures else None)

    # ------------------------------------------------------------ notebook 07
    def plot_shown(self, command: PlotShown) -> PlotWitnessed:
        """Put the course's ``redraw()`` (:func:`.shown.plot_redraw`, telling ``topic`` what
        it drew) in place of the given one on the class of the node made last, and wait (at
        most ``seconds``) for the judge's subscription on ``topic`` to match."""
        if self.node is None:
            return PlotWitnessed(ok=False)
        if self._plot_shown is not None:
            self._plot_shown.close()
        self._plot_shown = shown = Shown(command.topic)
        # the learner's class, not Node
        setattr(type(self.node), 'redraw', plot_redraw(shown))
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
