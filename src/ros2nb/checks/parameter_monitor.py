"""The learner's monitor as ``ros2 param`` reaches it: a node in a fresh subject and a
parameter client of the judge's (notebook 08).

Part of :mod:`ros2nb.checks`, for :mod:`.lesson08`: the judge lists, gets, describes and sets
the monitor's parameters over ROS with rclpy's ``AsyncParameterClient``, and asks it for a
status by publishing a reading itself; a callback of the learner's that raised is named.
"""

from __future__ import annotations

import re
from typing import Any, Callable, Optional

from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient

from .. import course
from ..errors import CheckFailed
from ..runtime.services import call_until_answered
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, learner_error
from ..subject_interface import GetCounts, Serve
from ..subject_replies import Counts, LearnerError
from .file_nodes import feed, lines_logged, new_node, reach

#: The on-set callback the learner writes (part 4); the constructor registers it.
CALLBACK = 'on_set_thresholds'
THRESHOLDS = (course.HIGH_PARAMETER, course.LOW_PARAMETER)
#: rclpy's reason when an on-set callback returns anything but a SetParametersResult.
INVALID_RETURN = 'Callback returned an invalid type'
#: The monitor's status line (notebook 04's, and the given callback of notebook 08).
STATUS = re.compile(r'\b(High|Low|Normal)\b')


class ParameterMonitor:
    """The learner's monitor in a fresh subject, a parameter client of the judge's, and the
    judge's publisher to ask it for a status."""

    def __init__(self, judge: Judge, stand_ins: tuple[str, ...]) -> None:
        # A fresh process each time: one node of this name, ever, so that the judge's client
        # reaches no services of an earlier node (they linger in the graph).
        judge.drop(('file', course.SUBSCRIBER_FILE))
        mark = len(judge.observer.logs)
        try:
            self.subject, self.info = new_node(judge, course.SUBSCRIBER_FILE,
                                               course.MONITOR_CLASS, stand_ins=stand_ins)
        except CheckFailed as error:
            undeclared = re.search(r"undeclared parameter\(s\)\W*(\w+)|the parameter '(\w+)' "
                                   r"was read \(or set\) before it was declared", str(error))
            if undeclared is None:
                raise
            raise CheckFailed(f'{course.MONITOR_CLASS}() reads the parameter '
                              f'{undeclared.group(1) or undeclared.group(2)} before it declares '
                              'it, or never declares it: declare it in __init__ with '
                              'self.declare_parameter() before reading it (names must match '
                              'exactly).') from None
        self.judge, self.observer, self.stand_ins = judge, judge.observer, stand_ins
        self.name = self.info.name
        self.full = self.info.namespace.rstrip('/') + '/' + self.name
        lines_logged(judge, self.info, mark, self.info.started_lines)
        reach(judge, self.subject, self.name)
        self.counts: Counts = self.info
        self.subject.request(Serve())
        self.client = AsyncParameterClient(self.observer.node, self.full)
        if not self.info.parameter_services:  # the subject says: no use waiting
            raise CheckFailed(f'{course.MONITOR_CLASS} has no parameter services (was it made '
                              'with start_parameter_services=False?): ros2 param cannot reach '
                              'it; leave that argument out of super().__init__().')
        if not self.client.wait_for_services(ARRIVAL_TIMEOUT_S):
            raise CheckFailed(f'The grader could not reach the parameter services of {self.full} '
                              f'within {ARRIVAL_TIMEOUT_S:g} s (is the machine very busy?): run '
                              'this check again.')

    def answer(self, send: Callable[[], Any], what: str) -> Any:
        """Ask until the node answers (asked again now and then: a request or its reply can
        be lost right after the node appeared); a callback of the learner's that raised is
        named."""
        def failed() -> None:
            counts = self.subject.request(GetCounts())
            failure = counts.failure or counts.error
            if failure is not None:
                _callback_failure(failure, what)

        done = call_until_answered(send, lambda f, s: self.observer.wait_until(f.done, s),
                                   ARRIVAL_TIMEOUT_S, failed)
        if done is None:
            failed()
            raise CheckFailed(f'{self.name} did not answer {what} within '
                              f'{ARRIVAL_TIMEOUT_S:g} s: does your callback wait for '
                              'something?')
        return done.result()

    def names(self) -> list[str]:
        return sorted(self.answer(self.client.list_parameters, 'ros2 param list').result.names)

    def values(self, names: list[str]) -> list[Any]:
        return list(self.answer(lambda: self.client.get_parameters(names),
                                'ros2 param get').values)

    def descriptors(self, names: list[str]) -> list[Any]:
        return list(self.answer(lambda: self.client.describe_parameters(names),
                                'ros2 param describe').descriptors)

    def set(self, name: str, value: float) -> Any:
        return self.answer(lambda: self.client.set_parameters([Parameter(name, value=value)]),
                           f'ros2 param set {name} {value}').results[0]

    def status(self, reading: float) -> Optional[str]:
        """The status the monitor logs for ``reading``, published by the judge (None: no
        status in what it logged)."""
        self.counts, lines = feed(self.judge, self.subject, self.info, reading, self.counts,
                                  f'{self.name}: keep its subscription (given in part 3).')
        found = [word for line in lines for word in STATUS.findall(line)]
        return found[-1] if found else None


def _callback_failure(failure: LearnerError, what: str) -> None:
    """Raise for the learner's on-set callback raising inside the node's parameter service."""
    if failure.type == 'AttributeError' and "'successful'" in failure.message:
        returned = failure.message.split("'")[1]
        raise CheckFailed(f'{CALLBACK} returned a {returned}, not a SetParametersResult: return '
                          'SetParametersResult(successful=..., reason=...).')
    missing = re.fullmatch(r"'(\w+)'", failure.message)
    if failure.type == 'KeyError' and missing and missing.group(1) in \
            course.THRESHOLD_DEFAULTS_C:
        where = f' ({failure.where})' if failure.where else ''
        raise CheckFailed(f'{CALLBACK} raised KeyError: {missing.group(0)} for {what}: it gets '
                          f'only the parameters being set, so read the other with new.get(name, '
                          f'self.get_parameter(name).value){where}.')
    raise learner_error(f'{course.MONITOR_CLASS}.{CALLBACK}', failure, context=f' for {what}')
