"""Learners whose code forges what the subject process reports: no verdict may follow it.

As tests/test_checks.py: this process is the judge, the learner's code runs in real subject
processes and the verdicts come from the judge's own ROS node. Each learner below is the
course's reference with one piece of work left out and, at import, code that walks up the
stack to the subject's request loop and rewrites its replies (or does the missing work
itself inside them, or rewrites the files the judge reads). Against a judge that believed
the subject's replies, every check below passed (notebook 03: no timer 6/6, a callback doing
nothing 6/6, a property's start value 3/6, a main() that never starts ROS 6/6; notebook 04:
a callback doing nothing 5/5; notebook 02's reader 1/1). Here each fails with one line; the
honest twin of each is the reference, which passes (tests/test_checks.py).
"""

import re

import pytest

from ros2nb import checks, course
from ros2nb.judge_interface import AnswerRef

from grading_samples import REWRITING_READER
from nodes import name_without_endpoints
from waiting import wait_for
from judging import FIND_SUBJECT, run_check
from test_checks import PUB, SUB, fails, mutated, restore

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]

#: The timer's work done by the request handler: each ``advance`` calls publish_temperature
#: once per simulated second itself (new_node's reply is passed on: a reply names no timers,
#: the judge sees the node's readings itself).
FORGED_TIMER = FIND_SUBJECT + '''
def _forge(_new_node=_HANDLERS.get('new_node'), _advance=_HANDLERS.get('advance')):
    def new_node(command):  # a reply names no timers: the judge reads them from the graph
        return _new_node(command)

    def advance(seconds, seed=None):
        if seed is not None:
            random.seed(seed)
        for _ in range(round(seconds)):
            _SUBJECT.node.publish_temperature()
        return _advance(seconds=seconds)

    _HANDLERS.update(new_node=new_node, advance=advance)


if _SUBJECT is not None:
    _forge()
'''

TIMER_LINE = '        self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)\n'
MAIN_GUARD = "\nif __name__ == '__main__':"

#: The callback's work done by the request handler: each ``advance`` steps the walk,
#: publishes and logs the reading itself, while publish_temperature does nothing.
FORGED_CALLBACK = FIND_SUBJECT + '''
def _forge(_advance=_HANDLERS.get('advance')):
    def advance(seconds, seed=None):
        if seed is not None:
            random.seed(seed)
        node = _SUBJECT.node
        for _ in range(round(seconds)):
            step = random.uniform(-MAX_STEP_C, MAX_STEP_C)
            walked = node.temperature + step
            node.temperature = max(MIN_TEMPERATURE_C, min(MAX_TEMPERATURE_C, walked))
            node.publisher_.publish(Float32(data=node.temperature))
            node.get_logger().info(f'Publishing: {node.temperature:.2f}C')
        return _advance(seconds=seconds)

    _HANDLERS['advance'] = advance


if _SUBJECT is not None:
    _forge()
'''


def test_forged_checks_are_seen(session):
    """A file whose import walks the stack to the subject's request loop: the check fails on
    what the judge observes (no timer), and what the subject's audit hook saw is a note for
    the instructor, never the check's line (``ros2nb.judge.reaching``)."""
    mutated(session, PUB, (TIMER_LINE, MAIN_GUARD), ('', FORGED_TIMER + MAIN_GUARD))
    try:
        fails(session, checks.check_sensor_constructor, r'TemperatureSensor has no timer')
        notes = session.reaching.flags()
        assert any(re.search(r'^temperature_publisher\.py line \d+: at run time, reads stack '
                             r'frames.*\(sys\._getframe\)', note) for note in notes), notes
    finally:
        restore(session, PUB)


def test_a_sensor_without_a_timer_whose_subject_reports_one(session):
    mutated(session, PUB, (TIMER_LINE, MAIN_GUARD), ('', FORGED_TIMER + MAIN_GUARD))
    try:
        fails(session, checks.check_sensor_constructor, r'TemperatureSensor has no timer')
        # part 4 is the reference's: it deserves its points
        run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)


def test_a_callback_that_does_nothing_while_its_subject_publishes(session):
    mutated(session, PUB, ('    def publish_temperature(self):\n', MAIN_GUARD),
            ('    def publish_temperature(self):\n        return\n\n    def unused(self):\n',
             FORGED_CALLBACK + MAIN_GUARD))
    try:
        # part 3 is the reference's: it deserves its point
        run_check(session, checks.check_sensor_constructor)
        fails(session, checks.check_sensor_callback,
              r'publish_temperature ran but nothing arrived on '
              r'/temperature')
        fails(session, checks.check_sensor_hour, r'No reading arrived on /temperature')
    finally:
        restore(session, PUB)


