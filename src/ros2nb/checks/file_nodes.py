"""A node from the learner's file, created in a subject and watched by the judge.

Part of :mod:`ros2nb.checks`: what the checks of notebooks 03, 04, 06, 07 and 08 share.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from .. import course
from ..errors import CheckFailed, NotDecided
from ..qos_profiles import why_unmatched
from ..terminal.files import parts_verdict
from std_msgs.msg import Float32

from ..judge_interface import ARRIVAL_TIMEOUT_S, JUDGE_NODES, Judge, Subject, learner_error
from ..subject_interface import NewNode, WaitPublishers, WaitReceived
from ..subject_replies import Counts, LearnerError, NodeMade


#: CPU seconds a subject may work once the learner's node is made, the judge's clock standing
#: still, before the check goes on: a constructor's own work is done by then, and a thread it
#: started that logs or publishes without waiting has sent thousands of messages, a flood
#: (:meth:`ros2nb.judge.observer.Observer.settle`).
SETTLE_CPU_S = 0.25


def new_node(judge: Judge, relative: str, cls: str, *, stand_ins: tuple[str, ...] = (),
             seed: Optional[int] = None, args: tuple[Any, ...] = ()
             ) -> tuple[Subject, NodeMade]:
    """Create the learner's node ``cls(*args)`` from their file in a subject, on the judge's
    clock, with the course's stand-ins (:mod:`ros2nb.judge.stand_ins`) for the parts the
    check does not grade (in a subject of their own); raise for what went wrong.

    Returns once the judge has the lines the node logged while it started (over /rosout):
    a start-up line arriving late would otherwise be taken for one of the next lines.
    """
    mark = len(judge.observer.logs)
    subject = judge.file_subject(relative, stand_ins)
    reply = subject.request(NewNode(cls=cls, stand_ins=list(stand_ins), seed=seed,
                                    args=list(args)))
    file = Path(relative).name
    if reply.no_class or not reply.ok:
        parts_verdict(judge.workspace, relative)
    if reply.no_class:
        others = reply.classes
        hint = (f' (it defines {", ".join(others)}: names must match exactly; the tutorial '
                'misspelt TemperaturSensor in places)' if others else '')
        raise CheckFailed(f'{file} defines no class {cls}{hint}.')
    if reply.refused:
        raise CheckFailed(reply.refused)
    if not reply.ok:
        shown = ', '.join(repr(a) for a in args)
        raise raised(f'{cls}({shown})', reply.error)
    judge.observer.settle(SETTLE_CPU_S)
    lines_logged(judge, reply, mark, reply.started_lines)
    return subject, reply


def unreached(judge: Judge, topic: str, what: str) -> Exception:
    """Why ``what`` (the learner's publisher or subscription on ``topic``) and the grader's
    endpoint there never matched: a profile the other side cannot serve (a CheckFailed that
    names it, rclpy's own rule, from the profiles the graph shows), or else a machine too
    busy to bring them together in time (:class:`~ros2nb.errors.NotDecided`)."""
    why = why_unmatched(judge.observer.node, topic, JUDGE_NODES)
    if why is not None:
        side, _, reason = why.partition(': ')
        return CheckFailed(f"{what} on {topic} cannot reach the grader's {side}: {reason}")
    return NotDecided(f"{what} on {topic} never reached the grader's endpoint there")


def raised(what: str, error: Optional[LearnerError]) -> CheckFailed:
    """The failure for ``what`` a subject could not do: the ``error`` the learner's code
    raised, or, when its reply named none, one line to run the check again."""
    if error is not None:
        return learner_error(what, error)
    return CheckFailed(f'{what} did not work, for no reason the grader could read (was the '
                       'machine very busy?): run this check again.')


def started_log_verdict(judge: Judge, info: NodeMade, mark: int, cls: str) -> None:
    """Raise when the node ``info`` logged nothing while it was made (after ``mark``)."""
    if info.started_lines == 0 or not lines_logged(judge, info, mark, info.started_lines):
        words = ''.join(f' {c}' if c.isupper() else c for c in cls).strip()
        raise CheckFailed(f'{cls} logged nothing when it started: log a line such as '
                          f"'{words} Node Started' with the node's logger.")


def lines_logged(judge: Judge, info: NodeMade, mark: int, lines: int) -> list[str]:
    """Wait until the judge has ``lines`` log lines of the node after ``mark``; return them."""
    observer = judge.observer
    observer.wait_until(lambda: len(observer.lines_of(info.name, mark)) >= lines,
                        ARRIVAL_TIMEOUT_S)
    return observer.lines_of(info.name, mark)


def reach(judge: Judge, subject: Subject, node: str) -> None:
    """Wait until the learner's node (in ``subject``) has discovered the judge's publisher.

    Counted from the subject's side: a subscription of an earlier subject that just ended
    may still count on the judge's side for a moment.
    """
    _ = judge.probe_publisher  # created before the subject looks for it
    if not subject.request(WaitPublishers(topic='/' + course.TOPIC, seconds=ARRIVAL_TIMEOUT_S),
                           timeout=ARRIVAL_TIMEOUT_S + 10).ok:
        raise unreached(judge, '/' + course.TOPIC, f'The subscription of {node}')


def announced(counts: Counts, topic: str) -> Optional[int]:
    """How many messages a subject's counts say it published on ``topic``, or None when
    they say nothing (none counted): how long to wait for them, never what passes."""
    return None if counts.published is None else counts.published.get(topic, 0)


def feed(judge: Judge, subject: Subject, info: NodeMade, value: float, counts: Counts,
         never: str) -> tuple[Counts, list[str]]:
    """Publish one reading from the judge's node to the learner's node ``info`` in
    ``subject``, and wait until its subscription took it.

    :param counts: the subject's counts before (``received``, ``logged``): how many lines to
        wait for, never what passes.
    :param never: where the reading should have gone, for the line when it never arrives.
    :return: the subject's counts after it, and the lines the node logged meanwhile (as the
        judge heard them on /rosout).
    :raises LearnerCodeError: when the node's callback raised for it.
    :raises CheckFailed: when it never reached the callback.
    """
    mark = len(judge.observer.logs)
    judge.probe_publisher.publish(Float32(data=value))
    reply = subject.request(WaitReceived(count=counts.received + 1, seconds=ARRIVAL_TIMEOUT_S))
    if reply.failure is not None:
        raise learner_error(reply.failure.callback, reply.failure, context=f' for {value} °C')
    if reply.error is not None:  # a callback of theirs raised while the subject drained
        raise learner_error(f'{info.name} callback', reply.error, context=f' for {value} °C')
    if not reply.ok:
        raise CheckFailed(f'The reading {value} °C never reached {never}')
    return reply, lines_logged(judge, info, mark, reply.logged - counts.logged)
