"""Checks of notebook 03, write the publisher: the sensor's constructor, callback and main().

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``TemperatureSensor`` in a
subject, runs it on simulated time and decides from what reaches its own node over ROS.
"""

from __future__ import annotations

import math
import re
from typing import Any, Optional

from .. import course
from ..errors import CheckFailed
from .base import ARRIVAL_TIMEOUT_S, Judge, judged, learner_error, passed
from .mains import run_main
from .nodes import caught_up, new_node, started_log_verdict
from .source import UNKNOWN, ClassSource
from .verdicts import endpoint_verdict, node_name_verdict

#: Tolerance for values that went through a 32-bit float (°C).
FLOAT32_TOLERANCE_C = 1e-4
#: How far a logged number may be from its reading (°C): two decimals, rounded either way.
LOGGED_READING_TOLERANCE_C = 0.011
#: Simulated seconds the callback check runs the sensor, then each clamp probe.
CALLBACK_RUN_S, CLAMP_RUN_S = 20, 40
#: Seeds of ``random`` for the sensor checks (a clamp-less walk crosses both limits).
SENSOR_SEED, CEILING_SEED, FLOOR_SEED = 7, 2, 1
#: Where the clamp probes start the walk (°C): just inside the limits.
CLAMP_PROBES_C = (course.MAX_TEMPERATURE_C - 0.05, course.MIN_TEMPERATURE_C + 0.05)


def _sensor_verdict(judge: Judge, info: dict, found: list) -> None:
    """Name and publisher (the ROS graph), timer and start value (the file, read as text).

    Nothing here comes from the subject's word: the graph is the judge's own view, and
    the timer and start value are read from the learner's file with ``ast``; their effect
    (one reading a second, the first next to the start value) is what the callback checks
    observe on ``/temperature``.
    """
    node_name_verdict(info, course.SENSOR_NODE)
    endpoint_verdict(info['name'], found, 'publisher', '/' + course.TOPIC, course.MESSAGE_TYPE)
    source = ClassSource.read(judge.workspace, course.PUBLISHER_FILE, course.SENSOR_CLASS)
    if source is None:  # the subject imported another file than the judge can read
        raise CheckFailed(f'The grader cannot read the class {course.SENSOR_CLASS} in '
                          f'{course.PUBLISHER_FILE}: run the %%part cells that write it again.')
    _timer_verdict(source)
    _start_verdict(source)


def _timer_verdict(source: ClassSource) -> None:
    timers = source.timers()
    if not timers:
        raise CheckFailed(f'{course.SENSOR_CLASS} has no timer: create one in __init__ that calls '
                          f'self.publish_temperature every PUBLISH_PERIOD_S = '
                          f'{course.PUBLISH_PERIOD_S} s.')
    if len(timers) > 1:
        raise CheckFailed(f'{course.SENSOR_CLASS} has {len(timers)} timers; one timer calling '
                          'publish_temperature is all it needs.')
    period, callback = timers[0].period, timers[0].callback
    if callback != 'publish_temperature':
        raise CheckFailed(f'The timer calls {callback}; it must call self.publish_temperature '
                          '(the method itself, without parentheses).')
    if period is not UNKNOWN and not (_is_number(period) and math.isclose(
            period, course.PUBLISH_PERIOD_S)):  # else the readings' spacing decides
        shown = f'{period:g}' if _is_number(period) else repr(period)
        raise CheckFailed(f'The timer fires every {shown} s; the sensor publishes '
                          f'every {course.PUBLISH_PERIOD_S} s (PUBLISH_PERIOD_S).')


def _start_verdict(source: ClassSource) -> None:
    if source.computes('temperature'):
        raise CheckFailed(f'temperature of {course.SENSOR_CLASS} is a property (or a method): '
                          'make it a plain attribute of the node, set in __init__ with '
                          'self.temperature = START_TEMPERATURE_C.')
    start = source.attribute('temperature')
    if not source.assignments('temperature') and not source.assigned_anywhere('temperature'):
        raise CheckFailed(f'{course.SENSOR_CLASS} has no attribute temperature: start the walk '
                          'in __init__ with self.temperature = START_TEMPERATURE_C.')
    if start is not UNKNOWN and not (_is_number(start) and math.isclose(
            start, course.START_TEMPERATURE_C)):  # else the first reading decides
        raise CheckFailed(f'self.temperature starts at {start!r}; the walk starts at '
                          f'START_TEMPERATURE_C = {course.START_TEMPERATURE_C} °C.')


