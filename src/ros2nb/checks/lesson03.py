"""Checks of notebook 03, write the publisher: the sensor's constructor, callback and main().

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``TemperatureSensor`` in a
subject, runs it on the judge's own clock (:mod:`ros2nb.judge.clock`) and decides from what
reaches its own node over ROS: the graph, each reading on ``/temperature`` with the
judge's time of its arrival, and the lines on ``/rosout``.  Each part is graded on its own:
while one part is checked, the course's stand-in may take the place of another
(:mod:`ros2nb.subject.stand_ins`).  The file, read as text, only picks the words of a
failure the judge has already seen.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any, Optional

from std_msgs.msg import Float32

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Flooded, Judge, learner_error
from .base import direct, judged
from .drawn import clamp_probes_c, sensor_seed
from .mains import run_main
from .file_nodes import lines_logged, new_node
from .source import ClassSource
from .verdicts import endpoint_verdict, node_name_verdict

#: Tolerance for values that went through a 32-bit float (°C).
FLOAT32_TOLERANCE_C = 1e-4
#: How far a logged number may be from its reading (°C): two decimals, rounded either way.
LOGGED_READING_TOLERANCE_C = 0.011
#: Simulated seconds the judge runs the sensor: for the constructor, the callback, each clamp
#: probe, and the hidden hour.
CONSTRUCTOR_RUN_S, CALLBACK_RUN_S, CLAMP_RUN_S, HOUR_S = 6, 20, 40, 3600
#: Steps of the judge's clock (s), and the probe before each while a constructor runs: a timer
#: of another period fires on the probe, off the whole periods (JudgeClock.drive's probe_s).
STEP_S, PROBE_S = course.PUBLISH_PERIOD_S, 0.001
TOPIC = '/' + course.TOPIC


@dataclass
class SensorRun:
    """What the judge saw of one sensor made in a subject, run on the judge's clock.

    :ivar subject: the subject process the node runs in.
    :ivar info: the subject's reply to ``new_node`` (name, namespace).
    :ivar found: the node's endpoints as the judge's graph shows them.
    :ivar started_lines: the lines it logged while it was made.
    :ivar readings: ``(seconds since the run began on the judge's clock, °C)``.
    :ivar lines: the node's /rosout lines during the run.
    :ivar problem: what stopped the run early (a callback that raised), or None.
    """

    subject: Any
    info: dict
    found: list
    started_lines: list[str]
    readings: list[tuple[float, float]] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    problem: Optional[CheckFailed] = None

    @property
    def values(self) -> list[float]:
        return [value for _t, value in self.readings]


def _make_sensor(judge: Judge, stand_ins: tuple[str, ...], seed: int) -> SensorRun:
    """The learner's sensor (with the course's ``stand_ins``), made in a subject."""
    observer = judge.observer
    observer.watch(TOPIC, Float32, lambda m: float(m.data))  # before it can publish
    mark = len(observer.logs)
    subject, info = new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                             stand_ins=stand_ins, seed=seed)
    found = observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    return SensorRun(subject, info, found, lines_logged(judge, info, mark, info['started_lines']))


def _run(judge: Judge, sensor: SensorRun, seconds: float, *, probe_s: float, seed: int,
         start_c: Optional[float] = None) -> SensorRun:
    """Run ``sensor`` ``seconds`` of the judge's clock (the walk from ``start_c`` if given,
    ``probe_s``: :data:`PROBE_S` or 0); return what the judge heard, as a run of its own."""
    observer, subject = judge.observer, sensor.subject
    readings = observer.watch(TOPIC, Float32, lambda m: float(m.data))
    run = SensorRun(subject, sensor.info, sensor.found, sensor.started_lines)
    if ('publisher', TOPIC, course.MESSAGE_TYPE) not in run.found:
        return run  # nothing the judge could hear: the constructor's verdict says why
    if start_c is not None:
        subject.request('set_attribute', name='temperature', value=start_c)
    if not subject.request('wait_matched', topic=TOPIC, seconds=ARRIVAL_TIMEOUT_S)['ok']:
        raise CheckFailed(f'The publisher on {TOPIC} never reached the grader\'s subscription '
                          '(is the machine very busy?): run this check again.')
    first, log_mark, began = len(readings), len(observer.logs), judge.clock.now_ns
    try:
        reply = judge.clock.drive(subject, 'run', seconds=seconds, seed=seed, step_s=STEP_S,
                                  probe_s=probe_s, limit_s=seconds + 1, what=course.SENSOR_CLASS)
        if reply.get('failure'):
            raise learner_error(reply['failure']['callback'], reply['failure'])
    except CheckFailed as problem:
        run.problem = problem
    run.readings = [((heard.t_ns - began) / 1e9, heard.value) for heard in readings[first:]]
    run.lines = [line.text for line in observer.logs[log_mark:] if line.name == run.info['name']]
    return run


def _sensor_run(judge: Judge, stand_ins: tuple[str, ...], seconds: float, *, probe_s: float,
                seed: int) -> SensorRun:
    """A new sensor of the learner's (with ``stand_ins``), run ``seconds``."""
    return _run(judge, _make_sensor(judge, stand_ins, seed), seconds, probe_s=probe_s, seed=seed)