def test_a_start_value_reported_by_a_property(session):
    """``self.temperature`` reads 22.0 while the walk really starts at 25.0."""
    mutated(session, PUB, (
        '    def __init__(self):\n',
        '        self.temperature = START_TEMPERATURE_C\n',
        '''        self.temperature = max(MIN_TEMPERATURE_C,
                               min(MAX_TEMPERATURE_C, self.temperature + step))''',
        'msg.data = self.temperature',
        "info(f'Publishing: {self.temperature:.2f}C')"), (
        '    temperature = property(lambda self: START_TEMPERATURE_C)\n\n    def __init__(self):\n',
        '        self.walk = 25.0\n',
        '''        self.walk = max(MIN_TEMPERATURE_C,
                        min(MAX_TEMPERATURE_C, self.walk + step))''',
        'msg.data = self.walk',
        "info(f'Publishing: {self.walk:.2f}C')"))
    try:
        fails(session, checks.check_sensor_constructor,
              r'The first reading is 2[45]\.\d\d °C: the walk starts at|'
              r"property 'temperature' of 'TemperatureSensor' object has no setter")
        fails(session, checks.check_sensor_callback, r'The first reading is 2[45]\.\d\d °C|'
                                            r"property 'temperature' of 'TemperatureSensor' "
                                            r'object has no setter')
    finally:
        restore(session, PUB)


def test_a_main_that_never_starts_ros(session):
    """main() waits for Ctrl+C and leaves cleanly, but no node ever runs."""
    mutated(session, PUB, ('    rclpy.init(args=args)\n    node = TemperatureSensor()\n'
                           '    try:\n        rclpy.spin(node)\n',
                           '        node.destroy_node()\n        rclpy.try_shutdown()  #'),
            ('    import time\n    node = None\n    try:\n        while True:\n'
             '            time.sleep(0.05)\n',
             '        if node:\n            node.destroy_node()\n        rclpy.try_shutdown()  #'))
    observer = session.observer
    try:
        # The name of an earlier sensor, left in the graph without endpoints (as after
        # ros2/ros2#1413's race): it must not pass for this main()'s node. Counted as a
        # node, it turned this verdict into "created its node but never spun it".
        with name_without_endpoints(course.SENSOR_NODE, observer.domain_id):
            wait_for(lambda: (course.SENSOR_NODE, '/') in
                     observer.node.get_node_names_and_namespaces(),
                     'the graph listing a temperature_sensor that owns no endpoint',
                     seen=observer.node.get_node_names_and_namespaces)
            assert not observer.has_node(course.SENSOR_NODE)
            fails(session, checks.check_sensor_main, r'never started its node temperature_sensor')
    finally:
        restore(session, PUB)


#: The callback's work done by a method the subscription was switched to after the
#: subject created the node: temperature_callback itself does nothing.
FORGED_SUBSCRIPTION = FIND_SUBJECT + '''
def _forge(_new_node=_HANDLERS.get('new_node')):
    def new_node(command):
        reply = _new_node(command)
        node = _SUBJECT.node
        for subscription in node.subscriptions if reply.ok else ():
            counted = subscription.callback
            subscription.callback = lambda msg, counted=counted: (counted(msg), node.unused(msg))
        return reply

    _HANDLERS['new_node'] = new_node


if _SUBJECT is not None:
    _forge()
'''


def test_a_monitor_callback_that_does_nothing_while_another_method_logs(session):
    mutated(session, SUB, ('    def temperature_callback(self, msg):\n', MAIN_GUARD),
            ('    def temperature_callback(self, msg):\n        return\n\n'
             '    def unused(self, msg):\n',
             FORGED_SUBSCRIPTION + MAIN_GUARD))
    try:
        # part 3 is the reference's: it deserves its points
        run_check(session, checks.check_monitor_constructor)
        fails(session, checks.check_monitor_callback, r'the monitor logged nothing: log one line')
    finally:
        restore(session, SUB)


def test_a_package_reader_that_rewrites_the_package_xml(session):
    xml = session.workspace / course.PACKAGE_XML_FILE
    saved = xml.read_text()
    try:
        fails(session, checks.check_dependencies,
              r"For graded_reader/package.xml you returned \['ament_python', 'geometry_msgs', "
              r"'rclpy', 'sensor_msgs'\], but it declares \['geometry_msgs', 'rclpy', "
              r"'sensor_msgs'\]", AnswerRef('package_dependencies', (REWRITING_READER,)))
    finally:
        xml.write_text(saved)
