"""Three small pieces for the promises of notebook 06: counting, a busy worker, rooms."""

import time

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float32

TOPIC = 'temperature'
QUEUE_DEPTH = 10
HEARTBEAT_PERIOD_S = 0.1      # the worker's quick timer: 10 Hz
SLOW_PERIOD_S = 0.5           # the worker's slow timer ...
SLOW_WORK_S = 0.45            # ... whose callback works (sleeps) this long


class CountingMonitor(Node):
    """A monitor that only counts the readings it receives."""

    def __init__(self, name='counting_monitor'):
        super().__init__(name)
        # self.received starts at 0; a subscription to Float32 on TOPIC that calls
        # self.count, QUEUE_DEPTH deep -> self.subscription
        self.received = 0
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.count, QUEUE_DEPTH)

    def count(self, msg):
        # add one to self.received, then log the new count
        self.received += 1
        self.get_logger().info(f'received {self.received}')


class Worker(Node):
    """A node with a slow timer and a quick one; the callback groups are chosen by the caller."""

    def __init__(self, name='worker', slow_group=None, heartbeat_group=None):
        super().__init__(name)
        self.slow_timer = self.create_timer(SLOW_PERIOD_S, self.slow_work,
                                            callback_group=slow_group)
        self.heartbeat_timer = self.create_timer(HEARTBEAT_PERIOD_S, self.heartbeat,
                                                 callback_group=heartbeat_group)

    def slow_work(self):
        self.get_logger().info('slow work: start')
        time.sleep(SLOW_WORK_S)   # stands for a long computation
        self.get_logger().info('slow work: done')

    def heartbeat(self):
        self.get_logger().info('heartbeat')   # stands for a quick, regular job


def responsive_worker():
    """Return (node, executor): a Worker whose timers may overlap, and a multi-threaded executor."""
    node = Worker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup(),
                  heartbeat_group=MutuallyExclusiveCallbackGroup())
    executor = MultiThreadedExecutor(num_threads=2)
    return node, executor


def room_arguments(room):
    """Return the arguments that run a node in the namespace /<room>."""
    return ['--ros-args', '-r', f'__ns:=/{room}']
