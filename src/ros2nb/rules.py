"""The course's rules: what a learner's answer computes, written once for the judge.

Introduced in ``04-write-the-subscriber.ipynb`` (the monitor's status).  The checks compare
the learner's node with these, the course's stand-ins use them, and a notebook may call
them for the learner where a cell shows what the rule gives (``ros2nb.rules.monitor_status``,
loaded on first use).  It is an answer: a judge's subject refuses to import it
for the learner's code (:mod:`ros2nb.subject.out_of_reach`).  No ROS import.
"""

from __future__ import annotations

from .course import HIGH_ABOVE_C, LOW_BELOW_C


def monitor_status(temperature_c: float) -> str:
    """Return the monitor's status for a reading: ``'High'``, ``'Low'`` or ``'Normal'``.

    ``High`` strictly above :data:`~ros2nb.course.HIGH_ABOVE_C`, ``Low`` strictly below
    :data:`~ros2nb.course.LOW_BELOW_C`, ``Normal`` otherwise (both boundaries are Normal).

    Introduced in ``04-write-the-subscriber.ipynb``.

    :param temperature_c: the reading in °C.
    """
    if temperature_c > HIGH_ABOVE_C:
        return 'High'
    if temperature_c < LOW_BELOW_C:
        return 'Low'
    return 'Normal'
