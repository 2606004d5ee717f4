"""The judge's clock: simulated time that only the judge decides and moves on.

Part of the judge (:mod:`ros2nb.judge`).  The judge publishes ``/clock`` from its own node;
the learner's nodes in a subject run on it (their runtime follows it, see
:class:`ros2nb.subject.judge_time.JudgeTime`), and everything the judge's node hears is stamped
with it (:attr:`ros2nb.judge.observer.Observer.now_ns`).  How far each step goes, and how
far the clock goes at all, is the judge's choice; a subject only says, after each step,
that it has run what became due, how much it published and logged meanwhile (so that the
judge waits for all of it to arrive before the next step, and stamps each message with the
step that made it) and how far its spin would like to go.  A subject that lies about any of
it only makes the judge wait longer or stamp its messages later.
"""

from __future__ import annotations

import time
from typing import Any, Optional, TypeVar

from rosgraph_msgs.msg import Clock

from .. import working
from ..judge_interface import ARRIVAL_TIMEOUT_S, JUDGE_NODES, learner_error
from ..errors import CheckFailed, NotDecided
from ..qos_profiles import why_unmatched
from ..patience import Patience
from ..processes import kill_process_group
from ..subject.judge_time import JUDGE_CLOCK_QOS, Acknowledgement
from ..runtime.core import QUIET_PUBLISHER
from ..subject_interface import Command
from ..subject_replies import Reply
from ..judge_interface import Subject
from .observer import Observer
from .subjects import REPLY_TIMEOUT_S, SubjectProcess

R = TypeVar('R', bound=Reply)

#: Seconds between two looks at a subject that is neither answering nor acknowledging.
POLL_S = 0.05
#: Seconds a subject is quiet before its work is read from /proc, and between two reads
#: (:class:`~ros2nb.patience.Patience`: every process's stat, milliseconds on a busy
#: machine, where a step often takes longer than POLL_S).
PATIENCE_LOOK_S = 0.25
#: Where the judge's clock starts (ns): rcl takes a ROS time of 0 for a clock not yet set,
#: and a timer a node starts then first fires one step late (docs/decisions.md).
START_NS = 1_000_000_000


