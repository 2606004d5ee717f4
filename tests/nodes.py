"""Small real nodes the unit tests hand to ros2nb."""

import random
from contextlib import contextmanager
from typing import Iterator

import rclpy
from rclpy.node import Node
from std_msgs.msg import Float32, String

PERIOD_S = 1.0


class Sensor(Node):
    """A 1 Hz random walk on ``topic``, like the course's temperature sensor."""

    def __init__(self, name: str = 'temperature_sensor', topic: str = 'temperature') -> None:
        super().__init__(name)
        self.publisher = self.create_publisher(Float32, topic, 10)
        self.timer = self.create_timer(PERIOD_S, self.tick)
        self.value = 22.0
        self.get_logger().info('started')

    def tick(self) -> None:
        self.value += random.uniform(-0.5, 0.5)
        self.publisher.publish(Float32(data=self.value))
        self.get_logger().info(f'Publishing: {self.value:.2f}C')


class Monitor(Node):
    """Counts and logs what arrives on ``topic``."""

    def __init__(self, name: str = 'temperature_monitor', topic: str = 'temperature') -> None:
        super().__init__(name)
        self.received: list[float] = []
        self.create_subscription(Float32, topic, self.on_message, 10)

    def on_message(self, msg: Float32) -> None:
        self.received.append(msg.data)
        self.get_logger().info(f'Temperature: {msg.data:.2f}C')


class Broken(Node):
    """A node whose timer callback raises every time."""

    def __init__(self) -> None:
        super().__init__('broken')
        self.create_timer(PERIOD_S, self.explode)

    def explode(self) -> None:
        raise ZeroDivisionError('division by zero')


class Chatter(Node):
    """Publishes a String once per second."""

    def __init__(self) -> None:
        super().__init__('chatter_talker')
        self.publisher = self.create_publisher(String, 'chatter', 10)
        self.create_timer(PERIOD_S, lambda: self.publisher.publish(String(data='hi')))


@contextmanager
def name_without_endpoints(name: str, domain_id: int) -> Iterator[Node]:
    """A node called ``name`` on ``domain_id`` with no publisher or subscription, for as long
    as the block.

    What the ROS graph shows after a process ended while its last discovery message was
    still on its way (ros2/ros2#1413): the node's name, none of its publishers or
    subscriptions. That race cannot be started on purpose; this real node, with rosout off
    and its /parameter_events publisher destroyed, shows the graph the same thing (it keeps
    rclpy's type-description service, which the judge does not count).
    """
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain_id)
    node = Node(name, context=context, enable_rosout=False, start_parameter_services=False)
    try:
        for publisher in list(node.publishers):
            node.destroy_publisher(publisher)
        yield node
    finally:
        node.destroy_node()
        rclpy.try_shutdown(context=context)
