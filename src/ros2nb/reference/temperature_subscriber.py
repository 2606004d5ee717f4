#!/usr/bin/env python3
"""A temperature monitor: judges every reading on the temperature topic."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32

TOPIC = 'temperature'
QUEUE_DEPTH = 10              # messages kept while the callback is busy
HIGH_ABOVE_C = 26.0           # strictly above: High
LOW_BELOW_C = 20.0            # strictly below: Low


class TemperatureMonitor(Node):
    """Logs every reading it receives with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        # 1. a subscription to Float32 messages on TOPIC that calls
        #    self.temperature_callback, QUEUE_DEPTH deep -> self.subscription
        # 2. one log line saying that the node started
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.get_logger().info('Temperature Monitor Node Started')

    def temperature_callback(self, msg):
        # 1. the reading is in msg.data
        # 2. its status: 'High' strictly above HIGH_ABOVE_C, 'Low' strictly below
        #    LOW_BELOW_C, 'Normal' otherwise (20.0 and 26.0 included)
        # 3. log one line with the reading (two decimals) and the status,
        #    e.g. 'Temperature: 23.00C - Status: Normal'
        temperature_c = msg.data
        if temperature_c > HIGH_ABOVE_C:
            status = 'High'
        elif temperature_c < LOW_BELOW_C:
            status = 'Low'
        else:
            status = 'Normal'
        self.get_logger().info(f'Temperature: {temperature_c:.2f}C - Status: {status}')


def main(args=None):
    # as for the sensor: bring rclpy up, create the node, spin it until Ctrl+C or a
    # shutdown from outside, then destroy the node and shut rclpy down safely
    rclpy.init(args=args)
    node = TemperatureMonitor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C or a shutdown from outside: leave quietly
    finally:
        node.destroy_node()   # the tutorial's subscriber never did this
        rclpy.try_shutdown()  # nor this


if __name__ == '__main__':
    main()
