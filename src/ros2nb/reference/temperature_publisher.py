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
        # 1. a publisher of Float32 messages on TOPIC, QUEUE_DEPTH deep -> self.publisher_
        # 2. a timer calling self.publish_temperature every PUBLISH_PERIOD_S -> self.timer
        # 3. the walk starts at START_TEMPERATURE_C -> self.temperature
        # 4. one log line saying that the node started
        self.publisher_ = self.create_publisher(Float32, TOPIC, QUEUE_DEPTH)
        self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)
        self.temperature = START_TEMPERATURE_C
        self.get_logger().info('Temperature Sensor Node Started')

    def publish_temperature(self):
        # 1. a random step between -MAX_STEP_C and +MAX_STEP_C
        # 2. add it to self.temperature, clamped into [MIN_TEMPERATURE_C, MAX_TEMPERATURE_C]
        # 3. a Float32 message carrying self.temperature, handed to self.publisher_
        # 4. log the reading with two decimals, e.g. 'Publishing: 22.31C'
        step = random.uniform(-MAX_STEP_C, MAX_STEP_C)
        self.temperature = max(MIN_TEMPERATURE_C,
                               min(MAX_TEMPERATURE_C, self.temperature + step))
        msg = Float32()
        msg.data = self.temperature
        self.publisher_.publish(msg)
        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')


def main(args=None):
    # 1. bring rclpy up with args, then create the node
    # 2. spin it until Ctrl+C (KeyboardInterrupt) or a shutdown from outside
    #    (ExternalShutdownException); both end the program quietly
    # 3. however the spin ended: destroy the node, then shut rclpy down safely
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