# ------------------------------------------------------------------ what each part must do
def _constructor_problem(judge: Judge, run: SensorRun, seconds: float) -> Optional[CheckFailed]:
    """What the constructor (part 3) got wrong, as the judge saw it: None when nothing."""
    try:
        node_name_verdict(run.info, course.SENSOR_NODE)
        endpoint_verdict(run.info['name'], run.found, 'publisher', TOPIC, course.MESSAGE_TYPE)
    except CheckFailed as problem:
        return problem
    if run.problem is not None or not run.readings:
        return run.problem or CheckFailed(_no_readings(judge))
    problem = _period_problem(run.readings, seconds)
    if problem is not None:
        return problem
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


def _period_problem(readings: list[tuple[float, float]], seconds: float) -> Optional[CheckFailed]:
    """One reading per period, on the judge's clock: the timer's period and count."""
    period = course.PUBLISH_PERIOD_S
    if not readings:
        return CheckFailed(f'No reading arrived on {TOPIC} in {seconds:g} s of the grader\'s '
                           'clock: publish_temperature must publish each reading with the '
                           'publisher made in __init__.')
    times = [t for t, _v in readings]
    gaps = [b - a for a, b in zip(times, times[1:])]
    together = next((t for t, gap in zip(times, gaps) if gap < 1e-6), None)
    if together is not None:
        count = times.count(together)
        return CheckFailed(f'{count} readings arrived at the same moment ({together:g} s of the '
                           'grader\'s clock): publish one message per timer call, from one timer.')
    odd = next((gap for gap in gaps if not math.isclose(gap, period, abs_tol=1e-6)), None)
    if odd is not None:
        return CheckFailed(f'Readings came {odd:g} s apart on the grader\'s clock; the sensor '
                           f'publishes every {period} s: give the timer PUBLISH_PERIOD_S.')
    off = next((t for t in times if abs(t - round(t / period) * period) > 1e-6), None)
    if off is not None:
        return CheckFailed(f'A reading came {off:g} s after the sensor started on the grader\'s '
                           f'clock, off its whole periods of {period} s: use PUBLISH_PERIOD_S.')
    if times and times[0] > period + 1e-6:
        return CheckFailed(f'The first reading came after {times[0]:g} s; the timer fires every '
                           f'{period} s: give the timer PUBLISH_PERIOD_S.')
    if abs(len(readings) - seconds / period) > 1:
        return CheckFailed(f'{len(readings)} readings in {seconds:g} s; expected one every '
                           f'{period} s: check the timer period.')
    return None


def _log_format_problem(run: SensorRun) -> Optional[CheckFailed]:
    """Each reading has a log line that shows it (two decimals, as 'Publishing: 22.31C')."""
    values, lines = run.values, run.lines

    def shows(line: str, reading: float) -> bool:
        return any(abs(float(n) - reading) <= LOGGED_READING_TOLERANCE_C
                   for n in re.findall(r'-?\d+(?:\.\d+)?', line))

    if len(lines) < len(values):
        return CheckFailed(f'{len(values)} readings were published but {len(lines)} logged: log '
                           "each reading with the node's logger, e.g. 'Publishing: 22.31C'.")
    unshown = [r for r in values if not any(shows(line, r) for line in lines)]
    if unshown:
        odd = [line for line in lines if not any(shows(line, r) for r in values)]
        said = f'"{odd[-1]}"' if odd else 'lines without it'
        return CheckFailed(f'publish_temperature logged {said} for a reading of {unshown[0]:.2f} '
                           "°C: show the reading in its line, e.g. "
                           f"'Publishing: {unshown[0]:.2f}C'.")
    return None


