"""Checks of notebook 04, write the subscriber: the monitor's constructor, callback and main().

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``TemperatureMonitor`` in a
subject, publishes readings to it from its own node and reads its log lines on ``/rosout``.
Each part is graded on its own: while one part is checked, the course's stand-in may take
the place of another (:mod:`ros2nb.judge.stand_ins`).
"""

from __future__ import annotations

import re

from .. import course, rules
from ..errors import CheckFailed
from ..judge_interface import Judge, Subject
from ..subject_interface import GetCounts
from ..subject_replies import NodeMade
from .base import judged
from .drawn import chooser
from .mains import run_main
from .file_nodes import feed, new_node, reach, started_log_verdict
from .verdicts import endpoint_verdict, node_name_verdict

#: Readings the monitor callback check sends: both boundaries and their neighbours (°C).
BOUNDARY_READINGS_C = (19.99, 20.0, 23.0, 26.0, 26.01, 18.5, 27.5)
#: Where readings are drawn (°C, two decimals): each status's band, kept off the boundaries.
STATUS_BANDS_C = {'Low': (17.0, course.LOW_BELOW_C - 0.02),
                  'Normal': (course.LOW_BELOW_C + 0.01, course.HIGH_ABOVE_C - 0.01),
                  'High': (course.HIGH_ABOVE_C + 0.02, 29.0)}
#: Readings drawn in each band for the callback's check, and for the hidden test.
CALLBACK_DRAWN_PER_STATUS, HIDDEN_DRAWN_PER_STATUS = 2, 10


def drawn_readings_c(judge: Judge, purpose: str, per_status: int) -> list[float]:
    """``per_status`` readings of each status (two decimals, °C), drawn for this run
    (:mod:`.drawn`), in a drawn order: no table of the course's readings holds them."""
    source = chooser(judge, purpose)
    readings = [round(source.uniform(*STATUS_BANDS_C[status]), 2)
                for status in STATUS_BANDS_C for _ in range(per_status)]
    source.shuffle(readings)
    return readings


