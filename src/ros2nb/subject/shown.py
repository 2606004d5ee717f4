"""What the course's own code in a subject shows the judge: two callbacks at work, a plot drawn.

Part of :mod:`ros2nb.subject` (used by :mod:`.trials`), for the checks of notebooks 06 and 07.
A line the learner's code logs is a line any code can print, and anything this process holds
its code can reach, so what the judge believes is made so that the learner's code cannot
produce it by other means:

- notebook 06: the course's slow work and heartbeat are services on the learner's Worker,
  in the callback groups of its two timers (:func:`worker_services`).  The judge calls them
  and times the answers itself: only the learner's executor takes a request and sends its
  answer, so calling the course's callbacks from a thread of one's own answers nothing;
- notebook 07: the course's ``redraw()`` hands what it draws to a sealer
  (:func:`make_sealer`), which reads the node's lists itself and seals each drawing with a key
  the judge sent before the learner's code was loaded and that lives only in the sealer's
  frame (reaching it raises an audit event, :mod:`.seen`).  A drawing published by anything
  else does not carry the seal.
"""

from __future__ import annotations

import hashlib
import numbers
import os
import threading
from typing import Any, Callable, Generator, Optional

from rcl_interfaces.msg import ParameterType, ParameterValue
from rcl_interfaces.srv import GetParameters
from rclpy.node import Node
from rclpy.qos import QoSProfile, ReliabilityPolicy
from std_msgs.msg import String

from ..patience import wait_for_work

#: The course's node that publishes what it saw (not spun: publishing needs no executor).
SHOWN_NODE = 'ros2nb_shown'
#: Reliable and deep enough for every message of one check: the judge counts them all.
SHOWN_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE)
#: The nonce of the judge's first calls to the worker's services, which only show that
#: both ways are matched: the slow work then answers at once.
WARM_UP = 'warm-up'
#: What the heartbeat answers when the learner's executor ran it (nothing otherwise).
BEAT = 'beat'


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


# ------------------------------------------------------------------ notebook 06: the worker
def worker_services(node: Node, names: tuple[str, str], groups: tuple[Any, Any],
                    shown: Shown, release: threading.Event,
                    dispatching: Callable[[], set]) -> None:
    """Put the course's ``slow_work`` and ``heartbeat`` on the learner's ``node`` as services
    named ``names``, in the callback ``groups`` of its slow and quick timer.

    The slow one, called with a nonce, tells ``started <nonce>`` on the witness topic and
    works until ``release`` is set (the judge says when); the quick one answers :data:`BEAT`
    when one of the learner's executor's threads (``dispatching()``, their idents) runs it.
    Either answer reaches the judge only through the executor that took the request."""

    def slow_work(request: Any, response: Any) -> Any:
        nonce = request.names[0] if request.names else ''
        if nonce != WARM_UP:
            shown.tell(f'started {nonce}')
            release.wait()
        return response

    def heartbeat(request: Any, response: Any) -> Any:
        if threading.get_ident() in dispatching():
            response.values = [ParameterValue(type=ParameterType.PARAMETER_STRING,
                                              string_value=BEAT)]
        return response

    node.create_service(GetParameters, names[0], slow_work, callback_group=groups[0])
    node.create_service(GetParameters, names[1], heartbeat, callback_group=groups[1])


# ------------------------------------------------------------------ notebook 07: the plot
#: Notebook 07's sealer (:func:`make_sealer`): sent ``(what, node)``, it answers a sealed
#: drawing, ``'bound'``, or None.
Sealer = Generator[Optional[str], tuple[str, Any], None]


def make_sealer(key: str) -> Sealer:
    """The sealer of notebook 07's drawings, made before the learner's code is loaded.

    Send it ``('bind', node)`` once (the first node bound is the only one it reads), then
    ``('draw', node)`` for each redraw: it answers ``SEQ;TIMES;TEMPS;MAC``, the bound node's
    ``times_s`` and ``temps_c`` as it reads them (``x`` for what is no number) sealed with an
    HMAC-SHA256 of ``key``, or None for a node it was not bound to.  Its key and everything
    it uses are locals of its own frame, bound now."""
    sealer = _sealing(key)
    next(sealer)
    return sealer


def _sealing(key: str) -> Sealer:
    sha, real, is_a, make_float, text, joined = hashlib.sha256, numbers.Real, isinstance, \
        float, repr, ';'.join
    listed, attribute, as_text = list, getattr, str  # none looked up once the code runs
    raw = key.encode()
    raw = raw + bytes(64 - len(raw)) if len(raw) <= 64 else sha(raw).digest() + bytes(32)
    inner, outer = bytes(b ^ 0x36 for b in raw), bytes(b ^ 0x5c for b in raw)
    del key, raw
    bound, count, answer = None, 0, None
    while True:
        message = yield answer
        answer = None
        try:
            what, node = message
            if what == 'bind' and bound is None:
                bound, answer = node, 'bound'
            elif what == 'draw' and node is bound and bound is not None:
                count += 1
                lists = [[text(make_float(v)) if is_a(v, real) else 'x'
                          for v in listed(attribute(node, name, None) or ())]
                         for name in ('times_s', 'temps_c')]
                payload = joined([as_text(count), ','.join(lists[0]), ','.join(lists[1])])
                mac = sha(outer + sha(inner + payload.encode()).digest()).hexdigest()
                answer = f'{payload};{mac}'
        except Exception:  # noqa: BLE001 - the learner's lists may raise: nothing is sealed
            answer = None


def plot_redraw(shown: Shown, sealer: Sealer) -> Callable[[Any], None]:
    """The course's ``PlotFeeder.redraw`` (part 1 of live_plot.py, given), for a feeder
    without a figure: it counts, logs the newest point as part 1 does (so a list holding
    something other than numbers fails as it would there), and tells the judge every point
    it drew, sealed (:func:`make_sealer`)."""
    send = sealer.send

    def redraw(self: Any) -> None:
        self.redraws = getattr(self, 'redraws', 0) + 1
        if self.times_s and self.temps_c:
            self.get_logger().info(f'Plotted {self.temps_c[-1]:.2f} °C at '
                                   f'{self.times_s[-1]:.3f} s, point {len(self.temps_c)}')
            sealed = send(('draw', self))
            if sealed is not None:
                shown.tell(f'drawn {sealed}')

    redraw.__qualname__ = 'PlotFeeder.redraw'
    return redraw