def _samples_verdict(samples: list[float], *, seconds: float,
                     start_c: float = course.START_TEMPERATURE_C) -> None:
    """Raise CheckFailed for the first rule of the walk a run of readings breaks."""
    low, high = course.MIN_TEMPERATURE_C, course.MAX_TEMPERATURE_C
    if not samples:
        raise CheckFailed(f'No reading arrived on {TOPIC} in {seconds:g} s of the grader\'s '
                          'clock: publish_temperature must publish each reading with the '
                          'publisher made in __init__.')
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
            raise CheckFailed(f'A reading of {value:.2f} °C is above MAX_TEMPERATURE_C = {high} '
                              f'°C: clamp every new reading into [{low}, {high}].')
        if value < low - FLOAT32_TOLERANCE_C:
            tutorial = (' (the tutorial\'s floor of 10.2 °C lets it fall too far)'
                        if value >= 10.2 - FLOAT32_TOLERANCE_C else '')
            raise CheckFailed(f'A reading of {value:.2f} °C is below MIN_TEMPERATURE_C = {low} '
                              f'°C{tutorial}: clamp every new reading into [{low}, {high}].')


@direct
def check_publisher_samples(judge: Optional[Judge], samples: list[float], *,
                            seconds: float) -> str:
    """Check a recorded run of the sensor: one reading per second, walk and clamp respected.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param samples: readings in °C in the order received.
    :param seconds: simulated seconds the sensor ran.
    :raises CheckFailed: naming the first rule broken.
    """
    _samples_verdict(samples, seconds=seconds)
    return (f'{len(samples)} readings, one every {course.PUBLISH_PERIOD_S} s, steps within '
            f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C.')


# ------------------------------------------------------------------ part 3: the constructor
def _attempt(judge: Judge, stand_ins: tuple[str, ...]) -> tuple[Optional[SensorRun],
                                                                 Optional[CheckFailed]]:
    """A constructor run with ``stand_ins``, and what part 3 got wrong in it (None: nothing)."""
    try:
        run = _sensor_run(judge, stand_ins, CONSTRUCTOR_RUN_S, probe_s=PROBE_S,
                          seed=sensor_seed(judge, '03 sensor constructor'))
    except CheckFailed as problem:
        return None, problem
    return run, _constructor_problem(judge, run, CONSTRUCTOR_RUN_S)


def _sensor_constructor(judge: Judge) -> str:
    """Part 3 alone: the learner's __init__, with the course's callback (their own when the
    course's cannot work with their constructor)."""
    run, problem = _attempt(judge, ('sensor_callback',))
    if problem is not None and not isinstance(problem, Flooded):  # theirs would flood too
        own, own_problem = _attempt(judge, ())
        if own_problem is None:
            run, problem = own, None
        elif run is not None and (run.problem is not None or not run.readings):
            problem = own_problem  # the course's callback could not run there: theirs says more
    if problem is not None:
        raise problem
    assert run is not None
    return (f'{run.info["name"]} publishes {course.MESSAGE_TYPE} on {TOPIC} every '
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
        run: Optional[SensorRun] = _sensor_run(judge, (), trial_s, probe_s=PROBE_S, seed=seed)
    except Flooded:  # its constructor floods: part 3's fault, which the course's stands in for
        run = None
    if run is None or _constructor_problem(judge, run, trial_s) is not None:
        stand_ins = ('sensor_init',)
        run = _sensor_run(judge, stand_ins, trial_s, probe_s=PROBE_S, seed=seed)
    if whole:
        return run
    return _sensor_run(judge, stand_ins, seconds, probe_s=0.0, seed=seed)


def _callback_problem(run: SensorRun, seconds: float) -> None:
    """Raise for what the callback (part 4) got wrong in ``run``."""
    if run.problem is not None:
        raise run.problem
    if not run.readings:
        raise CheckFailed(f'publish_temperature ran but nothing arrived on {TOPIC}: put the new '
                          'reading into a Float32 message and publish it with the publisher '
                          'from __init__.')
    _samples_verdict(run.values, seconds=seconds)
    problem = _log_format_problem(run)
    if problem is not None:
        raise problem


def _sensor_callback(judge: Judge) -> str:
    run = _callback_run(judge, CALLBACK_RUN_S, sensor_seed(judge, '03 sensor callback'))
    _callback_problem(run, CALLBACK_RUN_S)
    for number, start_c in enumerate(clamp_probes_c(judge)):
        seed = sensor_seed(judge, f'03 clamp probe {number}', start_c, CLAMP_RUN_S)
        probe = _run(judge, run, CLAMP_RUN_S, probe_s=0.0, seed=seed, start_c=start_c)
        if probe.problem is not None:
            raise probe.problem
        _samples_verdict(probe.values, seconds=CLAMP_RUN_S, start_c=start_c)
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
    _samples_verdict(run.values, seconds=HOUR_S)
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
