"""Checks of notebook 06, the five promises: a third node, its main(), a counting monitor,
and the arguments that make two rooms of one package (the responsive worker is
:mod:`.lesson06_worker`).

Part of :mod:`ros2nb.checks`.  Every part is in a file of the learner's package
(``fan_controller.py``, ``promises.py``); the judge runs it in a subject and decides from
what its own node sees: the ROS graph, the commands on ``/fan_command`` and the counting
monitor's lines on ``/rosout``.  What the subject reports (its counts) only says how long to
wait, or why a failure happened.
"""

from __future__ import annotations

import re
import time

from std_msgs.msg import Bool

from .. import course, rules
from ..errors import CheckFailed
from ..explain.ros_settings import ros_arguments_mistake, without_c_location
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, Subject
from ..subject_interface import Call, RoomNodes, WaitMatched
from ..subject_replies import Counts
from .base import judged
from .drawn import chooser
from .mains import run_main
from .file_nodes import (announced, feed, lines_logged, new_node, raised, reach,
                         started_log_verdict, unreached)
from .verdicts import endpoint_verdict, node_name_verdict

#: Readings the fan check sends (°C): both sides of the High threshold; then drawn ones.
FAN_READINGS_C = (22.0, 26.0, 26.01, 27.5, 25.99, 19.0)
#: Readings drawn for each run (°C, two decimals): two High, two not, away from the threshold.
FAN_DRAWN_BANDS_C = ((course.HIGH_ABOVE_C + 0.02, 29.0), (course.HIGH_ABOVE_C + 0.02, 29.0),
                     (17.0, course.LOW_BELOW_C - 0.02),
                     (course.LOW_BELOW_C + 0.01, course.HIGH_ABOVE_C - 0.02))
#: A fan controller slower than this (s, the judge's own watch) for every one of its readings
#: waits in its callback: honest ones answer in milliseconds, even on a busy machine.
SLOW_CALLBACK_S = 0.5
#: Readings the counting monitor check sends, their values drawn for each run (°C).
COUNTED_READINGS = 5
COUNTED_RANGE_C = (17.0, 29.0)
#: Rooms the reusability check runs, then one drawn for each run from these words (and a
#: number): no table of rooms holds it.
DRAWN_ROOM_WORDS = ('cellar', 'garage', 'hall', 'landing', 'loft', 'office', 'pantry', 'porch',
                    'study', 'workshop')


def _fan_readings(judge: Judge) -> list[float]:
    """The fan check's readings: :data:`FAN_READINGS_C`, then ones drawn for this run."""
    source = chooser(judge, '06 fan readings')
    drawn = [round(source.uniform(*band), 2) for band in FAN_DRAWN_BANDS_C]
    source.shuffle(drawn)
    return [*FAN_READINGS_C, *drawn]


# ------------------------------------------------------------------ modularity
def _fan_controller(judge: Judge) -> str:
    judge.drop(('file', course.PROMISES_FILE))  # the fan is the only subscription here
    commands = judge.observer.watch('/' + course.FAN_TOPIC, Bool, lambda m: bool(m.data))
    mark = len(judge.observer.logs)
    subject, info = new_node(judge, course.FAN_FILE, course.FAN_CLASS)
    node_name_verdict(info, course.FAN_NODE)
    found = judge.observer.endpoints(info.name, info.namespace, info.endpoints)
    endpoint_verdict(info.name, found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE,
                     info.endpoints)
    endpoint_verdict(info.name, found, 'publisher', '/' + course.FAN_TOPIC,
                     course.FAN_MESSAGE_TYPE, info.endpoints)
    started_log_verdict(judge, info, mark, course.FAN_CLASS)  # the task's third step
    if not subject.request(WaitMatched(topic='/' + course.FAN_TOPIC,
                                       seconds=ARRIVAL_TIMEOUT_S)).ok:
        raise unreached(judge, '/' + course.FAN_TOPIC, f'The publisher of {info.name}')
    reach(judge, subject, info.name)
    counts: Counts = info
    fan_topic = '/' + course.FAN_TOPIC
    answered_s = []  # per reading: from the judge's publishing it to its command arriving
    readings = _fan_readings(judge)
    for value in readings:
        before, sent_before = len(commands), announced(counts, fan_topic)
        started = time.monotonic()
        counts, lines = feed(judge, subject, info, value, counts,
                             'temperature_callback: is it the subscription\'s callback?')
        # Wait for as many commands as the subject says its callback published (none: no
        # wait; it says nothing: at least one); what arrived decides.
        after = announced(counts, fan_topic)
        sent = 1 if after is None or sent_before is None else after - sent_before
        judge.observer.wait_until(lambda: len(commands) - before >= sent, ARRIVAL_TIMEOUT_S)
        answered_s.append(time.monotonic() - started)
        said = [heard.value for heard in commands[before:]]
        want = rules.monitor_status(value) == 'High'
        if not said:
            raise CheckFailed(f'For a reading of {value} °C the fan controller published nothing '
                              f'on /{course.FAN_TOPIC}: publish one Bool for every reading.')
        if len(said) > 1:
            raise CheckFailed(f'For a reading of {value} °C the fan controller published '
                              f'{len(said)} commands; publish exactly one per reading.')
        if bool(said[0]) != want:
            raise CheckFailed(f'For {value} °C the fan controller published {bool(said[0])}; it '
                              f'should be {want}: the fan is on only when the reading is High, '
                              f'strictly above HIGH_ABOVE_C = {course.HIGH_ABOVE_C} °C.')
        _log_verdict(value, bool(said[0]), lines)
    _slow_callback_verdict(min(answered_s), len(readings))
    return (f'{info.name} hears /{course.TOPIC} and publishes one command on '
            f'/{course.FAN_TOPIC} per reading, True only when High ({len(readings)} '
            'readings).')