@judged
def check_monitor_main(judge: Judge) -> str:
    """Check part 5 of ``temperature_subscriber.py``: ``main()`` and Ctrl+C.

    As :func:`check_sensor_main`, for the monitor.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    return run_main(judge, relative=course.SUBSCRIBER_FILE, node_name=course.MONITOR_NODE,
                    node_class=course.MONITOR_CLASS)


# ------------------------------------------------------------------ the monitor
def _monitor_verdict(info: NodeMade, found: list[tuple[str, str, str]]) -> None:
    node_name_verdict(info, course.MONITOR_NODE)
    endpoint_verdict(info.name, found, 'subscription', '/' + course.TOPIC,
                     course.MESSAGE_TYPE, info.endpoints)


def _monitor(judge: Judge, stand_ins: tuple[str, ...] = ()) -> tuple[Subject, NodeMade]:
    """Make the learner's monitor (with ``stand_ins``); raise for what its constructor got
    wrong (name, subscription, start-up line) as the judge sees it."""
    observer = judge.observer
    mark = len(observer.logs)
    subject, info = new_node(judge, course.SUBSCRIBER_FILE, course.MONITOR_CLASS,
                             stand_ins=stand_ins)
    _monitor_verdict(info, observer.endpoints(info.name, info.namespace, info.endpoints))
    started_log_verdict(judge, info, mark, course.MONITOR_CLASS)
    reach(judge, subject, info.name)
    return subject, info


def _feed(judge: Judge, subject: Subject, info: NodeMade,
          readings: tuple[float, ...] | list[float]) -> list[list[str]]:
    """Publish readings to the learner's monitor from the judge's node; return the lines it
    logged for each (the subject's counts only say how many to wait for)."""
    per_reading = []
    counts = subject.request(GetCounts())
    for value in readings:
        counts, lines = feed(judge, subject, info, value, counts,
                             "the subscription's callback: keep the subscription in an "
                             'attribute of the node.')
        per_reading.append(lines)
    return per_reading


def _monitor_constructor(judge: Judge) -> str:
    """Part 3 alone: the learner's __init__, with the course's callback (their own when the
    course's cannot run with their constructor)."""
    reading = [23.0]
    try:
        subject, info = _monitor(judge, ('monitor_callback',))
        lines = _feed(judge, subject, info, reading)
    except CheckFailed as problem:
        try:
            subject, info = _monitor(judge)
            lines = _feed(judge, subject, info, reading)
        except CheckFailed:
            raise problem from None
    if not lines[0]:
        raise CheckFailed(f'A reading of {reading[0]} °C reached {info.name}, which logged '
                          'nothing: the subscription\'s callback must be '
                          'self.temperature_callback (the method itself, without parentheses).')
    return (f'{info.name} subscribes to /{course.TOPIC} [{course.MESSAGE_TYPE}] and hears the '
            'grader\'s readings.')


@judged
def check_monitor_constructor(judge: Judge) -> str:
    """Check part 3 of ``temperature_subscriber.py``: the monitor's ``__init__``.

    Creates your ``TemperatureMonitor`` (with the course's ``temperature_callback``, so that
    only your constructor counts) and checks its name, its subscription (topic and type, from
    the ROS graph), its start-up log line, and that a reading the grader publishes reaches it.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    return _monitor_constructor(judge)


def _own_or_course_constructor(judge: Judge, readings: list[float]) -> list[list[str]]:
    """The learner's callback fed ``readings``: in their own monitor, or, when its constructor
    is at fault, in the course's (a mistake in part 3 costs part 3 only)."""
    try:
        subject, info = _monitor(judge)
    except CheckFailed:
        subject, info = _monitor(judge, ('monitor_init',))
    return _feed(judge, subject, info, readings)


def _statuses_verdict(readings: tuple[float, ...] | list[float], lines: list[list[str]], *,
                      with_value: bool) -> None:
    words = re.compile(r'\b(High|Low|Normal)\b')
    for value, said in zip(readings, lines):
        want = rules.monitor_status(value)
        if not said:
            raise CheckFailed(f'For a reading of {value} °C the monitor logged nothing: log one '
                              'line with the reading and its status.')
        if len(said) > 1:
            raise CheckFailed(f'For a reading of {value} °C the monitor logged {len(said)} lines; '
                              'log exactly one per message.')
        found = words.findall(said[0])
        if not found:
            lower = re.search(r'\b(high|low|normal)\b', said[0], re.IGNORECASE)
            if lower:
                raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}": write the '
                                  f'status {lower.group(0).capitalize()}, with a capital letter, '
                                  f'as High, Low and Normal are written.')
            raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}", without a status: '
                              'add High, Low or Normal to the line.')
        if found != [want]:
            rule = (f'only readings strictly above {course.HIGH_ABOVE_C} °C are High and strictly '
                    f'below {course.LOW_BELOW_C} °C Low')
            raise CheckFailed(f'For {value} °C the monitor said {", ".join(found)}; it should say '
                              f'{want}: {rule}.')
        if with_value and f'{value:.2f}' not in said[0]:
            raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}": show the reading '
                              'with two decimals, e.g. 23.00.')


def _monitor_callback(judge: Judge) -> str:
    readings = [*BOUNDARY_READINGS_C,
                *drawn_readings_c(judge, '04 monitor callback', CALLBACK_DRAWN_PER_STATUS)]
    lines = _own_or_course_constructor(judge, readings)
    _statuses_verdict(readings, lines, with_value=True)
    return (f'one line with the right status for each of {len(readings)} readings, '
            f'including {course.LOW_BELOW_C} and {course.HIGH_ABOVE_C} °C (both Normal).')


@judged
def check_monitor_callback(judge: Judge) -> str:
    """Check part 4 of ``temperature_subscriber.py``: the callback and its statuses.

    The judge publishes readings around both thresholds (19.99, 20.0, 26.0, 26.01 °C and
    more, and two of each status drawn for this run) to your monitor over ROS and reads its
    log lines from ``/rosout``: exactly one line per message, with the reading (two
    decimals), naming High, Low or Normal correctly.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming the reading, what your monitor said and the rule.
    """
    return _monitor_callback(judge)


def _monitor_readings(judge: Judge) -> str:
    readings = drawn_readings_c(judge, '04 monitor readings', HIDDEN_DRAWN_PER_STATUS)
    readings += [course.LOW_BELOW_C, course.HIGH_ABOVE_C, 19.995, 26.005]
    lines = _own_or_course_constructor(judge, readings)
    _statuses_verdict(readings, lines, with_value=True)
    return f'the right status and the reading in one line for each of {len(readings)} readings.'


@judged
def check_monitor_readings(judge: Judge) -> str:
    """Hidden test of notebook 04: 34 readings from the grader's own publisher.

    Readings drawn for this run, ten of each status, and the boundaries; every one must give
    one line with the reading (two decimals) and the right status.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming the first reading handled wrongly.
    """
    return _monitor_readings(judge)
