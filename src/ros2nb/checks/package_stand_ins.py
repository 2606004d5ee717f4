"""The grader's stand-in nodes for notebook 05's build: the package is graded on its own.

Part of :mod:`ros2nb.checks` (:mod:`ros2nb.checks.lesson05` builds them into a copy of the
learner's package in place of ``temperature_publisher.py`` and ``temperature_subscriber.py``).
"""

from __future__ import annotations

from .. import course

#: How a stand-in takes rclpy's own race at Ctrl+C: as the end of the spin.  rclpy (Jazzy) shuts
#: the context down from a thread of its own, and the KeyboardInterrupt reaches the spin a
#: moment later; a callback, or the spin's next wait, that runs in between fails on the invalid
#: context (RCLError, a RuntimeError), as ros2cli also finds (ros2/ros2cli#854).  The stand-ins,
#: busy five times a second, meet it on a busy machine, and the learner would lose the point
#: to rclpy; with this clause they do not (docs/decisions.md).  (A learner's main() that
#: meets it is run again with the course's stand-in node: mains.run_main.)
RCLPY_SHUTDOWN_RACE = '''\
    except RuntimeError:  # Ctrl+C shut rclpy down while it worked: rclpy's race, not a fault
        if rclpy.ok():
            raise
'''
#: The grader's own stand-in nodes, so notebook 05 is graded on its own: they take the
#: place of temperature_publisher.py and temperature_subscriber.py in the judge's build.
#: The sensor publishes the number given as its parameter ``reading`` five times a second;
#: the monitor logs every reading it hears.  ``race``: :data:`RCLPY_SHUTDOWN_RACE`.
STAND_IN = '''\
"""Grader's stand-in {name}: a node that only {does}."""
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32


def main(args=None):
    rclpy.init(args=args)
    node = Node('{name}')
    {setup}
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
{race}    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''
STAND_IN_PUBLISHER = STAND_IN.format(
    name=course.SENSOR_NODE, does='publishes the reading it is given, five times a second',
    race=RCLPY_SHUTDOWN_RACE,
    setup="reading = node.declare_parameter('reading', 0.0).value\n"
          "    publisher = node.create_publisher(Float32, 'temperature', 10)\n"
          "    node.create_timer(0.2, lambda: publisher.publish(Float32(data=reading)))")
STAND_IN_SUBSCRIBER = STAND_IN.format(
    name=course.MONITOR_NODE, does='logs every reading it hears', race=RCLPY_SHUTDOWN_RACE,
    setup="node.create_subscription(Float32, 'temperature',\n"
          "                             lambda m: "
          "node.get_logger().info(f'heard {m.data:.3f}'), 10)")
#: The two executables, the module of each, and the grader's stand-in for it.
EXECUTABLES = ((course.PUBLISHER_EXECUTABLE, STAND_IN_PUBLISHER),
               (course.SUBSCRIBER_EXECUTABLE, STAND_IN_SUBSCRIBER))