def _log_verdict(value: float, command: bool, lines: list[str]) -> None:
    """The fan's log line is optional, but one that says on or off says what it published."""
    for line in lines:
        said = set(re.findall(r'\b(on|off)\b', line.lower()))
        if len(said) == 1 and (said == {'on'}) != command:
            raise CheckFailed(f'For {value} °C the fan controller published {command} but '
                              f'logged "{line}": log what it published (command.data), or no '
                              'line.')


def _slow_callback_verdict(fastest_s: float, readings: int) -> None:
    """A callback that waits (``time.sleep``, a loop, a blocking call) holds up every other
    callback of its node: notebook 06 says to answer each reading at once."""
    if fastest_s >= SLOW_CALLBACK_S:
        raise CheckFailed(f'The fan controller took {SLOW_CALLBACK_S:g} s or more to answer each '
                          f'of {readings} readings: temperature_callback waits (a loop, or a '
                          'wait?), and meanwhile every other callback of its node waits too '
                          '(section 4): publish the command at once, without waiting.')


@judged
def check_fan_controller(judge: Judge) -> str:
    """Check part 2 of ``fan_controller.py``: the third node, added without touching the others.

    The judge creates your ``FanController``, reads its subscription and publisher from the
    ROS graph, publishes readings on both sides of 26 °C from its own publisher (some drawn
    for this run) and reads every command on ``/fan_command``.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the reading and the command your node published.
    """
    return _fan_controller(judge)