def _publishes_verdict(judge: Judge) -> None:
    """The readings that arrived came from publish_temperature, as the file (text) says.

    The judge hears readings, not which code sent them, and what a subject says about that
    counts for nothing: the method the timer calls must publish.
    """
    source = ClassSource.read(judge.workspace, course.PUBLISHER_FILE, course.SENSOR_CLASS)
    if source is None or not source.reaches_call('publish_temperature', 'publish'):
        raise CheckFailed('publish_temperature never publishes, yet readings arrived from '
                          'elsewhere: put the new reading into a Float32 message and publish it '
                          'with the publisher from __init__, in publish_temperature.')


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _sensor_constructor(judge: Judge) -> str:
    mark = len(judge.observer.logs)
    _subject, info = new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                               placeholders=('publish_temperature',))
    found = judge.observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    _sensor_verdict(judge, info, found)
    started_log_verdict(judge, info, mark, course.SENSOR_CLASS)
    return (f'{info["name"]} publishes {course.MESSAGE_TYPE} on /{course.TOPIC} every '
            f'{course.PUBLISH_PERIOD_S} s, starting at {course.START_TEMPERATURE_C} °C.')


def check_sensor_constructor() -> None:
    """Check part 3 of ``temperature_publisher.py``: the sensor's ``__init__``.

    Creates your ``TemperatureSensor`` (a stand-in replaces ``publish_temperature`` if part
    4 is not written yet) and checks its name, its publisher (topic and type, as the ROS
    graph shows them), its timer (period and callback), the start value of
    ``self.temperature`` and its start-up log line.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    judged('check_sensor_constructor', _sensor_constructor)


def _run_sensor(judge: Judge, subject: Any, info: dict, seconds: int, *,
                step_s: float = 1.0, seed: Optional[int] = None) -> tuple[list[float], list[str], int]:
    """Run the sensor ``seconds`` simulated seconds; return readings, log lines, firings.

    The readings and log lines are what arrived at the judge's own subscriptions, over
    ROS; the subject's counts only tell the judge how long to wait for them.
    """
    observer = judge.observer
    topic = '/' + course.TOPIC
    observer.watch_readings(topic)
    if not subject.request('wait_matched', topic=topic, seconds=ARRIVAL_TIMEOUT_S)['ok']:
        raise CheckFailed(f'The publisher on {topic} never reached the grader\'s subscription: '
                          f'check its topic name and its type ({course.MESSAGE_TYPE}).')
    base = subject.request('counts')
    first, log_mark = len(observer.readings), len(observer.logs)
    reply = base
    for number in range(math.ceil(seconds / step_s)):
        reply = subject.request('advance', seconds=step_s, seed=seed if number == 0 else None)
        if reply['failure']:
            failure = reply['failure']
            raise learner_error(failure['callback'], failure)
        want = reply['published'].get(topic, 0) - base['published'].get(topic, 0)
        if not observer.wait_until(lambda: len(observer.readings) - first >= want,
                                   ARRIVAL_TIMEOUT_S):
            raise CheckFailed(f'The node published {want} readings, but only '
                              f'{len(observer.readings) - first} arrived: is something else '
                              'wrong with the publisher (its queue depth)?')
    lines = caught_up(judge, info, log_mark, reply['logged'] - base['logged'])
    return observer.readings[first:], lines, reply['fired'] - base['fired']


def _log_format_verdict(readings: list[float], lines: list[str]) -> None:
    """Each reading has a log line that shows it (two decimals, as 'Publishing: 22.31C').

    The start-up line may arrive among them (over /rosout): lines are matched to readings
    by the number they show, not by position.
    """
    def shows(line: str, reading: float) -> bool:
        return any(abs(float(n) - reading) <= LOGGED_READING_TOLERANCE_C
                   for n in re.findall(r'-?\d+(?:\.\d+)?', line))

    unshown = [r for r in readings if not any(shows(line, r) for line in lines)]
    if unshown:
        odd = [line for line in lines if not any(shows(line, r) for r in readings)]
        said = f'"{odd[-1]}"' if odd else 'lines without it'
        raise CheckFailed(f'publish_temperature logged {said} for a reading of {unshown[0]:.2f} '
                          f"°C: show the reading in its line, e.g. 'Publishing: {unshown[0]:.2f}C'.")


def _samples_verdict(samples: list[float], *, seconds: float,
                     start_c: float = course.START_TEMPERATURE_C) -> None:
    """Raise CheckFailed for the first rule a run of readings breaks."""
    low, high = course.MIN_TEMPERATURE_C, course.MAX_TEMPERATURE_C
    if abs(len(samples) - seconds / course.PUBLISH_PERIOD_S) > 1:
        raise CheckFailed(f'{len(samples)} readings in {seconds:g} s; expected one every '
                          f'{course.PUBLISH_PERIOD_S} s: check the timer period.')
    if samples and abs(samples[0] - start_c) > course.MAX_STEP_C + FLOAT32_TOLERANCE_C:
        raise CheckFailed(f'The first reading is {samples[0]:.2f} °C, but self.temperature was '
                          f'{start_c} °C: each reading is the previous self.temperature plus one '
                          f'step of at most ±{course.MAX_STEP_C} °C.')
    for i, (a, b) in enumerate(zip(samples, samples[1:]), start=2):
        if abs(b - a) > course.MAX_STEP_C + FLOAT32_TOLERANCE_C:
            raise CheckFailed(f'Reading {i} jumps {b - a:+.2f} °C ({a:.2f} to {b:.2f}); one step '
                              f'is at most ±{course.MAX_STEP_C} °C (MAX_STEP_C).')
    if len(samples) > 2 and max(samples) - min(samples) < FLOAT32_TOLERANCE_C:
        raise CheckFailed(f'Every reading is {samples[0]:.2f} °C: add a random step between '
                          f'-MAX_STEP_C and +MAX_STEP_C to self.temperature each time.')
    for value in samples:
        if value > high + FLOAT32_TOLERANCE_C:
            raise CheckFailed(f'A reading of {value:.2f} °C is above MAX_TEMPERATURE_C = {high} °C: '
                              f'clamp every new reading into [{low}, {high}].')
        if value < low - FLOAT32_TOLERANCE_C:
            tutorial = (' (the tutorial\'s floor of 10.2 °C lets it fall too far)'
                        if value >= 10.2 - FLOAT32_TOLERANCE_C else '')
            raise CheckFailed(f'A reading of {value:.2f} °C is below MIN_TEMPERATURE_C = {low} '
                              f'°C{tutorial}: clamp every new reading into [{low}, {high}].')


def check_publisher_samples(samples: list[float], *, seconds: float) -> None:
    """Check a recorded run of the sensor: one reading per second, walk and clamp respected.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param samples: readings in °C in the order received.
    :param seconds: simulated seconds the sensor ran.
    :raises CheckFailed: naming the first rule broken.
    """
    _samples_verdict(samples, seconds=seconds)
    passed(f'{len(samples)} readings, one every {course.PUBLISH_PERIOD_S} s, steps within '
           f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
           f'{course.MAX_TEMPERATURE_C}] °C.')


def _sensor_callback(judge: Judge) -> str:
    subject, info = new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                              seed=SENSOR_SEED)
    _sensor_verdict(judge, info, judge.observer.endpoints(info['name'], info['namespace'],
                                                          info['endpoints']))
    readings, logged, fired = _run_sensor(judge, subject, info, CALLBACK_RUN_S, seed=SENSOR_SEED)
    if not readings:
        raise CheckFailed('publish_temperature ran but nothing arrived on /temperature: put the '
                          'new reading into a Float32 message and publish it with the publisher '
                          'from __init__.' if fired else
                          'The timer never called publish_temperature: check the timer in part 3.')
    _publishes_verdict(judge)
    if len(logged) < len(readings):
        raise CheckFailed(f'{len(readings)} readings were published but {len(logged)} logged: log '
                          "each reading with the node's logger, e.g. 'Publishing: 22.31C'.")
    _log_format_verdict(readings, logged)
    _samples_verdict(readings, seconds=CALLBACK_RUN_S)
    for start_c, seed in zip(CLAMP_PROBES_C, (CEILING_SEED, FLOOR_SEED)):
        subject.request('set_attribute', name='temperature', value=start_c)
        probe, _, _ = _run_sensor(judge, subject, info, CLAMP_RUN_S, seed=seed)
        _samples_verdict(probe, seconds=CLAMP_RUN_S, start_c=start_c)
    return (f'{len(readings)} readings, one every {course.PUBLISH_PERIOD_S} s, from '
            f'{course.START_TEMPERATURE_C} °C in steps of at most ±{course.MAX_STEP_C} °C, held '
            f'inside [{course.MIN_TEMPERATURE_C}, {course.MAX_TEMPERATURE_C}] °C.')


def check_sensor_callback() -> None:
    """Check part 4 of ``temperature_publisher.py``: the timer callback.

    Runs your sensor for 20 simulated seconds and watches ``/temperature`` over ROS: one
    reading per second, the first within 0.5 °C of 22.0, steps of at most ±0.5 °C, one
    log line per reading; then starts the walk just inside each limit and checks that the
    clamp holds it in [18.0, 28.0] °C.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    judged('check_sensor_callback', _sensor_callback)


def _sensor_hour(judge: Judge) -> str:
    subject, info = new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                              seed=SENSOR_SEED + 1)
    _sensor_verdict(judge, info, judge.observer.endpoints(info['name'], info['namespace'],
                                                          info['endpoints']))
    seconds = 3600
    readings, _, _ = _run_sensor(judge, subject, info, seconds, step_s=5.0)
    _samples_verdict(readings, seconds=seconds)
    _publishes_verdict(judge)
    return (f'an hour of simulated time: {len(readings)} readings, steps within '
            f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C.')


def check_sensor_hour() -> None:
    """Hidden test of notebook 03: your sensor over one simulated hour (3600 readings).

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming the first rule broken.
    """
    judged('check_sensor_hour', _sensor_hour)


def check_sensor_main() -> None:
    """Check part 5 of ``temperature_publisher.py``: ``main()`` and Ctrl+C.

    Starts the file as a program (``python temperature_publisher.py``), presses Ctrl+C
    once its node spins and checks for exit code 0 and no traceback; then that ``main()`` destroys
    the node and shuts rclpy down in a ``finally:`` block.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    judged('check_sensor_main', run_main, relative=course.PUBLISHER_FILE,
           node_name=course.SENSOR_NODE)
