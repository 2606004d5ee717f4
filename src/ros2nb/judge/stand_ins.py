"""The course's own version of each part a check does not grade, put in place of the learner's.

Introduced in ``03-write-the-publisher.ipynb``.  A check grades one part of a node: the
constructor, or the callback.  So that a mistake in one part costs only that part's points,
the judge may run the learner's class with another part replaced by the one here
(``new_node(..., stand_ins=[...])``, :mod:`ros2nb.subject.commands`).  A stand-in never
counts for the learner: it only makes room for their own part to be seen.

This module is an answer and the judge's alone: no subject imports it (and while grading its
file is not on a subject's disk).  A subject that needs stand-ins gets the code of just those
(:func:`source_of`), sent after the learner's code is loaded, in a subject that runs no other
stand-ins (:meth:`ros2nb.judge.session.Session.file_subject`): what the learner's code there
can reach is the course's version of the parts that subject does not grade, never of the
part it grades.

Each function is written for a class of the learner's (no ``super()``: the class it ends up
in is made on the fly).  The callbacks find the node's publisher by its topic, so a
learner's constructor that names its attribute differently still works with them.
"""

from __future__ import annotations

import inspect
import random
import sys
import types
from typing import Any, Callable, Optional

from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from rclpy.parameter import Parameter
from std_msgs.msg import Bool, Float32

from .. import course
from ..rules import monitor_status


def _publisher_on(node: Node, topic: str) -> Any:
    """The node's publisher on ``topic`` (relative to its namespace), whatever its attribute;
    an AttributeError for ``publisher_`` (the task's name) when no attribute keeps it."""
    full = node.resolve_topic_name(topic)
    found = [p for p in node.publishers if p.topic_name == full]
    if not found:
        raise AttributeError(f'{node.get_name()} has no publisher on {full}')
    kept = [name for name, value in vars(node).items()
            if value is found[-1] and not name.startswith('_')]
    if not kept:  # made in a local name: the learner's own callback could never reach it
        raise AttributeError(f"'{type(node).__name__}' object has no attribute 'publisher_'",
                             name='publisher_', obj=node)
    return found[-1]


#: The learner's node class a stand-in method is put on: a Node subclass with attributes of
#: its own (``publisher_``, ``temperature``, ...), which no type declares.
LearnersNode = Any


def _constructing(node: Node) -> bool:
    """Whether ``node``'s own ``__init__`` is running further up this thread's stack."""
    frame: Optional[types.FrameType] = sys._getframe(1)
    while frame is not None:
        if frame.f_code.co_name == '__init__' and frame.f_locals.get('self') is node:
            return True
        frame = frame.f_back
    return False


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

    On a node without ``temperature`` (a constructor that keeps the walk in a local name, or
    under another name) it raises the AttributeError of reading it: the check names the
    constructor's line (:mod:`ros2nb.explain.everyday`), and tries the learner's own
    callback with it.  Called by the constructor itself (``self.publish_temperature()``
    where the method should be passed), before the walk's start is set, it does nothing, as
    a call of a part not written yet would: the check then names the call.
    """
    if not hasattr(self, 'temperature') and _constructing(self):
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


def thresholds_on_set(self: LearnersNode, parameters: list[Parameter]) -> SetParametersResult:
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
#: What a stand-in's code uses besides :data:`PREAMBLE`'s names.
HELPERS: dict[str, tuple[Callable[..., Any], ...]] = {
    'sensor_callback': (_publisher_on, _constructing), 'fan_callback': (_publisher_on,),
    'monitor_callback': (monitor_status,)}
#: The names every stand-in's code may use, imported in the subject (no answer among them);
#: its annotations are text, whatever the code that compiles it (a compile the learner's
#: code wrapped passes on none of the command loop's future flags).
PREAMBLE = """\
from __future__ import annotations
import random
import sys
import types
from typing import Any, Optional
from rcl_interfaces.msg import FloatingPointRange, ParameterDescriptor, SetParametersResult
from rclpy.node import Node
from std_msgs.msg import Bool, Float32
from ros2nb import course
from ros2nb.course import HIGH_ABOVE_C, LOW_BELOW_C
"""


def source_of(names: tuple[str, ...]) -> str:
    """The code of the stand-ins ``names`` and of what they use, as a module's text that
    ends in ``STAND_INS = {name: (method, function)}``: what a subject compiles.

    :raises KeyError: for a name that is no stand-in (a mistake of the course's).
    """
    used = dict.fromkeys(helper for name in names for helper in HELPERS.get(name, ()))
    parts = [PREAMBLE, *(inspect.getsource(helper) for helper in used),
             *(inspect.getsource(STAND_INS[name][1]) for name in names)]
    table = ', '.join(f'{name!r}: ({STAND_INS[name][0]!r}, {STAND_INS[name][1].__name__})'
                      for name in names)
    return '\n\n'.join(parts) + f'\n\nSTAND_INS = {{{table}}}\n'
