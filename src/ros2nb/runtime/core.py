"""The kernel's ROS 2 runtime: one rclpy context, its hidden node, its executor thread.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.start`).
:class:`Runtime` is made of four sides, each in a module of its own: its log lines
(:mod:`.logs`), its executor thread (:mod:`.spinning`), its nodes (:mod:`.nodes`) and its
clock (:mod:`.clock`).  The learner's notebook uses the verbs of :mod:`ros2nb.kernel`.
"""

from __future__ import annotations

import os
import sys
from typing import Any, Optional

import rclpy
from rcl_interfaces.msg import Log
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rosgraph_msgs.msg import Clock

from .. import domains
from ..errors import SHUT_DOWN_MESSAGE, Ros2nbError
from .callers import use_cheaper_caller_lookup
from .simulated_clock import SimulatedClock
from .logs import LogLines
from .nodes import NodeKeeping, destroy_stray_nodes, drop_qos_warnings, keep_shared_names
from .spinning import Spinning

#: Hidden name of the kernel's own node (names starting with ``_`` are hidden
#: from ``ros2 node list``, as the ros2cli daemon's are).
INTERNAL_NODE_NAME = '_ros2nb'
#: For ros2nb's own subscriptions: no QoS event handlers (rclpy's default warns of
#: incompatible QoS, which the kernel's own subscriptions choose to accept).
QUIET_SUBSCRIPTION = SubscriptionEventCallbacks(use_default_callbacks=False)
#: For ros2nb's own publishers: no QoS event handlers either.
QUIET_PUBLISHER = PublisherEventCallbacks(use_default_callbacks=False)


def node_serving_nothing(name: str, **kwargs: Any) -> Node:
    """A node of ros2nb's own that offers no services: neither rclpy's six parameter services
    nor its type-description service.  Those seven services are fourteen DDS endpoints that
    every participant of the domain must discover, and seven more entities in each wait of
    the executor, which waits thousands of times a second on simulated time.

    For the kernel's hidden node, the judge's node and the QoS trials' nodes (not for learners).

    Nor does its ``/parameter_events`` publisher (every rclpy node has one) keep rclpy's
    default QoS event handlers: two more entities in each wait, only to warn of a QoS that
    does not match.  The judge's node waited with eight such handlers it never needed, in
    each of the thousands of waits of a simulated hour (what they cost: docs/decisions.md).

    :param name: the node's name.
    :param kwargs: passed on to :class:`rclpy.node.Node` (e.g. ``context``, ``enable_rosout``).
    """
    node = Node(name, start_parameter_services=False,
                parameter_overrides=[Parameter('start_type_description_service',
                                               Parameter.Type.BOOL, False)], **kwargs)
    drop_qos_warnings(node)
    return node


def enable_field_checks() -> None:
    """Turn on rosidl's generated type/range checks, also for already imported messages."""
    os.environ['ROS_PYTHON_CHECK_FIELDS'] = '1'
    for module in list(sys.modules.values()):
        if getattr(module, 'ros_python_check_fields', None) == '':
            setattr(module, 'ros_python_check_fields', '1')


class Runtime(LogLines, Spinning, NodeKeeping, SimulatedClock):
    """The kernel's ROS 2 runtime: rclpy context, one executor, one spin thread.

    Create it with :func:`ros2nb.start`; use the module-level functions, not this class.
    A check's subject makes one of its own, without the background thread.

    :param domain_id: the ROS domain.
    :param sim_time: the kernel's clock: simulated (True) or wall-clock time.
    :param background: spin in a background thread (False: only in :meth:`drain`).
    """

    def __init__(self, *, domain_id: int, sim_time: bool, background: bool = True) -> None:
        LogLines.__init__(self)
        Spinning.__init__(self, background)
        NodeKeeping.__init__(self)
        SimulatedClock.__init__(self, sim_time)
        self._participant: Optional[bytes] = None
        use_cheaper_caller_lookup()  # the same /rosout messages, without reading source files
        domains.use_discovery_profile()  # also with a domain given: read as ROS comes up
        rclpy.init(args=['--ros-args', '--disable-stdout-logs', '--disable-external-lib-logs'],
                   domain_id=domain_id, signal_handler_options=SignalHandlerOptions.NO)
        self.context = rclpy.get_default_context()
        keep_shared_names(self.context)  # no node of a name in use freed under the others
        self.domain_id = self.context.get_domain_id()
        self.executor = SingleThreadedExecutor()
        # The kernel's own node serves nothing and logs nothing.
        self.node = node_serving_nothing(INTERNAL_NODE_NAME, enable_rosout=False)
        self._clock_publisher = self.node.create_publisher(
            Clock, '/clock', 10, event_callbacks=QUIET_PUBLISHER)
        if self.judge_time is None:  # a judge's subject shows no lines: the judge hears them
            # itself, and a flood of the learner's cost the subject as much again to hear
            rosout_qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                                    durability=DurabilityPolicy.TRANSIENT_LOCAL)
            self.node.create_subscription(Log, '/rosout', self._on_log, rosout_qos,
                                          event_callbacks=QUIET_SUBSCRIPTION)
        self.executor.add_node(self.node)
        self.follow_judge_clock()  # in a judge's subject only: the judge's time from now on
        self.start_spinning()

    @property
    def alive(self) -> bool:
        """False once ROS was shut down under ros2nb (e.g. by ``rclpy.shutdown()``)."""
        return self.context.ok() and not self._stopping

    def ensure_alive(self) -> None:
        """:raises Ros2nbError: when ROS 2 was shut down under ros2nb."""
        if not self.alive:
            raise Ros2nbError(SHUT_DOWN_MESSAGE)

    def participant_prefix(self) -> Optional[bytes]:
        """This process's DDS participant: the first 12 bytes of its endpoints' GIDs."""
        if self._participant is None:
            for info in self.node.get_publishers_info_by_topic('/clock'):
                if info.node_name == INTERNAL_NODE_NAME:
                    self._participant = bytes(info.endpoint_gid[:12])
        return self._participant

    def shutdown(self) -> None:
        """Stop every node, stop the executor, join its thread and shut rclpy down."""
        self.stop_spinning()
        self._destroy_all_nodes()
        self.executor.remove_node(self.node)
        self.node.destroy_node()
        self.executor.shutdown()
        destroy_stray_nodes(self.context)
        rclpy.try_shutdown()
