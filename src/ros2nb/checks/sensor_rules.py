"""The rules of the sensor's readings, held against what the judge heard (notebook 03).

Part of :mod:`ros2nb.checks`: one reading per period of the judge's clock, a walk from
22.0 °C in steps of at most ±0.5 °C, clamped into the course's limits, each reading logged.
Each function names the first rule a run breaks, in the learner's terms; it never looks at
the learner's code.  Used by :mod:`.lesson03` on the runs of :mod:`.sensor_runs`.
"""

from __future__ import annotations

import math
import re
from typing import Optional

from .. import course
from ..errors import CheckFailed
from .sensor_runs import TOPIC, SensorRun

#: Tolerance for values that went through a 32-bit float (°C).
FLOAT32_TOLERANCE_C = 1e-4
#: How far a logged number may be from its reading (°C): two decimals, rounded either way.
LOGGED_READING_TOLERANCE_C = 0.011


def period_problem(readings: list[tuple[float, float]], seconds: float) -> Optional[CheckFailed]:
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
    # The judge's clock moves in steps (and stops just before each whole one), so arrival
    # times say only which step a reading came in: a count says the period, a time off the
    # whole steps only that it is not one.
    expected = round(seconds / period)
    if abs(len(readings) - seconds / period) > 1:
        return CheckFailed(f'{len(readings)} readings in {seconds:g} s of the grader\'s clock; '
                           f'the sensor publishes one every {period} s ({expected} in '
                           f'{seconds:g} s): give the timer PUBLISH_PERIOD_S.')
    odd = any(not math.isclose(gap, period, abs_tol=1e-6) for gap in gaps) or any(
        abs(t - round(t / period) * period) > 1e-6 for t in times)
    if odd:
        return CheckFailed(f'The readings came between the grader\'s whole seconds: the timer\'s '
                           f'period is not {period} s: give the timer PUBLISH_PERIOD_S.')
    if times and times[0] > period + 1e-6:
        return CheckFailed(f'The first reading came after {times[0]:g} s; the timer fires every '
                           f'{period} s: give the timer PUBLISH_PERIOD_S.')
    return None


def log_format_problem(run: SensorRun) -> Optional[CheckFailed]:
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


def samples_verdict(samples: list[float], *, seconds: float,
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
        if start_c != course.START_TEMPERATURE_C:  # a probe of the clamp, set by the grader
            raise CheckFailed(f'The grader set self.temperature to {start_c} °C, just inside '
                              f'the limits, and the next reading was {samples[0]:.2f} °C, more '
                              f'than one step of ±{course.MAX_STEP_C} °C away: clamp each new '
                              f'reading into [{low}, {high}] (MIN_TEMPERATURE_C to '
                              'MAX_TEMPERATURE_C), no narrower.')
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