@judged
def check_fan_main(judge: Judge) -> str:
    """Check part 3 of ``fan_controller.py``: ``main()`` runs it as a process of its own.

    As :func:`check_sensor_main`: the file is started as a program, gets Ctrl+C once its
    node spins, and must exit with code 0 after cleaning up in ``finally``.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    return run_main(judge, relative=course.FAN_FILE, node_name=course.FAN_NODE, part=3,
                    node_class=course.FAN_CLASS)


# ------------------------------------------------------------------ scalability
def _counting_monitor(judge: Judge) -> str:
    judge.drop(('file', course.FAN_FILE))  # the counting monitor is the only subscription here
    name = 'monitor_7'
    observer = judge.observer
    mark = len(observer.logs)
    subject, info = new_node(judge, course.PROMISES_FILE, course.COUNTING_CLASS, args=(name,))
    if info.name != name:
        raise CheckFailed(f"{course.COUNTING_CLASS}('{name}') made a node called {info.name}: "
                          'pass the name it is given on to super().__init__(name).')
    found = observer.endpoints(info.name, info.namespace, info.endpoints)
    endpoint_verdict(name, found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE,
                     info.endpoints)
    lines_logged(judge, info, mark, info.started_lines)
    reach(judge, subject, name)
    counts: Counts = info
    source = chooser(judge, '06 counted readings')
    for index in range(1, COUNTED_READINGS + 1):
        value = round(source.uniform(*COUNTED_RANGE_C), 2)
        counts, lines = feed(judge, subject, info, value, counts,
                             "its callback: is it the subscription's callback?")
        numbers = [int(n) for line in lines for n in re.findall(r'(?<![\d.])\d+(?![\d.])', line)]
        if not lines:
            raise CheckFailed(f'{name} logged nothing for reading {index}: log the count in '
                              'count(), after adding one, e.g. '
                              "self.get_logger().info(f'received {self.received}').")
        if len(lines) > 1:
            raise CheckFailed(f'{name} logged {len(lines)} lines for reading {index}; log one, '
                              'with the count.')
        if index not in numbers:
            raise CheckFailed(f'After {index} reading{"s" if index > 1 else ""} {name} logged '
                              f'"{lines[0]}"; the count is {index}: start self.received at 0 '
                              'in __init__, add one for every message, and log the new count.')
    _named_as_told(judge, f'monitor_{chooser(judge, "06 counting name").randrange(10, 1000)}')
    return (f"{course.COUNTING_CLASS}('{name}') is called {name} and counted "
            f'{COUNTED_READINGS} of {COUNTED_READINGS} readings, as its lines on /rosout say.')


def _named_as_told(judge: Judge, name: str) -> None:
    """A counting monitor given ``name`` (drawn for this run: no table holds it) is called
    ``name``."""
    _subject, info = new_node(judge, course.PROMISES_FILE, course.COUNTING_CLASS, args=(name,))
    if info.name != name:
        raise CheckFailed(f"{course.COUNTING_CLASS}('{name}') made a node called {info.name}: "
                          'pass the name it is given on to super().__init__(name).')


@judged
def check_counting_monitor(judge: Judge) -> str:
    """Check part 2 of ``promises.py``: a monitor that only counts, named as it is told.

    Creates ``CountingMonitor('monitor_7')``, checks its name and subscription in the ROS
    graph, publishes 5 readings (drawn for this run) and reads on ``/rosout`` the count it
    logs for each: 1 to 5; then checks the name of one made with a name drawn for this run.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the name or count found and the one expected.
    """
    return _counting_monitor(judge)


# ------------------------------------------------------------------ reusability
def _room_arguments_of(subject: Subject, room: str) -> list[str]:
    reply = subject.request(Call(name=course.ROOMS_FUNCTION, inputs=[[room]]))
    if reply.undefined:
        raise CheckFailed(f'promises.py defines no function {course.ROOMS_FUNCTION}: write part 5 '
                          '(and run its cell).')
    output = reply.outputs[0] if reply.outputs else None
    if output is None or output.result is None:
        raise raised(f"{course.ROOMS_FUNCTION}('{room}')", output.error if output else None)
    result = output.result
    if not isinstance(result.value, list) or any(item.type != 'str' for item in result.value):
        raise CheckFailed(f"{course.ROOMS_FUNCTION}('{room}') returned {result.value!r}; "
                          "return a list of strings, e.g. ['--ros-args', '-r', ...].")
    arguments = [str(item.value) for item in result.value]
    if '--ros-args' not in arguments:
        raise CheckFailed(f"{course.ROOMS_FUNCTION}('{room}') returned {arguments}: a node reads "
                          "only the arguments after '--ros-args'; start the list with it.")
    return arguments


def _drawn_room(judge: Judge) -> str:
    """A room for this run (:mod:`.drawn`), e.g. ``study_42``: a name no table holds."""
    source = chooser(judge, '06 room')
    return f'{source.choice(DRAWN_ROOM_WORDS)}_{source.randrange(10, 100)}'


def _rooms(judge: Judge) -> str:
    subject = judge.file_subject(course.PROMISES_FILE)
    seen: dict[str, str] = {}
    for room in (*course.ROOMS, _drawn_room(judge)):
        arguments = _room_arguments_of(subject, room)
        reply = subject.request(RoomNodes(arguments=arguments))
        if not reply.ok:
            if reply.error is None:
                raise raised(f"rooms started with {course.ROOMS_FUNCTION}('{room}')", None)
            kind, text = reply.error.type, reply.error.message
            why = ros_arguments_mistake(kind, text) or \
                f'{kind}: {without_c_location((text.splitlines() or [""])[0])[:160]}'
            raise CheckFailed(f"rclpy refused the arguments {course.ROOMS_FUNCTION}('{room}') "
                              f'returned, {arguments}: {why}')
        for name, namespace, endpoints in reply.nodes:
            full = namespace.rstrip('/') + '/' + name
            found = judge.observer.endpoints(name, namespace, endpoints)
            if namespace != f'/{room}':
                raise CheckFailed(f"With {course.ROOMS_FUNCTION}('{room}') the node runs as "
                                  f'{full}; put it in the namespace /{room} (remap __ns) so '
                                  'that each room has its own nodes and topics.')
            kind = 'publisher' if name == course.SENSOR_NODE else 'subscription'
            endpoint_verdict(full, found, kind, f'/{room}/{course.TOPIC}', course.MESSAGE_TYPE)
            if full in seen:
                raise CheckFailed(f'Both rooms run a node {full}: use the room you are given.')
            seen[full] = room
    shown = sorted(full for full, room in seen.items() if room in course.ROOMS)
    return (f'the same two nodes run as {", ".join(shown)}, each room on its own '
            f'/ROOM/{course.TOPIC}, as the ROS graph shows.')


@judged
def check_room_arguments(judge: Judge) -> str:
    """Check part 5 of ``promises.py``: the arguments that make one package serve two rooms.

    Calls ``room_arguments('kitchen')``, ``room_arguments('attic')`` and the same for a room
    drawn for this run (e.g. ``'study_42'``), starts a sensor and
    a monitor node with each list (as ``ros2 run ... --ros-args ...`` would) and reads the
    ROS graph: each room's nodes in their own namespace, talking on their own topic.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the node or topic the graph shows and the one expected.
    """
    return _rooms(judge)
