#!/usr/bin/env python3
"""A fan controller: switches a fan on while the temperature is High."""

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Bool, Float32

TOPIC = 'temperature'
FAN_TOPIC = 'fan_command'     # True: fan on, False: fan off
QUEUE_DEPTH = 10
HIGH_ABOVE_C = 26.0           # strictly above: High, the fan goes on


class FanController(Node):
    """Publishes one fan command for every reading it hears."""

    def __init__(self):
        super().__init__('fan_controller')
        # 1. subscription: Float32 on TOPIC -> self.temperature_callback, QUEUE_DEPTH deep
        # 2. publisher: Bool on FAN_TOPIC, QUEUE_DEPTH deep -> self.publisher_
        # 3. a log line saying that the node started
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.publisher_ = self.create_publisher(Bool, FAN_TOPIC, QUEUE_DEPTH)
        self.get_logger().info('Fan Controller Node Started')

    def temperature_callback(self, msg):
        # publish one Bool: True strictly above HIGH_ABOVE_C, False otherwise
        command = Bool()
        command.data = msg.data > HIGH_ABOVE_C
        self.publisher_.publish(command)
        self.get_logger().info(f'Fan {"on" if command.data else "off"} at {msg.data:.2f}C')


def main(args=None):
    # bring rclpy up, create the node, spin it until Ctrl+C or a shutdown from outside,
    # then destroy the node and shut rclpy down safely
    rclpy.init(args=args)
    node = FanController()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
