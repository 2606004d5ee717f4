"""Checks of notebook 00, the set-up and the pub/sub idea: a node's endpoint.

Part of :mod:`ros2nb.checks`.  In the kernel the learner's class is created there (ROS
must be up); the judge creates it from the learner's answer cell in a subject and reads
the ROS graph.
"""

from __future__ import annotations

from typing import Any, Optional

import rclpy
from rclpy.node import Node

from ..endpoints import node_endpoints
from ..errors import CheckFailed
from ..judge_interface import AnswerRef, Judge
from ..subject_interface import NewNode
from .base import call_learner, direct
from .file_nodes import raised
from .verdicts import endpoint_verdict


def require_ros() -> None:
    """Raise CheckFailed when ROS is not running in this kernel (e.g. after rclpy.shutdown())."""
    if not rclpy.ok():
        raise CheckFailed('ROS 2 is not running in this kernel (was rclpy.shutdown() called?): '
                          'run ros2nb.shutdown(); ros2nb.start() and this cell again.')


@direct
def check_endpoint(judge: Optional[Judge], node_class: Any, kind: str, topic: str,
                   type_name: str) -> str:
    """Check that a node class makes a publisher or subscription on ``topic`` with ``type_name``.

    In the kernel the node is created, inspected and destroyed again (ROS must be up);
    the grader creates it in a process of its own and reads the ROS graph.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node_class: the class, e.g. ``LoudListener`` (no parentheses).
    :param kind: ``'publisher'`` or ``'subscription'``.
    :param topic: e.g. ``'/chatter'``.
    :param type_name: e.g. ``'std_msgs/msg/String'``.
    :raises CheckFailed: naming what the node has instead.
    """
    if isinstance(node_class, AnswerRef) and judge is not None:
        name, found, made = _answer_node_endpoints(judge, node_class)
    else:
        name, found = _kernel_node_endpoints(node_class)
        made = found
    endpoint_verdict(name, found, kind, topic, type_name, made)
    return f'{name} has a {kind} on {topic} [{type_name}].'


def _kernel_node_endpoints(node_class: Any) -> tuple[str, list[tuple[str, str, str]]]:
    require_ros()
    node = call_learner(node_class)
    if not isinstance(node, Node):
        raise CheckFailed(f'Expected a node, got {type(node).__name__}: pass your Node '
                          'subclass itself, e.g. LoudListener (no parentheses).')
    try:
        return node.get_name(), node_endpoints(node)
    finally:
        node.destroy_node()


def _answer_node_endpoints(judge: Judge, ref: AnswerRef
                          ) -> tuple[str, list[tuple[str, str, str]], list[tuple[str, str, str]]]:
    subject = judge.answer_subject(ref)
    reply = subject.request(NewNode(cls=ref.name))
    if reply.no_class:
        raise CheckFailed(f'{ref.name} is not defined in your answer cell as a Node subclass.')
    if reply.refused:
        raise CheckFailed(reply.refused)
    if not reply.ok:
        raise raised(f'{ref.name}()', reply.error)
    found = judge.observer.endpoints(reply.name, reply.namespace, reply.endpoints)
    return reply.name, found, list(reply.endpoints)
