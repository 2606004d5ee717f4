"""Mistakes refused before they run: when a node is handed over, or an endpoint is created.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.add`).
:func:`check_node` refuses, with one line, a node that would fail or mislead once it runs;
:func:`guard_endpoint_types` makes ``create_publisher``/``create_subscription`` refuse a
second message type on a topic in this process (rcl would print a C error dump).
"""

from __future__ import annotations

from typing import Any, Callable, Optional

from rclpy.exceptions import InvalidHandle
from rclpy.node import Node
from rclpy.subscription import Subscription

from ..endpoints import type_name
from ..errors import Ros2nbError


def _callback_name(callback: Any) -> str:
    return getattr(callback, '__qualname__', repr(callback))


def check_node(node: Any, rt: Any) -> None:
    """Refuse, with one line, a node that would fail or mislead once it runs.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.add`).

    :param node: what was handed to :func:`ros2nb.add`.
    :param rt: the kernel's runtime.
    :raises Ros2nbError: naming the mistake and the fix.
    """
    if isinstance(node, type) and issubclass(node, Node):
        raise Ros2nbError(f'ros2nb.add() takes a node, not the class {node.__name__}: create '
                          f'one first, ros2nb.add({node.__name__}()).')
    if not isinstance(node, Node):
        raise Ros2nbError(f'ros2nb.add() takes an rclpy Node, not {type(node).__name__}: create '
                          'the node first, e.g. ros2nb.add(TemperatureSensor()).')
    if not hasattr(node, '_Node__node'):
        raise Ros2nbError(f"{type(node).__name__}.__init__ never calls "
                          "super().__init__('node_name'): make that its first line.")
    try:
        name = node.get_name()
    except InvalidHandle:
        raise Ros2nbError(f'This {type(node).__name__} was destroyed (by ros2nb.stop() or '
                          'destroy_node()): create a new one, then hand it over.') from None
    if node.context is not rt.context or not node.context.ok():
        raise Ros2nbError(f'{name} was created before ROS 2 was (re)started in this kernel: run '
                          'the cell that creates it again, then hand it over.')
    for timer in node.timers:
        if not callable(timer.callback):
            raise Ros2nbError(f'{name} has a timer whose callback is {timer.callback!r}, not a '
                              'function: pass the method itself (self.publish_temperature, '
                              'without the parentheses).')
        if timer.timer_period_ns == 0:
            raise Ros2nbError(f'{name} has a timer with a period of 0 s for '
                              f'{_callback_name(timer.callback)}: it would fire without pause; '
                              'give create_timer a period in seconds, e.g. 1.0.')
    for kind, entities in (('publisher', node.publishers), ('subscription', node.subscriptions)):
        for entity in entities:
            if not isinstance(entity.msg_type, type):
                cls = type(entity.msg_type).__name__
                raise Ros2nbError(f'{name} made a {kind} on {entity.topic_name} with a message '
                                  f'{cls}() instead of the message type: pass {cls} without '
                                  'the parentheses.')
            if isinstance(entity, Subscription) and not callable(entity.callback):
                raise Ros2nbError(f'{name} has a subscription on {entity.topic_name} whose '
                                  f'callback is {entity.callback!r}: pass the method itself, '
                                  'without the parentheses.')
    _check_types_agree(node, rt)


def _check_types_agree(node: Any, rt: Any) -> None:
    """Refuse a node whose topic type differs from what another node of this process uses.

    Only this process's own endpoints count (by DDS participant): they are known at once,
    so the same node always gets the same sentence.  Whether a node of another process
    (``ros2 run``, a check's judge) has been discovered yet depends on timing; that kind of
    mismatch is the graph's business (:func:`ros2nb.topic_list` notes it).
    """
    name = node.get_name()
    graph = rt.node
    local = rt.participant_prefix()
    for kind, entities in (('publishes', node.publishers), ('subscribes to', node.subscriptions)):
        for entity in entities:
            topic = node.resolve_topic_name(entity.topic_name)
            mine = type_name(entity.msg_type)
            others = sorted([*graph.get_publishers_info_by_topic(topic),
                             *graph.get_subscriptions_info_by_topic(topic)],
                            key=lambda e: (e.node_name, e.topic_type))
            for info in others:  # hidden nodes (ros2nb's, a check's, not yet named) aside
                if info.node_name == name or info.node_name.startswith('_') \
                        or info.topic_type == mine or bytes(info.endpoint_gid[:12]) != local:
                    continue
                role = 'publishes' if 'PUBLISHER' in str(info.endpoint_type) else 'subscribes to'
                raise Ros2nbError(f'{name} {kind} {topic} as {mine}, but {info.node_name} {role} '
                                  f'it as {info.topic_type}: both sides of a topic must use the '
                                  'same message type.')


# --------------------------------------------------------------- checks at creation
_GUARDED = '_ros2nb_guarded'


def _refuse_other_type(node: Any, kind: str, msg_type: Any, topic: str,
                       local: Optional[bytes]) -> None:
    """Raise before rcl would fail with ``invalid allocator`` and a C error dump.

    That happens when an endpoint of this very process already uses the topic with another
    type; endpoints of other processes are the graph's business (``topic_list`` notes them).
    """
    if not isinstance(msg_type, type) or not hasattr(node, '_Node__node'):
        return  # rclpy's own error (or check_node at add()) says it better
    try:
        name = node.resolve_topic_name(topic)
        endpoints = [*node.get_publishers_info_by_topic(name),
                     *node.get_subscriptions_info_by_topic(name)]
    except Exception:  # an invalid name: rclpy's own message, with its caret, is best
        return
    mine = type_name(msg_type)
    others = sorted({e.topic_type for e in endpoints if bytes(e.endpoint_gid[:12]) == local
                     and e.topic_type != mine})
    if local is not None and others:
        verb = 'publish on' if kind == 'publisher' else 'subscribe to'
        raise Ros2nbError(f'{node.get_name()} would {verb} {name} as {mine}, but {name} already '
                          f'carries {", ".join(others)} in this kernel: both sides of a topic '
                          'must use the same message type.')


def guard_endpoint_types(local_prefix: Callable[[], Optional[bytes]]) -> None:
    """Make ``create_publisher``/``create_subscription`` refuse a second type on a topic.

    In one process rcl refuses such an endpoint with ``invalid allocator`` after printing a
    C error dump; across processes the two sides simply never meet.  Installed by
    :func:`ros2nb.start` in a notebook, so the learner gets one line instead, at their line.
    Installing it again changes nothing.

    :param local_prefix: returns the DDS participant prefix of this process's ROS (None
        while ROS is down): endpoints with it are this process's own.
    """
    for method, kind in (('create_publisher', 'publisher'),
                         ('create_subscription', 'subscription')):
        original = getattr(Node, method)
        if getattr(original, _GUARDED, False):
            continue

        def guarded(self: Any, *args: Any, _original: Any = original, _kind: str = kind,
                    **kwargs: Any) -> Any:
            # rclpy's own signature refuses arguments left out or too many, in its own name
            msg_type = args[0] if args else kwargs.get('msg_type')
            topic = args[1] if len(args) > 1 else kwargs.get('topic')
            if isinstance(topic, str):
                _refuse_other_type(self, _kind, msg_type, topic, local_prefix())
            return _original(self, *args, **kwargs)

        guarded.__doc__, guarded.__name__ = original.__doc__, method
        guarded.__qualname__ = original.__qualname__
        setattr(guarded, _GUARDED, True)
        setattr(Node, method, guarded)
