"""Checks of notebook 03, write the publisher: the sensor's constructor, callback and main().

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``TemperatureSensor`` in a
subject, runs it on the judge's own clock (:mod:`ros2nb.judge.clock`) and decides from what
reaches its own node over ROS: the graph, each reading on ``/temperature`` with the
judge's time of its arrival, and the lines on ``/rosout``.  Each part is graded on its own:
while one part is checked, the course's stand-in may take the place of another
(:mod:`ros2nb.judge.stand_ins`).  The file, read as text, only picks the words of a
failure the judge has already seen.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Optional

from .. import course
from ..errors import CheckFailed
from ..judge_interface import Flooded, Judge
from .base import direct, judged
from .drawn import clamp_probes_c, sensor_seed
from .mains import run_main
from .sensor_rules import (FLOAT32_TOLERANCE_C, log_format_problem, period_problem,
                           samples_verdict)
from .sensor_runs import PROBE_S, TOPIC, SensorRun, run_sensor, sensor_run
from .source import TEXT, ClassSource
from .verdicts import endpoint_verdict, node_name_verdict

#: Simulated seconds the judge runs the sensor: for the constructor, the callback, each clamp
#: probe, and the hidden hour.
CONSTRUCTOR_RUN_S, CALLBACK_RUN_S, CLAMP_RUN_S, HOUR_S = 6, 20, 40, 3600


# ------------------------------------------------------------------ what each part must do
def _constructor_problem(judge: Judge, run: SensorRun, seconds: float) -> Optional[CheckFailed]:
    """What the constructor (part 3) got wrong, as the judge saw it: None when nothing."""
    try:
        node_name_verdict(run.info, course.SENSOR_NODE)
        endpoint_verdict(run.info.name, run.found, 'publisher', TOPIC, course.MESSAGE_TYPE,
                         run.info.endpoints)
    except CheckFailed as problem:
        return problem
    if run.problem is not None or not run.readings:
        return run.problem or CheckFailed(_no_readings(judge))
    period = period_problem(run.readings, seconds)
    if period is not None:
        return _timer_period(judge, len(run.readings), seconds) or period
    first = run.readings[0][1]
    if abs(first - course.START_TEMPERATURE_C) > course.MAX_STEP_C + FLOAT32_TOLERANCE_C:
        return CheckFailed(f'The first reading is {first:.2f} °C: the walk starts at '
                           f'START_TEMPERATURE_C = {course.START_TEMPERATURE_C} °C (set '
                           'self.temperature to it in __init__), and each reading is one step '
                           f'of at most ±{course.MAX_STEP_C} °C from the one before.')
    if not run.started_lines:
        return CheckFailed(f'{course.SENSOR_CLASS} logged nothing when it started: log a line '
                           "such as 'Temperature Sensor Node Started' with the node's logger.")
    return None


def _timer_period(judge: Judge, count: int, seconds: float) -> Optional[CheckFailed]:
    """The line for ``count`` readings in ``seconds``, too many or too few for
    PUBLISH_PERIOD_S, when the learner's one timer was given another period (read after the
    fact, and only when the count the judge heard agrees with it): that period, and the
    learner's line that set it; None otherwise (the count alone says it)."""
    source = ClassSource.read(judge.workspace, course.PUBLISHER_FILE, course.SENSOR_CLASS)
    timers = source.timers() if source is not None else []
    period = timers[0].period if len(timers) == 1 else None
    if source is None or not isinstance(period, (int, float)) or isinstance(period, bool) \
            or period <= 0 or abs(count - seconds / course.PUBLISH_PERIOD_S) <= 1 \
            or abs(count - seconds / period) > 1:
        return None
    line = source.defined_at(timers[0].named) if timers[0].named else timers[0].line
    lines = (TEXT.read(judge.workspace / course.PUBLISHER_FILE) or '').splitlines()
    if line is None or not 0 < line <= len(lines):
        return None
    where = f'({Path(course.PUBLISHER_FILE).name} line {line}: {lines[line - 1].strip()})'
    fix = (f'write {timers[0].named} = {course.PUBLISH_PERIOD_S}, as the course gives it'
           if timers[0].named else 'give the timer PUBLISH_PERIOD_S')
    expected = round(seconds / course.PUBLISH_PERIOD_S)
    return CheckFailed(f'The timer fires every {period} s {where}: {count} readings in '
                       f'{seconds:g} s of the grader\'s clock, where the sensor publishes one '
                       f'every {course.PUBLISH_PERIOD_S} s ({expected} in {seconds:g} s): {fix}.')