class JudgeClock:
    """The judge's ``/clock``: its time now and the steps that move it on.

    :param observer: the judge's node (it publishes the clock and stamps what it hears).
    """

    def __init__(self, observer: Observer) -> None:
        self._observer = observer
        self._publisher = observer.node.create_publisher(Clock, '/clock', JUDGE_CLOCK_QOS,
                                                         event_callbacks=QUIET_PUBLISHER)
        with observer.changed:
            observer.now_ns = max(observer.now_ns, START_NS)
        self._publish()

    @property
    def now_ns(self) -> int:
        """The judge's simulated time now (ns)."""
        return self._observer.now_ns

    @property
    def now_s(self) -> float:
        """The judge's simulated time now (s)."""
        return self._observer.now_ns / 1e9

    def _publish(self) -> None:
        msg = Clock()
        msg.clock.sec, msg.clock.nanosec = divmod(self._observer.now_ns, 1_000_000_000)
        self._publisher.publish(msg)

    def step_to(self, t_ns: int) -> None:
        """Move the clock on to ``t_ns``: what the judge hears from now on is stamped so.

        :raises ValueError: for a time before now (the judge's clock never goes back).
        """
        if t_ns < self._observer.now_ns:
            raise ValueError('the judge\'s clock never goes back')
        with self._observer.changed:
            self._observer.now_ns = t_ns
        self._publish()

    def drive(self, subject: Subject, command: Command[R], *, step_s: float, limit_s: float,
              probe_s: float = 0.0, timeout: float = REPLY_TIMEOUT_S, what: str = 'your code'
              ) -> R:
        """Send ``command`` to ``subject`` and move the clock on, a step of ``step_s`` at a time,
        for as long as the subject's spin wants it (at most ``limit_s`` simulated seconds);
        return the subject's reply once it comes.

        With ``probe_s``, the clock also stops ``probe_s`` before each whole step: a timer
        of period ``step_s`` started now fires on the whole steps, and one whose period is
        shorter or longer by more than ``probe_s`` over the run fires on a probe (its
        messages are stamped off the whole steps), two steps per period instead of one.

        Before each step the judge waits until every message the subject says it published
        on a topic the judge watches, and every line it says it logged, has arrived.

        :param what: who would be spinning too long, for the message (``record_hour(bag_path)``).
        :raises CheckFailed: when the spin wants more than ``limit_s``, or a message the
            subject announced never arrives.
        :raises SubjectHung: when the subject neither answers nor finishes a step in time.
        :raises NotDecided: when it sat idle that long waiting for the judge's clock.
        :raises TypeError: for a subject this judge did not start.
        """
        if not isinstance(subject, SubjectProcess):
            raise TypeError(f'the judge drives only its own subjects, not {subject!r}')
        try:
            return subject.reply_to(command, self._drive(subject, command, (step_s, probe_s),
                                                         limit_s, timeout, what))
        except BaseException:
            # The subject is left in the middle of its command: it serves no other.
            kill_process_group(subject.proc)
            raise

    def _drive(self, subject: SubjectProcess, command: Command[Any], steps: tuple[float, float],
               limit_s: float, timeout: float, what: str) -> Any:
        step_ns, probe_ns = round(steps[0] * 1e9), round(steps[1] * 1e9)
        began_ns = self.now_ns
        limit_ns, whole_ns = began_ns + round(limit_s * 1e9), began_ns + step_ns
        subject.send(command)
        # Patience reads /proc: it starts only once the subject has been quiet for
        # PATIENCE_LOOK_S (an hour of steps would otherwise read it 7200 times), and looks
        # again every PATIENCE_LOOK_S.
        patience: Optional[Patience] = None
        quiet_since = looked = time.monotonic()
        while True:
            self._observer.floods.raise_any()  # its processes were ended: none will answer
            reply = subject.poll_reply(POLL_S)
            ack = subject.take_ack()
            if ack is not None:
                patience, quiet_since = None, time.monotonic()
                self._settle(ack, subject.heard_base, subject.proc.pid)
                if ack.wants is None:  # its spin ended, and all it told of arrived:
                    self._publish()  # the same time again lets it go on (destroy its nodes)
            if reply is not None:
                return reply
            latest = subject.last_ack
            wants = latest.wants if latest else None
            if latest is not None and latest.t >= self.now_ns and wants is not None \
                    and wants > self.now_ns:
                if whole_ns > limit_ns:
                    kill_process_group(subject.proc)
                    raise CheckFailed(f'{what} kept the nodes spinning past {limit_s:g} '
                                      'simulated seconds of the grader\'s clock: spin only as '
                                      'long as the task says.')
                if 0 < probe_ns < step_ns and self.now_ns < whole_ns - probe_ns:
                    self.step_to(whole_ns - probe_ns)
                else:
                    self.step_to(whole_ns)
                    whole_ns += step_ns
                working.say(f'running {what} on the grader\'s clock: '
                            f'{(self.now_ns - began_ns) / 1e9:.0f} simulated s', often=True)
                patience, quiet_since = None, time.monotonic()
            elif time.monotonic() - max(quiet_since, looked) < PATIENCE_LOOK_S:
                continue
            elif patience is None:
                patience, looked = Patience(subject.proc.pid, timeout,
                                            started=quiet_since), time.monotonic()
            elif patience.exhausted():
                raise subject.ran_out(patience, timeout)
            else:
                looked = time.monotonic()

    def _settle(self, ack: Acknowledgement, base: tuple[dict[str, int], dict[str, int]],
                pid: int) -> None:
        """Wait until what the subject ``pid`` announced in ``ack`` (all it published and
        logged since it started) has arrived: what the judge heard since then (``base``: what
        it had heard when the subject started), on the topics it watched then and on /rosout.
        What it announced beyond :data:`~ros2nb.judge.floods.FLOOD_LIMIT` in a second of
        the judge's clock is a flood, raised before any wait."""
        topics0, logs0 = base
        observer = self._observer
        if ack.failure is not None:
            raise learner_error(ack.failure.callback, ack.failure)

        for logger, total in ack.logged.items():
            observer.floods.announced(pid, '/rosout', logger, total)
        for topic, total in ack.published.items():
            if topic in topics0:
                observer.floods.announced(pid, topic, topic, total)
        observer.floods.raise_any()

        def missing() -> list[str]:
            topics, logs = observer.counts()
            short = []
            for topic, total in ack.published.items():
                if topic in topics0 and topics[topic] - topics0[topic] < total:
                    short.append(topic)
            for logger, total in ack.logged.items():
                if logs.get(logger, 0) - logs0.get(logger, 0) < total:
                    short.append(f'/rosout ({logger})')
            return short

        if not observer.wait_until(lambda: not missing(), ARRIVAL_TIMEOUT_S):
            for topic in missing():  # a profile the grader's subscription cannot take
                why = why_unmatched(observer.node, topic, JUDGE_NODES) \
                    if not topic.startswith('/rosout') else None
                if why is not None:
                    raise CheckFailed(f'Messages on {topic} were published but cannot reach '
                                      f"the grader's {why}")
            raise NotDecided(f'Messages on {", ".join(missing())} were published but never '
                             'reached the grader')
