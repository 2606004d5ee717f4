"""What the course's own code in a subject told the judge, on the judge's witness topic.

Part of :mod:`ros2nb.checks` (used by :mod:`.lesson07`, introduced in ``07-live-plot.ipynb``).
The course's ``redraw()`` tells, as plain data, every point it drew
(:mod:`ros2nb.subject.shown`): ``drawn TIMES;TEMPS``.  Anything in the subject's process may
publish such a line; it carries no secret, and the check believes only what it can compare
with what it did itself: the readings it sent and the times it sent them.
"""

from __future__ import annotations

from typing import Optional

from std_msgs.msg import String

from ..judge_interface import Heard, Judge

#: The topic the course's code in a subject tells the judge on.
WITNESS_TOPIC = '/ros2nb/witness'


def told_to(judge: Judge) -> list[Heard]:
    """The judge's list of what arrives on :data:`WITNESS_TOPIC` (watched from now on)."""
    return judge.observer.watch(WITNESS_TOPIC, String, lambda msg: msg.data)


def _numbers(text: str) -> list[Optional[float]]:
    """``1.5,x,2.0`` -> ``[1.5, None, 2.0]`` (``x``: what was no number)."""
    found: list[Optional[float]] = []
    for part in text.split(',') if text else []:
        try:
            found.append(None if part == 'x' else float(part))
        except ValueError:
            found.append(None)
    return found


def drawings(heard: list[Heard], start: int) -> list[dict[str, list[Optional[float]]]]:
    """The drawings told from position ``start`` on, in order of arrival:
    ``{'times_s': [...], 'temps_c': [...]}`` each; what is no drawing is left out."""
    found = []
    for message in heard[start:]:
        text = message.value if isinstance(message.value, str) else ''
        if not text.startswith('drawn '):
            continue
        times, _, temps = text.removeprefix('drawn ').partition(';')
        found.append({'times_s': _numbers(times), 'temps_c': _numbers(temps)})
    return found
