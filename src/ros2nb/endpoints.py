"""A node's endpoints and a message type's ROS name: the words the kernel, the checks
and the judge share.

No ROS import: these read the objects rclpy gives them.
"""

from __future__ import annotations

from typing import Any


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
