"""What the course's own code in a subject shows the judge: the points a plot drew.

Part of :mod:`ros2nb.subject` (used by :mod:`.trials`), for the check of notebook 07.  The
course's ``redraw()`` (part 1 of ``live_plot.py``, given) tells the judge, as plain data,
every point it drew: the node's ``times_s`` and ``temps_c`` as it reads them.  Nothing here is
a secret or decides anything: the judge compares what it hears with the readings it sent
itself and the times it sent them (:mod:`ros2nb.checks.lesson07`), so a drawing from any
code in this process counts only when it holds what the callback had to keep: every reading
sent so far, each with the time it arrived on the node's clock.
"""

from __future__ import annotations

import numbers
import os
from typing import Any, Callable

from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from ..patience import wait_for_work

#: The course's node that publishes what it saw (not spun: publishing needs no executor).
SHOWN_NODE = 'ros2nb_shown'
#: Reliable and deep enough for every message of one check: the judge counts them all.
SHOWN_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)


class Shown:
    """The course's publisher on the judge's witness topic."""

    def __init__(self, topic: str) -> None:
        #: Messages told so far: how many the judge waits for, never what passes.
        self.told = 0
        self.node = Node(SHOWN_NODE, start_parameter_services=False, enable_rosout=False)
        self._publisher = self.node.create_publisher(String, topic, SHOWN_QOS)

    def reaches_judge(self, seconds: float) -> bool:
        """Wait (at most ``seconds`` of this process's work or idle waiting) until the judge's
        subscription matched: a volatile topic keeps nothing for a subscription discovered
        later."""
        return wait_for_work(lambda: self._publisher.get_subscription_count() >= 1,
                             [os.getpid()], seconds)

    def tell(self, text: str) -> None:
        """Publish one message."""
        self._publisher.publish(String(data=text))
        self.told += 1

    def close(self) -> None:
        """Destroy the course's node (and with it its publisher)."""
        self.node.destroy_node()


def drawing(node: Any) -> str:
    """``drawn TIMES;TEMPS``: the node's ``times_s`` and ``temps_c`` as they read now, each
    value as ``repr(float(v))``, ``x`` for what is no number."""
    lists = [[repr(float(v)) if isinstance(v, numbers.Real) else 'x'
              for v in list(getattr(node, name, None) or ())]
             for name in ('times_s', 'temps_c')]
    return 'drawn ' + ';'.join(','.join(values) for values in lists)


def plot_redraw(shown: Shown) -> Callable[[Any], None]:
    """The course's ``PlotFeeder.redraw`` (part 1 of live_plot.py, given), for a feeder
    without a figure: it counts, logs the newest point as part 1 does (so a list holding
    something other than numbers fails as it would there), and tells the judge every point
    it drew (:func:`drawing`)."""

    def redraw(self: Any) -> None:
        self.redraws = getattr(self, 'redraws', 0) + 1
        if self.times_s and self.temps_c:
            self.get_logger().info(f'Plotted {self.temps_c[-1]:.2f} °C at '
                                   f'{self.times_s[-1]:.3f} s, point {len(self.temps_c)}')
            try:
                told = drawing(self)
            except Exception:  # noqa: BLE001 - the learner's lists may raise: nothing drawn
                return
            shown.tell(told)

    redraw.__qualname__ = 'PlotFeeder.redraw'
    return redraw
