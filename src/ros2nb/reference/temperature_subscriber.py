#!/usr/bin/env python3
"""A temperature monitor: classifies every reading on the temperature topic."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32

TOPIC = 'temperature'
QUEUE_DEPTH = 10
HIGH_ABOVE_C = 26.0   # strictly above: High
LOW_BELOW_C = 20.0    # strictly below: Low


def classify(temperature_c):
    """Return 'High', 'Low' or 'Normal' for a reading in °C."""
    if temperature_c > HIGH_ABOVE_C:
        return 'High'
    if temperature_c < LOW_BELOW_C:
        return 'Low'
    return 'Normal'


class TemperatureMonitor(Node):
    """Logs every reading it receives with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.get_logger().info('Temperature Monitor Node Started')

    def temperature_callback(self, msg):
        temperature_c = msg.data
        self.get_logger().info(
            f'Temperature: {temperature_c:.2f}C - Status: {classify(temperature_c)}')


def main(args=None):
    rclpy.init(args=args)
    node = TemperatureMonitor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()   # the tutorial's subscriber never did this
        rclpy.try_shutdown()  # nor this


if __name__ == '__main__':
    main()
