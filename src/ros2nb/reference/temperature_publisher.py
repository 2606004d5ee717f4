#!/usr/bin/env python3
"""A simulated temperature sensor: a random walk published on the temperature topic."""

import random

import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32

TOPIC = 'temperature'
QUEUE_DEPTH = 10              # messages kept for a slow subscription
PUBLISH_PERIOD_S = 1.0        # one reading per second
START_TEMPERATURE_C = 22.0    # room temperature
MAX_STEP_C = 0.5              # largest change between two readings
MIN_TEMPERATURE_C = 18.0      # the tutorial's 10.2 was a typo
MAX_TEMPERATURE_C = 28.0


class TemperatureSensor(Node):
    """Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds."""

    def __init__(self):
        super().__init__('temperature_sensor')
        self.publisher_ = self.create_publisher(Float32, TOPIC, QUEUE_DEPTH)
        self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)
        self.temperature = START_TEMPERATURE_C
        self.get_logger().info('Temperature Sensor Node Started')

    def publish_temperature(self):
        step = random.uniform(-MAX_STEP_C, MAX_STEP_C)
        self.temperature = max(MIN_TEMPERATURE_C,
                               min(MAX_TEMPERATURE_C, self.temperature + step))
        msg = Float32()
        msg.data = self.temperature
        self.publisher_.publish(msg)
        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')


def main(args=None):
    rclpy.init(args=args)
    node = TemperatureSensor()
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C or a shutdown from outside: leave quietly
    finally:
        node.destroy_node()
        rclpy.try_shutdown()  # rclpy.shutdown() would raise if Ctrl+C already shut down


if __name__ == '__main__':
    main()
