"""What a check of notebook 10 hears while the learner's function runs, itself.

Part of :mod:`ros2nb.checks` (used by :mod:`.lesson10`, introduced in
``10-record-and-replay.ipynb``): every reading on ``/temperature`` and every ``/rosout`` line,
each with the time it arrived: the judge's node, stamped with the judge's clock, or in the
kernel subscriptions of the check's own, on the kernel's clock.  Never what the learner's
code reports.
"""

from __future__ import annotations

import contextlib
import re
from dataclasses import dataclass, field
from typing import Iterator, Optional

from rcl_interfaces.msg import Log
from std_msgs.msg import Float32

from .. import course
from ..judge_interface import Judge
from ..runtime import current_runtime
from ..terminal import bag
from .bags import ROSOUT, TEMPERATURE

#: The monitor's log line, as notebook 04 writes it.
STATUS_LINE = re.compile(r'Temperature: (-?[\d.]+)C - Status: (\w+)')


@dataclass
class Witness:
    """What the check's own ROS hears while the learner's function runs: each reading on
    /temperature and each /rosout line, with the time it arrived (ns of simulated time).

    :ivar readings: ``(t_ns, °C)`` in order of arrival.
    :ivar lines: ``(t_ns, logger, text)`` in order of arrival.
    """

    readings: list[tuple[int, float]] = field(default_factory=list)
    lines: list[tuple[int, str, str]] = field(default_factory=list)

    def statuses(self) -> list[tuple[int, float, str]]:
        """``(t_ns, reading, status)`` of every status line of the monitor."""
        found = []
        for t_ns, name, text in self.lines:
            match = STATUS_LINE.fullmatch(text) if name == course.MONITOR_NODE else None
            if match:
                found.append((t_ns, float(match.group(1)), match.group(2)))
        return found


@contextlib.contextmanager
def witnessing(judge: Optional[Judge]) -> Iterator[Witness]:
    """Hear /temperature and /rosout while the block runs: the judge's node (stamped with
    its clock), or in the kernel subscriptions of the check's own (the kernel's clock)."""
    seen = Witness()
    if judge is not None:
        observer = judge.observer
        heard = observer.watch(TEMPERATURE, Float32, lambda m: float(m.data))
        first, mark = len(heard), len(observer.logs)
        try:
            yield seen
        finally:
            seen.readings = [(h.t_ns, h.value) for h in heard[first:]]
            seen.lines = [(line.t_ns, line.name, line.text) for line in observer.logs[mark:]]
        return
    rt = current_runtime()
    with rt.exclusive():
        made = [rt.node.create_subscription(
                    Float32, TEMPERATURE,
                    lambda m: seen.readings.append((rt.sim_now_ns, float(m.data))), bag.KEEP_ALL),
                rt.node.create_subscription(
                    Log, ROSOUT, lambda m: seen.lines.append((rt.sim_now_ns, m.name, m.msg)),
                    bag.KEEP_ALL)]
    try:
        yield seen
    finally:
        with rt.exclusive():
            rt.drain()
            for subscription in made:
                rt.node.destroy_subscription(subscription)
