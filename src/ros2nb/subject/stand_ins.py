"""The course's own version of each part a check does not grade, put in place of the learner's.

Introduced in ``03-write-the-publisher.ipynb``.  A check grades one part of a node: the
constructor, or the callback, or ``main()``.  So that a mistake in one part costs only
that part's points, the judge may run the learner's class with another part replaced by
the one here (``new_node(..., stand_ins=[...])``, :mod:`ros2nb.subject.commands`), or
``main()`` with a whole stand-in node (:mod:`ros2nb.subject.program`).  A stand-in never
counts for the learner: it only makes room for their own part to be seen.

This module is an answer: the subject refuses it to the learner's code and imports it only
after that code is loaded, and keeps it out of ``sys.modules`` (:mod:`.out_of_reach`).

Each function is written for a class of the learner's (no ``super()``: the class it ends up
in is made on the fly).  The callbacks find the node's publisher by its topic, so a
learner's constructor that names its attribute differently still works with them.
"""

from __future__ import annotations

import random
from typing import Any, Callable

from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from std_msgs.msg import Bool, Float32

from .. import course
from ..rules import monitor_status


def _publisher_on(node: Node, topic: str) -> Any:
    """The node's publisher on ``topic`` (relative to its namespace), whatever its attribute."""
    full = node.resolve_topic_name(topic)
    found = [p for p in node.publishers if p.topic_name == full]
    if not found:
        raise AttributeError(f'{node.get_name()} has no publisher on {full}')
    return found[-1]


#: The learner's node class a stand-in method is put on: a Node subclass with attributes of
#: its own (``publisher_``, ``temperature``, ...), which no type declares.
LearnersNode = Any


# ------------------------------------------------------------------ notebook 03: the sensor
def sensor_init(self: LearnersNode) -> None:
    """Part 3 of temperature_publisher.py: name, publisher, timer, start value, a log line."""
    Node.__init__(self, course.SENSOR_NODE)
    self.publisher_ = self.create_publisher(Float32, course.TOPIC, course.QUEUE_DEPTH)
    self.timer = self.create_timer(course.PUBLISH_PERIOD_S, self.publish_temperature)
    self.temperature = course.START_TEMPERATURE_C
    self.get_logger().info('Temperature Sensor Node Started')


def sensor_callback(self: LearnersNode) -> None:
    """Part 4 of temperature_publisher.py: one step of the walk, clamped, published, logged.

    Does nothing on a node without ``temperature`` (a constructor that calls it before it
    sets the walk's start, or keeps the walk under another name): the learner's own
    callback is then tried instead.
    """
    if not hasattr(self, 'temperature'):
        return
    step = random.uniform(-course.MAX_STEP_C, course.MAX_STEP_C)
    self.temperature = max(course.MIN_TEMPERATURE_C,
                           min(course.MAX_TEMPERATURE_C, self.temperature + step))
    _publisher_on(self, course.TOPIC).publish(Float32(data=self.temperature))
    self.get_logger().info(f'Publishing: {self.temperature:.2f}C')


# ------------------------------------------------------------------ notebook 04: the monitor
def monitor_init(self: LearnersNode) -> None:
    """Part 3 of temperature_subscriber.py: name, subscription, a log line."""
    Node.__init__(self, course.MONITOR_NODE)
    self.subscription = self.create_subscription(Float32, course.TOPIC,
                                                 self.temperature_callback, course.QUEUE_DEPTH)
    self.get_logger().info('Temperature Monitor Node Started')


def monitor_callback(self: LearnersNode, msg: Float32) -> None:
    """Part 4 of temperature_subscriber.py: one line with the reading and its status."""
    self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: '
                           f'{monitor_status(msg.data)}')


# ------------------------------------------------------------------ notebook 06: the fan
def fan_init(self: LearnersNode) -> None:
    """Part 2 of fan_controller.py, its constructor."""
    Node.__init__(self, course.FAN_NODE)
    self.subscription = self.create_subscription(Float32, course.TOPIC,
                                                 self.temperature_callback, course.QUEUE_DEPTH)
    self.publisher_ = self.create_publisher(Bool, course.FAN_TOPIC, course.QUEUE_DEPTH)
    self.get_logger().info('Fan Controller Node Started')


