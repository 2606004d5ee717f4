"""Small real nodes the unit tests hand to ros2nb."""

import os
import random
import subprocess
import sys
import time
from contextlib import contextmanager
from typing import Any, Iterator

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


#: A program that makes one node named ``argv[1]``, prints the moment it was made
#: (``time.monotonic()``, one clock for every process of the machine) and leaves ROS cleanly
#: when its standard input ends, as the course's processes end.
NEWCOMER = '''
import sys, time
import rclpy
rclpy.init()
node = rclpy.create_node(sys.argv[1])
print(time.monotonic(), flush=True)
sys.stdin.read()
node.destroy_node()
rclpy.shutdown()
'''


def join_times(observer: Any, count: int, env: dict[str, str]) -> list[float]:
    """Seconds each of ``count`` new processes' node (started one after another, each with
    ``env``) took to appear in the judge's graph (``observer``, a
    :class:`ros2nb.judge.observer.Observer`), counted from when the process made it; 30
    when it never did within 30 s."""
    times = []
    for index in range(count):
        name = f'newcomer_{os.getpid()}_{index}'
        proc = subprocess.Popen([sys.executable, '-c', NEWCOMER, name], env=env, text=True,
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE)
        try:
            made = float(proc.stdout.readline())
            observer.attending = lambda: [proc.pid]  # its discovery is its work
            seen = observer.wait_until(lambda: observer.has_node(name), 30.0)
            times.append(time.monotonic() - made if seen else 30.0)
        finally:
            proc.communicate('', timeout=30)
    return times
