"""Three small pieces for the promises of notebook 06: counting, a busy worker, rooms."""

import time

from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from std_msgs.msg import Float32
from std_srvs.srv import Trigger

TOPIC = 'temperature'
QUEUE_DEPTH = 10
HEARTBEAT_PERIOD_S = 0.1      # the worker's quick timer: 10 Hz
SLOW_PERIOD_S = 0.5           # the worker's slow timer, whose callback waits for ...
SLOW_SERVICE = 'slow_job'     # ... the answer of this service, ...
SLOW_WORK_S = 0.45            # ... which works this long before it answers


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


class SlowJob(Node):
    """Another node's long job: its service answers each call after SLOW_WORK_S seconds."""

    def __init__(self, name='slow_job'):
        super().__init__(name)
        self.service = self.create_service(Trigger, SLOW_SERVICE, self.work)

    def work(self, request, response):
        time.sleep(SLOW_WORK_S)   # stands for a long computation
        response.success = True
        return response


class Worker(Node):
    """A node with a slow timer and a quick one; the callback groups are chosen by the caller."""

    def __init__(self, name='worker', slow_group=None, heartbeat_group=None):
        super().__init__(name)
        # the slow job's answers come in a group of their own, which neither timer holds
        self.slow_client = self.create_client(Trigger, SLOW_SERVICE,
                                              callback_group=MutuallyExclusiveCallbackGroup())
        self.slow_timer = self.create_timer(SLOW_PERIOD_S, self.slow_work,
                                            callback_group=slow_group)
        self.heartbeat_timer = self.create_timer(HEARTBEAT_PERIOD_S, self.heartbeat,
                                                 callback_group=heartbeat_group)

    def slow_work(self):
        self.get_logger().info('slow work: start')
        self.slow_client.call(Trigger.Request())   # waits for the slow job's answer
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
