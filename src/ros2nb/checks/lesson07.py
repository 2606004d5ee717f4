"""Checks of notebook 07, a live plot: the subscription callback that feeds the plot.

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``PlotFeeder`` (from
``live_plot.py``) in a subject on simulated time, moves its clock on between readings it
publishes from its own node, and reads back what the node kept: the times, the readings
and how often it asked for a redraw.  Those values come from a process that ran the
learner's code, so they only name a mistake: the file, read as text, decides.
"""

from __future__ import annotations

import math

from std_msgs.msg import Float32

from .. import course
from ..errors import CheckFailed
from .base import ARRIVAL_TIMEOUT_S, Judge, judged, learner_error
from .nodes import new_node, reach
from .source import ClassSource
from .verdicts import endpoint_verdict, node_name_verdict

#: Readings the check publishes (°C), one simulated second apart; exact in Float32.
PLOT_READINGS_C = (21.5, 26.25, 19.75, 23.0)
#: Simulated seconds between two readings.
READING_GAP_S = 1.0


def _attribute(subject, name: str) -> list:
    reply = subject.request('attribute', name=name)
    if reply.get('missing'):
        raise CheckFailed(f'{course.PLOT_CLASS} has no attribute {name} any more: keep the lists '
                          'and the counter that part 1 makes.')
    value = reply['value']
    if value['type'] == 'list':
        return [item['value'] for item in value['value']]
    return value['value']


def _plot_callback(judge: Judge) -> str:
    subject, info = new_node(judge, course.LIVE_PLOT_FILE, course.PLOT_CLASS)
    node_name_verdict(info, course.PLOT_NODE)
    found = judge.observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    endpoint_verdict(info['name'], found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE)
    reach(judge, subject, info['name'])
    publisher = judge.probe_publisher
    times = []
    for value in PLOT_READINGS_C:
        # The node's clock subscription counts as received too: count from after the step.
        received = subject.request('advance', seconds=READING_GAP_S)['received']
        publisher.publish(Float32(data=value))
        reply = subject.request('wait_received', count=received + 1, seconds=ARRIVAL_TIMEOUT_S)
        if reply['failure']:
            raise learner_error(reply['failure']['callback'], reply['failure'],
                                context=f' for {value} °C')
        if not reply['ok']:
            raise CheckFailed(f'The reading {value} °C never reached temperature_callback.')
        times.append(reply['t'])
    verdict = _plot_verdict(subject, times)
    _plot_source_verdict(judge)
    return verdict


def _plot_source_verdict(judge: Judge) -> None:
    """The subscription's callback adds to ``times_s`` and ``temps_c`` and asks for a redraw,
    as the file (read as text) says.

    The lists and the counter are the subject's word, and a subject runs the learner's code,
    which may rewrite what it reports: their values only name a mistake, the source decides.
    """
    source = ClassSource.read(judge.workspace, course.LIVE_PLOT_FILE, course.PLOT_CLASS)
    callbacks = source.callbacks('create_subscription', 2) if source else []
    called = ', '.join(sorted(set(callbacks))) or 'nothing'
    for attribute, what in (('times_s', "the node's time, self.get_clock().now().nanoseconds "
                                        '/ 1e9'),
                            ('temps_c', 'msg.data')):
        if source is None or not any(source.reaches_change(c, attribute) for c in callbacks):
            raise CheckFailed(f'The subscription calls {called}, which never adds to '
                              f'self.{attribute}: append {what} to it there.')
    if not any(source.reaches_assignment(c, 'redraws') for c in callbacks):
        raise CheckFailed(f'The subscription calls {called}, which never calls self.redraw() '
                          '(the method that counts self.redraws): call it once per message.')


def _plot_verdict(subject, times: list[float]) -> str:
    count = len(PLOT_READINGS_C)
    temps = _attribute(subject, 'temps_c')
    if len(temps) != count:
        raise CheckFailed(f'After {count} readings temps_c holds {len(temps)} values: append '
                          'msg.data once for every message.')
    if any(not isinstance(t, (int, float)) or not math.isclose(t, want, abs_tol=1e-4)
           for t, want in zip(temps, PLOT_READINGS_C)):
        raise CheckFailed(f'temps_c holds {temps} for the readings {list(PLOT_READINGS_C)}: '
                          'append msg.data, the number the message carries.')
    stamps = _attribute(subject, 'times_s')
    if len(stamps) != count:
        raise CheckFailed(f'After {count} readings times_s holds {len(stamps)} values: append '
                          'one time for every message, next to its reading.')
    wrong = next(((got, want) for got, want in zip(stamps, times)
                  if not isinstance(got, (int, float)) or not math.isclose(got, want,
                                                                           abs_tol=1e-3)), None)
    if wrong is not None:
        raise CheckFailed(f'A reading that arrived at {wrong[1]:g} s of simulated time got the '
                          f'time {wrong[0]!r}: use the node\'s clock in seconds, '
                          'self.get_clock().now().nanoseconds / 1e9 (it follows simulated time).')
    redraws = _attribute(subject, 'redraws')
    if redraws != count:
        raise CheckFailed(f'After {count} readings the plot was redrawn {redraws} times: call '
                          'self.redraw() once per message, after appending.')
    return (f'each of {count} readings went into the plot with its simulated time, one redraw '
            'per message.')


def check_plot_callback() -> None:
    """Check part 2 of ``live_plot.py``: the callback that feeds the live plot.

    The judge publishes 4 readings one simulated second apart to your ``PlotFeeder`` and
    reads ``times_s``, ``temps_c`` and ``redraws``: every reading with the node's simulated
    time, and one redraw per message.  It also reads in your file that the subscription's
    callback appends to both lists and calls ``self.redraw()``.

    Introduced in ``07-live-plot.ipynb``.

    :raises CheckFailed: naming what the lists hold and what they should.
    """
    judged('check_plot_callback', _plot_callback)