def fan_callback(self: LearnersNode, msg: Float32) -> None:
    """Part 2 of fan_controller.py, its callback: one command per reading."""
    _publisher_on(self, course.FAN_TOPIC).publish(Bool(data=msg.data > course.HIGH_ABOVE_C))


# ------------------------------------------------------------------ notebook 08: parameters
def thresholds_init(self: LearnersNode) -> None:
    """Part 3 of notebook 08's monitor: both thresholds declared, the on-set callback
    registered, the subscription (its callback, given in the notebook, reads them)."""
    Node.__init__(self, course.MONITOR_NODE)
    in_range = [FloatingPointRange(from_value=course.MIN_TEMPERATURE_C,
                                   to_value=course.MAX_TEMPERATURE_C)]
    for name, default in course.THRESHOLD_DEFAULTS_C.items():
        self.declare_parameter(name, default, ParameterDescriptor(
            description=f'{name} in °C', floating_point_range=in_range))
    self.add_on_set_parameters_callback(self.on_set_thresholds)
    self.subscription = self.create_subscription(Float32, course.TOPIC,
                                                 self.temperature_callback, course.QUEUE_DEPTH)
    self.get_logger().info('Temperature Monitor Node Started')


def thresholds_on_set(self: LearnersNode, parameters: list) -> SetParametersResult:
    """Part 4 of notebook 08's monitor: a change that leaves ``low_below_c`` at or above
    ``high_above_c`` is refused, with a reason."""
    new = {parameter.name: parameter.value for parameter in parameters}
    high = new.get(course.HIGH_PARAMETER, self.get_parameter(course.HIGH_PARAMETER).value)
    low = new.get(course.LOW_PARAMETER, self.get_parameter(course.LOW_PARAMETER).value)
    if low >= high:
        return SetParametersResult(successful=False, reason=f'low {low} is not below high {high}')
    return SetParametersResult(successful=True)


def thresholds_callback(self: LearnersNode, msg: Float32) -> None:
    """Notebook 08's monitor callback (given in part 4): the status by both thresholds as
    they are now."""
    high = self.get_parameter(course.HIGH_PARAMETER).value
    low = self.get_parameter(course.LOW_PARAMETER).value
    status = 'High' if msg.data > high else 'Low' if msg.data < low else 'Normal'
    self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')


#: Stand-ins by name: the method of the learner's class each one replaces, and the function.
STAND_INS: dict[str, tuple[str, Callable[..., Any]]] = {
    'sensor_init': ('__init__', sensor_init),
    'sensor_callback': ('publish_temperature', sensor_callback),
    'monitor_init': ('__init__', monitor_init),
    'monitor_callback': ('temperature_callback', monitor_callback),
    'fan_init': ('__init__', fan_init),
    'fan_callback': ('temperature_callback', fan_callback),
    'thresholds_init': ('__init__', thresholds_init),
    'thresholds_on_set': ('on_set_thresholds', thresholds_on_set),
    'thresholds_callback': ('temperature_callback', thresholds_callback),
}
#: Whole nodes for a ``main()`` graded alone: the class main() creates, by class name.
STAND_IN_NODES = {
    course.SENSOR_CLASS: ('sensor_init', 'sensor_callback'),
    course.MONITOR_CLASS: ('monitor_init', 'monitor_callback'),
    course.FAN_CLASS: ('fan_init', 'fan_callback'),
}


def with_stand_ins(cls: type, names: list[str]) -> type:
    """A subclass of ``cls`` with the named stand-ins in place of its own methods.

    :raises KeyError: for a name that is no stand-in (a mistake of the course's).
    """
    methods = dict(STAND_INS[name] for name in names)
    return type(cls.__name__, (cls,), methods) if methods else cls


def stand_in_node(class_name: str) -> type:
    """A whole node of the course's for the class ``main()`` creates (``TemperatureSensor``).

    :raises KeyError: for a class the course has no stand-in for.
    """
    return type(class_name, (Node,), dict(STAND_INS[n] for n in STAND_IN_NODES[class_name]))
