"""Checks of notebook 07, a live plot: the subscription callback that feeds the plot.

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``PlotFeeder`` (from
``live_plot.py``) in a subject, with the course's own ``redraw()`` in place of the given one
(part 1): it tells the judge, as plain data, every point it drew, as the node's lists held them
(:mod:`.witnessed`).  The judge moves its own clock on between readings it publishes from its
own node, draws the times of those steps for each run, and compares every drawing with the
readings it sent and the times it sent them: a drawing counts only when it holds every
reading so far, each with the time it arrived on the node's clock, which no code can tell
without keeping the readings as they arrive.  Nothing in the learner's process holds a key or
decides: a line the node logs decides nothing (any code can print one); the file, read as
text, only picks the words of a failure the judge has seen.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, Subject
from ..subject_interface import PlotShown, Run
from ..subject_replies import Counts, NodeMade
from .base import judged
from .drawn import chooser
from .file_nodes import feed, new_node, reach
from .source import ClassSource
from .verdicts import endpoint_verdict, node_name_verdict
from .witnessed import WITNESS_TOPIC, drawings, told_to

#: Readings the check publishes: this many, drawn for each run in steps of ``READING_STEP_C``
#: (exact in Float32) between the clamp's bounds, no two alike.
PLOT_READINGS, READING_STEP_C = 4, 0.25
#: Steps of the judge's clock between two readings (s).
READING_GAP_S = 1.0
#: How close a drawn reading must be to the one sent (°C): Float32 keeps about 7 digits.
READING_TOLERANCE_C = 0.006
#: Seconds the subject may sit idle (or work, in CPU seconds) after a reading of which the
#: course's redraw() told nothing, while the judge listens for a drawing told another way.
UNTOLD_PATIENCE_S = 2.0
#: Whole seconds of the judge's clock before the first reading, and between two readings,
#: drawn for each run (a point's time is then no table's: the first never comes at 1 s).
FIRST_GAP_S, NEXT_GAP_S = (2, 9), (1, 4)


def _gaps_s(judge: Judge) -> list[int]:
    """Simulated seconds before each reading, drawn for this run (:mod:`.drawn`)."""
    source = chooser(judge, '07 reading times')
    return [source.randint(*(FIRST_GAP_S if k == 0 else NEXT_GAP_S))
            for k in range(PLOT_READINGS)]


def readings_c(judge: Judge) -> list[float]:
    """The readings the check publishes (°C), drawn for this run (:mod:`.drawn`): a drawing
    holds them only when the callback kept what each message carried."""
    steps = round((course.MAX_TEMPERATURE_C - course.MIN_TEMPERATURE_C) / READING_STEP_C)
    chosen = chooser(judge, '07 readings').sample(range(steps + 1), PLOT_READINGS)
    return [course.MIN_TEMPERATURE_C + k * READING_STEP_C for k in chosen]


def _drawn(judge: Judge, subject: Subject, info: NodeMade, value: float, counts: Counts
           ) -> tuple[Counts, list[dict[str, Any]]]:
    """Feed one reading and return the subject's counts after it and what was drawn
    meanwhile (each drawing told: its ``times_s`` and ``temps_c``)."""
    heard = told_to(judge)
    mark, before = len(heard), counts.shown
    counts, _lines = feed(judge, subject, info, value, counts, 'temperature_callback.')
    after = counts.shown
    # as many messages as the subject says it told (it says nothing: one); where it says
    # none, what anything else in it told, until it sits idle a moment: a drawing counts for
    # what it holds, whoever told it
    expected = 1 if before is None or after is None else after - before
    judge.observer.wait_until(lambda: len(heard) - mark >= max(expected, 1),
                              ARRIVAL_TIMEOUT_S if expected else UNTOLD_PATIENCE_S)
    return counts, drawings(heard, mark)


def _plot_callback(judge: Judge) -> str:
    observer = judge.observer
    told_to(judge)  # the judge's subscription exists before the subject looks for it
    subject, info = new_node(judge, course.LIVE_PLOT_FILE, course.PLOT_CLASS)
    node_name_verdict(info, course.PLOT_NODE)
    found = observer.endpoints(info.name, info.namespace, info.endpoints)
    endpoint_verdict(info.name, found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE)
    shown = subject.request(PlotShown(topic=WITNESS_TOPIC, seconds=ARRIVAL_TIMEOUT_S),
                            timeout=ARRIVAL_TIMEOUT_S + 30)
    if not shown.ok:
        raise CheckFailed("The plot's witness never reached the grader: is the machine very "
                          'busy? Run this check again.')
    reach(judge, subject, info.name)
    counts: Counts = dataclasses.replace(info, shown=shown.shown)
    sent: list[tuple[float, float]] = []
    for value, gap_s in zip(readings_c(judge), _gaps_s(judge)):
        judge.clock.drive(subject, Run(seconds=gap_s), step_s=READING_GAP_S,
                          limit_s=gap_s, what=course.PLOT_CLASS)
        sent.append((judge.clock.now_s, value))
        counts, drawn = _drawn(judge, subject, info, value, counts)
        _point_verdict(judge, sent, drawn)
    return (f'each of {PLOT_READINGS} readings was plotted once, at the time it arrived '
            'on the node\'s clock (the grader\'s simulated time), with its value.')


def _point_verdict(judge: Judge, sent: list[tuple[float, float]],
                   drawn: list[dict[str, Any]]) -> None:
    """One redraw per reading, drawing every reading sent so far: its value, at the time
    it arrived (``sent``: the judge's ``(time, reading)`` of each)."""
    sent_s, value = sent[-1]
    number = len(sent)
    if not drawn:
        raise CheckFailed(f'For the reading {value} °C nothing was plotted: '
                          f'{_unplotted_cause(judge)}')
    if len(drawn) > 1:
        raise CheckFailed(f'For the reading {value} °C the plot was redrawn {len(drawn)} times: '
                          'call self.redraw() once per message, after appending, from the one '
                          'subscription __init__ makes (each subscription hands the callback '
                          'every reading).')
    times_s, temps_c = drawn[0].get('times_s') or [], drawn[0].get('temps_c') or []
    if len(temps_c) != number:
        raise CheckFailed(f'After {number} readings the plot holds {len(temps_c)} points: append '
                          'one time and one reading per message, no more.')
    for (at_s, reading), time_s, temp_c in zip(sent, times_s, temps_c):
        if temp_c is None or not math.isclose(temp_c, reading, abs_tol=READING_TOLERANCE_C):
            raise CheckFailed(f'For the reading {reading} °C the plot shows '
                              f'{"something that is no number" if temp_c is None else temp_c} '
                              '°C: append msg.data, the number the message carries.')
        if time_s is None or not math.isclose(time_s, at_s, abs_tol=1e-3):
            raise CheckFailed(f'A reading that arrived at {at_s:g} s of simulated time was '
                              f'plotted at {time_s if time_s is None else format(time_s, "g")} '
                              "s: use the node's clock in seconds, self.get_clock().now()"
                              '.nanoseconds / 1e9 (it follows simulated time).')
    if len(times_s) != number:
        raise CheckFailed(f'After {number} readings the plot holds {len(times_s)} times: append '
                          'one time and one reading per message, no more.')


def _unplotted_cause(judge: Judge) -> str:
    """What the callback leaves out, as the learner's file reads (only to word the line)."""
    source = ClassSource.read(judge.workspace, course.LIVE_PLOT_FILE, course.PLOT_CLASS)
    method: Optional[object] = source.method('temperature_callback') if source else None
    if source is not None and method is not None:
        for attribute, what in (('times_s', "the node's time, "
                                            'self.get_clock().now().nanoseconds / 1e9'),
                                ('temps_c', 'msg.data')):
            if not source.reaches_change('temperature_callback', attribute):
                return f'append {what} to self.{attribute} in temperature_callback.'
    return ('append the time and the reading, then call self.redraw() once per message '
            '(redraw() draws every point so far).')


@judged
def check_plot_callback(judge: Judge) -> str:
    """Check part 2 of ``live_plot.py``: the callback that feeds the live plot.

    The judge publishes 4 readings to your ``PlotFeeder``, their values and the times of its
    clock drawn for this run; its ``redraw()`` is the course's own (as given in part 1),
    telling the grader every point it draws: every reading plotted once, with its value and
    the node's simulated time when it arrived.

    Introduced in ``07-live-plot.ipynb``.

    :raises CheckFailed: naming what was plotted and what should have been.
    """
    return _plot_callback(judge)