def _no_readings(judge: Judge) -> str:
    """Why no reading arrived, in the words the learner's file suggests (read after the fact)."""
    source = ClassSource.read(judge.workspace, course.PUBLISHER_FILE, course.SENSOR_CLASS)
    if source is not None and not source.timers():
        return (f'No reading arrived on {TOPIC} in {CONSTRUCTOR_RUN_S} s: {course.SENSOR_CLASS} '
                'has no timer; create one in __init__ that calls self.publish_temperature '
                f'every PUBLISH_PERIOD_S = {course.PUBLISH_PERIOD_S} s.')
    return (f'No reading arrived on {TOPIC} in {CONSTRUCTOR_RUN_S} s of the grader\'s clock: '
            'make a timer in __init__ that calls self.publish_temperature (the method itself, '
            f'without parentheses) every PUBLISH_PERIOD_S = {course.PUBLISH_PERIOD_S} s.')


@direct
def check_publisher_samples(judge: Optional[Judge], samples: list[float], *,
                            seconds: float) -> str:
    """Check a recorded run of the sensor: one reading per second, walk and clamp respected.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param samples: readings in °C in the order received.
    :param seconds: simulated seconds the sensor ran.
    :raises CheckFailed: naming the first rule broken.
    """
    samples_verdict(samples, seconds=seconds)
    return (f'{len(samples)} readings, one every {course.PUBLISH_PERIOD_S} s, steps within '
            f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C.')


# ------------------------------------------------------------------ part 3: the constructor
def _attempt(judge: Judge, stand_ins: tuple[str, ...]) -> tuple[Optional[SensorRun],
                                                                 Optional[CheckFailed]]:
    """A constructor run with ``stand_ins``, and what part 3 got wrong in it (None: nothing)."""
    try:
        run = sensor_run(judge, stand_ins, CONSTRUCTOR_RUN_S, probe_s=PROBE_S,
                          seed=sensor_seed(judge, '03 sensor constructor'))
    except CheckFailed as problem:
        return None, problem
    return run, _constructor_problem(judge, run, CONSTRUCTOR_RUN_S)


def _sensor_constructor(judge: Judge) -> str:
    """Part 3 alone: the learner's __init__, with the course's callback, as the check
    promises.  Their own callback is tried only when the course's found fault with it: a
    constructor of another style that works with the learner's own callback passes; else
    what the course's callback found is the verdict (part 4 may not be written yet)."""
    run, problem = _attempt(judge, ('sensor_callback',))
    if problem is not None and not isinstance(problem, Flooded):  # theirs would flood too
        own, own_problem = _attempt(judge, ())
        if own_problem is None:
            run, problem = own, None
    if problem is not None:
        raise problem
    assert run is not None
    return (f'{run.info.name} publishes {course.MESSAGE_TYPE} on {TOPIC} every '
            f'{course.PUBLISH_PERIOD_S} s of the grader\'s clock, starting next to '
            f'{course.START_TEMPERATURE_C} °C.')


@judged
def check_sensor_constructor(judge: Judge) -> str:
    """Check part 3 of ``temperature_publisher.py``: the sensor's ``__init__``.

    Creates your ``TemperatureSensor`` (with the course's ``publish_temperature``, so that
    only your constructor counts) and runs it on the grader's clock: its name and publisher
    (topic and type, as the ROS graph shows them), one reading every second, the first next
    to 22.0 °C, and a start-up log line.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming what was seen and what was expected.
    """
    return _sensor_constructor(judge)


# ------------------------------------------------------------------ part 4: the callback
def _callback_run(judge: Judge, seconds: float, seed: int) -> SensorRun:
    """The learner's callback running ``seconds``: in their own sensor, or, when its
    constructor is at fault, in the course's (a mistake in part 3 costs part 3 only)."""
    whole = seconds <= CALLBACK_RUN_S  # else a short probe decides whose constructor runs
    trial_s = seconds if whole else CONSTRUCTOR_RUN_S
    stand_ins: tuple[str, ...] = ()
    try:
        run: Optional[SensorRun] = sensor_run(judge, (), trial_s, probe_s=PROBE_S, seed=seed)
    except Flooded:  # its constructor floods: part 3's fault, which the course's stands in for
        run = None
    if run is None or _constructor_problem(judge, run, trial_s) is not None:
        stand_ins = ('sensor_init',)
        run = sensor_run(judge, stand_ins, trial_s, probe_s=PROBE_S, seed=seed)
    if whole:
        return run
    return sensor_run(judge, stand_ins, seconds, probe_s=0.0, seed=seed)


def _callback_problem(judge: Judge, run: SensorRun, seconds: float) -> None:
    """Raise for what the callback (part 4) got wrong in ``run``."""
    if run.problem is not None:
        raise run.problem
    if not run.readings:
        raise CheckFailed(f'publish_temperature ran but nothing arrived on {TOPIC}: put the new '
                          'reading into a Float32 message and publish it with the publisher '
                          'from __init__.')
    try:
        samples_verdict(run.values, seconds=seconds)
    except CheckFailed as broken:
        raise _walk_not_kept(judge) or broken
    logged = log_format_problem(run)
    if logged is not None:
        raise logged
    made = judge.observer.count_endpoints(run.info.name, run.info.namespace, 'publisher', TOPIC)
    if made > 1:  # each call makes another, and publishes on it: the readings still arrive
        raise CheckFailed(f'{run.info.name} has {made} publishers on {TOPIC} after '
                          f'{len(run.readings)} readings: publish_temperature makes a new one '
                          'each time it runs: create it once, in __init__, and publish with '
                          'self.publisher_.')


def _walk_not_kept(judge: Judge) -> Optional[CheckFailed]:
    """The line for a walk the readings broke because publish_temperature never keeps its new
    value in self.temperature (a local name instead, read after the fact), or None."""
    source = ClassSource.read(judge.workspace, course.PUBLISHER_FILE, course.SENSOR_CLASS)
    callback = source.method('publish_temperature') if source is not None else None
    if callback is None or source is None or \
            source.reaches_assignment('publish_temperature', 'temperature'):
        return None
    local = next((node for node in ast.walk(callback) if isinstance(node, ast.Assign) and any(
        isinstance(t, ast.Name) and t.id == 'temperature' for t in node.targets)), None)
    lines = (TEXT.read(judge.workspace / course.PUBLISHER_FILE) or '').splitlines()
    where = (f'it sets a local name temperature ({Path(course.PUBLISHER_FILE).name} line '
             f'{local.lineno}: {lines[local.lineno - 1].strip()}), which is gone when it returns, '
             'so ') if local is not None and local.lineno <= len(lines) else ''
    return CheckFailed(f'publish_temperature never changes self.temperature: {where}'
                       'self.temperature stays where __init__ set it and every reading is one '
                       'step from there: keep the new value, self.temperature = ..., so that '
                       'the walk goes on from it.')


def _sensor_callback(judge: Judge) -> str:
    run = _callback_run(judge, CALLBACK_RUN_S, sensor_seed(judge, '03 sensor callback'))
    _callback_problem(judge, run, CALLBACK_RUN_S)
    for number, start_c in enumerate(clamp_probes_c(judge)):
        seed = sensor_seed(judge, f'03 clamp probe {number}', start_c, CLAMP_RUN_S)
        probe = run_sensor(judge, run, CLAMP_RUN_S, probe_s=0.0, seed=seed, start_c=start_c)
        if probe.problem is not None:
            raise probe.problem
        samples_verdict(probe.values, seconds=CLAMP_RUN_S, start_c=start_c)
    return (f'{len(run.readings)} readings, one every {course.PUBLISH_PERIOD_S} s, from '
            f'{course.START_TEMPERATURE_C} °C in steps of at most ±{course.MAX_STEP_C} °C, held '
            f'inside [{course.MIN_TEMPERATURE_C}, {course.MAX_TEMPERATURE_C}] °C, each logged.')


@judged
def check_sensor_callback(judge: Judge) -> str:
    """Check part 4 of ``temperature_publisher.py``: the timer callback.

    Runs your sensor for 20 s of the grader's clock and watches ``/temperature`` over ROS:
    one reading per second, the first within 0.5 °C of 22.0, steps of at most ±0.5 °C, one
    log line showing each reading; then starts the walk just inside each limit (at places and
    with seeds drawn for this run, then at 27.95 and 18.05 °C) and checks that the clamp holds
    it in [18.0, 28.0] °C.  When your constructor is at fault, the
    course's stands in for it, so that only your callback counts.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming what was seen and what was expected.
    """
    return _sensor_callback(judge)


def _sensor_hour(judge: Judge) -> str:
    run = _callback_run(judge, HOUR_S,
                        sensor_seed(judge, '03 sensor hour', course.START_TEMPERATURE_C, HOUR_S))
    if run.problem is not None:
        raise run.problem
    samples_verdict(run.values, seconds=HOUR_S)
    return (f'an hour of simulated time: {len(run.readings)} readings, steps within '
            f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C.')


@judged
def check_sensor_hour(judge: Judge) -> str:
    """Hidden test of notebook 03: your sensor over one hour of the grader's clock (3600 readings).

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming the first rule broken.
    """
    return _sensor_hour(judge)


@judged
def check_sensor_main(judge: Judge) -> str:
    """Check part 5 of ``temperature_publisher.py``: ``main()`` and Ctrl+C.

    Runs your ``main()`` as ``ros2 run`` does, presses Ctrl+C once its node spins (it
    answers the grader) and expects exit code 0 with no traceback.  When your node class is
    at fault, the course's stands in for it, so that only ``main()`` counts.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    return run_main(judge, relative=course.PUBLISHER_FILE, node_name=course.SENSOR_NODE,
                    node_class=course.SENSOR_CLASS)
