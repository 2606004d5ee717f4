"""What the course's own code in a subject shows the judge: two callbacks at work, a plot drawn.

Part of :mod:`ros2nb.subject` (used by :mod:`.trials`), for the checks of notebooks 06 and 07.
A line the learner's code logs is a line any code can print, so no point rests on one.  Where
the part graded is what the learner's code makes happen to code the course gave them (the
``Worker``'s two timers overlapping, notebook 06; ``redraw()`` drawing the readings,
notebook 07), the subject puts the course's version of that given code in place, and it
publishes what happened on the judge's witness topic from a node of the course's.  Each
message carries a token the judge drew for this check run and sent only after the learner's
code was loaded: a message the learner's code publishes there itself does not count.
"""

from __future__ import annotations

import json
import numbers
import time
from typing import Any, Callable

from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

#: The course's node that publishes what it saw (not spun: publishing needs no executor).
SHOWN_NODE = 'ros2nb_shown'
#: Reliable and deep enough for every message of one check: the judge counts them all.
SHOWN_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)


class Shown:
    """The course's publisher on the judge's witness topic, with the check's token."""

    def __init__(self, topic: str, token: str) -> None:
        self._token = token
        #: Messages told so far: how many the judge waits for, never what passes.
        self.told = 0
        self.node = Node(SHOWN_NODE, start_parameter_services=False, enable_rosout=False)
        self._publisher = self.node.create_publisher(String, topic, SHOWN_QOS)

    def reaches_judge(self, seconds: float) -> bool:
        """Wait (at most ``seconds`` of the wall clock) until the judge's subscription matched:
        a volatile topic keeps nothing for a subscription discovered later."""
        deadline = time.monotonic() + seconds
        while self._publisher.get_subscription_count() < 1:
            if time.monotonic() >= deadline:
                return False
            time.sleep(0.01)
        return True

    def tell(self, event: str, **facts: Any) -> None:
        """Publish one event with the check's token, e.g. ``tell('drawn', temps_c=[...])``."""
        self._publisher.publish(String(data=json.dumps({'token': self._token, 'event': event,
                                                        **facts})))
        self.told += 1

    def close(self) -> None:
        """Destroy the course's node (and with it its publisher)."""
        self.node.destroy_node()


# ------------------------------------------------------------------ notebook 06: the worker
def worker_callbacks(shown: Shown, work_s: float) -> tuple[Callable[[], None],
                                                            Callable[[], None]]:
    """The course's ``slow_work`` and ``heartbeat`` for the Worker's two timers (part 3 of
    promises.py, given): the slow one tells ``start``, works ``work_s`` seconds of the wall
    clock and tells ``done``; the quick one tells ``beat``.  One publisher keeps their order:
    a ``beat`` between a ``start`` and its ``done`` ran while the slow callback worked."""

    def slow_work() -> None:
        shown.tell('start')
        time.sleep(work_s)  # stands for the Worker's long computation, as part 3's does
        shown.tell('done')

    def heartbeat() -> None:
        shown.tell('beat')

    return slow_work, heartbeat


# ------------------------------------------------------------------ notebook 07: the plot
def _numbers(values: Any) -> list:
    """The numbers of a list as JSON can carry them; None for anything that is no number."""
    return [float(v) if isinstance(v, numbers.Real) else None for v in values]


def plot_redraw(shown: Shown) -> Callable[[Any], None]:
    """The course's ``PlotFeeder.redraw`` (part 1 of live_plot.py, given), for a feeder
    without a figure: it counts, logs the newest point as part 1 does (so a list holding
    something other than numbers fails as it would there), and tells the judge every point
    it drew."""

    def redraw(self: Any) -> None:
        self.redraws = getattr(self, 'redraws', 0) + 1
        if self.times_s and self.temps_c:
            self.get_logger().info(f'Plotted {self.temps_c[-1]:.2f} °C at '
                                   f'{self.times_s[-1]:.3f} s, point {len(self.temps_c)}')
            shown.tell('drawn', times_s=_numbers(self.times_s), temps_c=_numbers(self.temps_c))

    redraw.__qualname__ = 'PlotFeeder.redraw'
    return redraw
