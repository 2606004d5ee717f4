"""Checks of notebook 07, a live plot: the subscription callback that feeds the plot.

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``PlotFeeder`` (from
``live_plot.py``) in a subject, moves its own clock on between readings it publishes from
its own node, and reads what the node says on ``/rosout``: its ``redraw()`` (part 1, given)
logs each point it plots, with its time and its reading.  So the judge hears, for every
reading it sent, whether a point was plotted, with which time and value.  The file, read
as text, only picks the words of a failure the judge has seen.
"""

from __future__ import annotations

import math
import re
from typing import Optional

from .. import course
from ..errors import CheckFailed
from ..judge_interface import Judge
from .base import judged
from .drawn import chooser
from .file_nodes import feed, lines_logged, new_node, reach
from .source import ClassSource
from .verdicts import endpoint_verdict, node_name_verdict

#: Readings the check publishes (°C); exact in Float32.
PLOT_READINGS_C = (21.5, 26.25, 19.75, 23.0)
#: Steps of the judge's clock between two readings (s).
READING_GAP_S = 1.0
#: Whole seconds of the judge's clock before the first reading, and between two readings,
#: drawn for each run (a point's time is then no table's: the first never comes at 1 s).
FIRST_GAP_S, NEXT_GAP_S = (2, 9), (1, 4)


def _gaps_s(judge: Judge) -> list[int]:
    """Simulated seconds before each reading, drawn for this run (:mod:`.drawn`)."""
    source = chooser(judge, '07 reading times')
    return [source.randint(*(FIRST_GAP_S if k == 0 else NEXT_GAP_S))
            for k in range(len(PLOT_READINGS_C))]
#: The line ``redraw()`` logs for each point (part 1 of live_plot.py).
PLOTTED = re.compile(r'Plotted (-?[\d.]+) °C at (-?[\d.]+) s, point (\d+)')


def _plotted(lines: list[str]) -> list[tuple[float, float, int]]:
    """(reading, time, number) of each point a list of log lines says was plotted."""
    found = []
    for line in lines:
        match = PLOTTED.fullmatch(line)
        if match:
            found.append((float(match.group(1)), float(match.group(2)), int(match.group(3))))
    return found


def _plot_callback(judge: Judge) -> str:
    observer = judge.observer
    mark = len(observer.logs)
    subject, info = new_node(judge, course.LIVE_PLOT_FILE, course.PLOT_CLASS)
    node_name_verdict(info, course.PLOT_NODE)
    found = observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    endpoint_verdict(info['name'], found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE)
    lines_logged(judge, info, mark, info['started_lines'])
    reach(judge, subject, info['name'])
    counts = info
    for number, (value, gap_s) in enumerate(zip(PLOT_READINGS_C, _gaps_s(judge)), start=1):
        judge.clock.drive(subject, 'run', seconds=gap_s, step_s=READING_GAP_S,
                          limit_s=gap_s, what=course.PLOT_CLASS)
        sent_s = judge.clock.now_s
        counts, lines = feed(judge, subject, info, value, counts, 'temperature_callback.')
        _point_verdict(judge, value, sent_s, number, _plotted(lines))
    return (f'each of {len(PLOT_READINGS_C)} readings was plotted once, at the time it arrived '
            'on the node\'s clock (the grader\'s simulated time), with its value.')


def _point_verdict(judge: Judge, value: float, sent_s: float, number: int,
                   points: list[tuple[float, float, int]]) -> None:
    """One point per reading: this reading, at the time it arrived, the next in the plot."""
    if not points:
        raise CheckFailed(f'For the reading {value} °C nothing was plotted: '
                          f'{_unplotted_cause(judge)}')
    if len(points) > 1:
        raise CheckFailed(f'For the reading {value} °C the plot was redrawn {len(points)} times: '
                          'call self.redraw() once per message, after appending.')
    reading, time_s, count = points[0]
    if count != number:
        raise CheckFailed(f'After {number} readings the plot holds {count} points: append one '
                          'time and one reading per message, no more.')
    if not math.isclose(reading, value, abs_tol=0.006):
        raise CheckFailed(f'For the reading {value} °C the plot shows {reading} °C: append '
                          'msg.data, the number the message carries.')
    if not math.isclose(time_s, sent_s, abs_tol=1e-3):
        raise CheckFailed(f'A reading that arrived at {sent_s:g} s of simulated time was plotted '
                          f'at {time_s:g} s: use the node\'s clock in seconds, '
                          'self.get_clock().now().nanoseconds / 1e9 (it follows simulated time).')


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
            '(redraw() plots the newest point and logs it).')


@judged
def check_plot_callback(judge: Judge) -> str:
    """Check part 2 of ``live_plot.py``: the callback that feeds the live plot.

    The judge publishes 4 readings to your ``PlotFeeder``, at times of its clock drawn for
    this run, and listens to what it plots (``redraw()`` logs each point on ``/rosout``):
    every reading plotted once, with its value and the node's simulated time when it arrived.

    Introduced in ``07-live-plot.ipynb``.

    :raises CheckFailed: naming what was plotted and what should have been.
    """
    return _plot_callback(judge)
