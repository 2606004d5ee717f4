"""A sensor of the learner's, made in a subject and run on the judge's clock (notebook 03).

Part of :mod:`ros2nb.checks`, for :mod:`.lesson03` (and the hidden hour): the judge creates
the learner's ``TemperatureSensor`` in a subject, drives it step by step with its own clock
(:mod:`ros2nb.judge.clock`) and keeps what reached its own node over ROS: the graph, each
reading on ``/temperature`` with the judge's time of its arrival, and the node's lines on
``/rosout``.  What those readings must be is :mod:`.sensor_rules`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

from std_msgs.msg import Float32

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, Subject, learner_error
from ..subject_interface import Run, SetAttribute, WaitMatched
from ..subject_replies import NodeMade
from .file_nodes import lines_logged, new_node, unreached

#: Steps of the judge's clock (s), and the probe before each while a constructor runs: a timer
#: of another period fires on the probe, off the whole periods (JudgeClock.drive's probe_s).
STEP_S, PROBE_S = course.PUBLISH_PERIOD_S, 0.001
TOPIC = '/' + course.TOPIC


@dataclass
class SensorRun:
    """What the judge saw of one sensor made in a subject, run on the judge's clock.

    :ivar subject: the subject process the node runs in.
    :ivar info: the subject's reply to ``new_node`` (name, namespace).
    :ivar found: the node's endpoints as the judge's graph shows them.
    :ivar started_lines: the lines it logged while it was made.
    :ivar readings: ``(seconds since the run began on the judge's clock, °C)``.
    :ivar lines: the node's /rosout lines during the run.
    :ivar problem: what stopped the run early (a callback that raised), or None.
    """

    subject: Subject
    info: NodeMade
    found: list[tuple[str, str, str]]
    started_lines: list[str]
    readings: list[tuple[float, float]] = field(default_factory=list)
    lines: list[str] = field(default_factory=list)
    problem: Optional[CheckFailed] = None

    @property
    def values(self) -> list[float]:
        """The readings' values (°C), in order."""
        return [value for _t, value in self.readings]


def make_sensor(judge: Judge, stand_ins: tuple[str, ...], seed: int) -> SensorRun:
    """The learner's sensor (with the course's ``stand_ins``), made in a subject."""
    observer = judge.observer
    observer.watch(TOPIC, Float32, lambda m: float(m.data))  # before it can publish
    mark = len(observer.logs)
    subject, info = new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                             stand_ins=stand_ins, seed=seed)
    found = observer.endpoints(info.name, info.namespace, info.endpoints)
    return SensorRun(subject, info, found, lines_logged(judge, info, mark, info.started_lines))


def run_sensor(judge: Judge, sensor: SensorRun, seconds: float, *, probe_s: float, seed: int,
         start_c: Optional[float] = None) -> SensorRun:
    """Run ``sensor`` ``seconds`` of the judge's clock (the walk from ``start_c`` if given,
    ``probe_s``: :data:`PROBE_S` or 0); return what the judge heard, as a run of its own."""
    observer, subject = judge.observer, sensor.subject
    readings = observer.watch(TOPIC, Float32, lambda m: float(m.data))
    run = SensorRun(subject, sensor.info, sensor.found, sensor.started_lines)
    if ('publisher', TOPIC, course.MESSAGE_TYPE) not in run.found:
        return run  # nothing the judge could hear: the constructor's verdict says why
    if start_c is not None:
        subject.request(SetAttribute(name='temperature', value=start_c))
    if not subject.request(WaitMatched(topic=TOPIC, seconds=ARRIVAL_TIMEOUT_S)).ok:
        raise unreached(judge, TOPIC, f'The publisher of {sensor.info.name}')
    first, log_mark, began = len(readings), len(observer.logs), judge.clock.now_ns
    try:
        reply = judge.clock.drive(subject, Run(seconds=seconds, seed=seed), step_s=STEP_S,
                                  probe_s=probe_s, limit_s=seconds + 1, what=course.SENSOR_CLASS)
        if reply.failure is not None:
            raise learner_error(reply.failure.callback, reply.failure)
    except CheckFailed as problem:
        run.problem = problem
    run.readings = [((heard.t_ns - began) / 1e9, heard.value) for heard in readings[first:]]
    run.lines = [line.text for line in observer.logs[log_mark:] if line.name == run.info.name]
    return run


def sensor_run(judge: Judge, stand_ins: tuple[str, ...], seconds: float, *, probe_s: float,
                seed: int) -> SensorRun:
    """A new sensor of the learner's (with ``stand_ins``), run ``seconds``."""
    return run_sensor(judge, make_sensor(judge, stand_ins, seed), seconds, probe_s=probe_s,
                      seed=seed)
