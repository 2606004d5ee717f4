"""A judge's simulated time, as a subject's runtime follows it.

Part of :mod:`ros2nb.subject`; runs only in a judge's subject.  The runtime
(:class:`ros2nb.runtime.simulated_clock.SimulatedClock`) publishes no ``/clock`` of its own
there: it takes each step of the judge's ``/clock``, runs what became due, and after each
step it finished (every callback due then has run) says so on a pipe of the judge's.  What
it says there only tells the judge when to look and how long to wait: the judge stamps what
it hears with its own clock.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import time
from collections import Counter
from dataclasses import dataclass
from typing import Any, Callable, Optional, Union

from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock

from ..patience import wait_for_work
from ..runtime import logs
from ..runtime.simulated_clock import follow_judge_time
from ..subject_replies import CallbackFailure

#: Set by a judge for its subjects: the file descriptor its runtime writes one line to for
#: each step of the judge's clock it finished (:class:`JudgeTime`).
JUDGE_CLOCK_ENV = 'ROS2NB_JUDGE_CLOCK_FD'
#: The profile of the judge's ``/clock``: reliable, and its latest step kept for a subject
#: that starts later (transient local), so a new runtime starts at the judge's time.
JUDGE_CLOCK_QOS = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
#: The topics the judge hears (a JSON list in the environment of its subjects): a message
#: published there must reach it, so a subject's spin starts once they are matched.
JUDGE_TOPICS_ENV = 'ROS2NB_JUDGE_TOPICS'
#: Seconds a subject's spin waits at most for its publishers to reach the judge, and for the
#: judge to say it heard a finished spin: of this process's work, or of its idle waiting
#: (:func:`ros2nb.patience.wait_for_work`), never time the machine kept it from running.
JUDGE_MATCH_WAIT_S = 30.0
#: Seconds one wait for the judge's next step lasts before it is waited for again.
JUDGE_STEP_WAIT_S = 0.5
#: What a subject says on the judge's pipe while its new runtime waits for the judge's first
#: ``/clock`` (``{"waiting": "the judge's clock"}``; ``{"waiting": null}`` once it came).
WAITING_FOR_CLOCK = "the grader's clock"


@dataclass(frozen=True, kw_only=True)
class Acknowledgement:
    """A subject's line on the judge's pipe after each step of the judge's clock it finished
    (:meth:`JudgeTime.ack`), read by the judge
    (:meth:`ros2nb.judge.subjects.SubjectProcess.take_ack`) with
    :func:`ros2nb.typed_json.decoded`.  It crosses from the subject, a process that runs the
    learner's code, to the judge: it only says when to step and what to wait for, never what
    passes.

    :ivar t: the step of the judge's clock the subject finished (ns).
    :ivar wants: how far its running spin wants the clock to go (ns); None: no further.
    :ivar published: messages the process has published so far, per topic.
    :ivar logged: lines the runtime's nodes have logged so far, per logger.
    :ivar failure: the first exception a callback of the learner's raised, or None.
    """

    t: int
    wants: Optional[int] = None
    published: dict[str, int]
    logged: dict[str, int]
    failure: Optional[CallbackFailure] = None


@dataclass(frozen=True)
class Waiting:
    """A subject's line on the judge's pipe while its new runtime waits for the judge's first
    ``/clock`` (:meth:`JudgeTime.follow`), read by the judge
    (:attr:`ros2nb.judge.subjects.SubjectProcess.waiting_for`): idle then, it waits for the
    judge, not for the learner's code.

    :ivar waiting: what it waits for (:data:`WAITING_FOR_CLOCK`), or None once it came.
    """

    waiting: Optional[str]


def told(failure: logs.CallbackFailure) -> CallbackFailure:
    """A callback's failure as the runtime keeps it, in the fields the judge reads every
    callback's failure in: the exception's class as ``type``, ros2nb's explanation when it
    had one (then also the ``message``), else Python's own message."""
    if failure.explained:
        message, explanation = failure.error, failure.error
    else:  # ``Type: message``, as the runtime words it
        message, explanation = failure.error.split(': ', 1)[-1], None
    return CallbackFailure(callback=failure.callback, node=failure.node, type=failure.kind,
                           message=message, explanation=explanation, where=failure.where,
                           traceback=list(failure.traceback))


class JudgeTime:
    """A judge's simulated time, as a subject's runtime follows it.

    The runtime takes each ``/clock`` step the judge publishes (:meth:`on_clock`), runs what
    became due, then writes one line of JSON to the judge's pipe (:meth:`ack`): the step it
    finished, how far it still wants the clock to go, and how many messages this process
    has published per topic and logged per logger so far.  Every ``Publisher.publish`` of the
    process is counted (class-wide, once): the judge waits for that many to arrive before
    its next step, so that it stamps each with the step that made it.
    """

    _counts: Counter[str] = Counter()
    _logged: Counter[str] = Counter()
    _counting = False
    _claimed: Optional[int] = None
    #: The topics the judge hears (:data:`JUDGE_TOPICS_ENV`).
    topics: frozenset[str] = frozenset()

    def __init__(self, fd: int) -> None:
        self._fd = fd
        #: The newest step of the judge's clock received (ns).
        self.latest_ns: Optional[int] = None
        #: ``/clock`` messages received: the judge publishes the same time again once it
        #: has heard everything a finished spin told it of (:meth:`Runtime._follow_judge`).
        self.heard = 0
        self._count_publishing()

    @classmethod
    def claim(cls) -> None:
        """Take the judge's pipe out of the environment (:data:`JUDGE_CLOCK_ENV`), once: a
        program this process starts must not inherit its number (another file of the
        child's may have it).  A subject calls it first thing."""
        value = os.environ.pop(JUDGE_CLOCK_ENV, '')
        if value.isdigit():
            cls._claimed = int(value)
        try:
            topics = json.loads(os.environ.pop(JUDGE_TOPICS_ENV, '[]'))
        except ValueError:
            topics = []
        cls.topics = cls.topics or frozenset(t for t in topics if isinstance(t, str))

    @classmethod
    def pipe(cls) -> Optional[int]:
        """The judge's pipe of this process (:meth:`claim`), or None when it has none."""
        return cls._claimed

    @classmethod
    def published(cls) -> Optional[dict[str, int]]:
        """Messages this process has published so far, per topic; None when nothing is
        counted here (no judge's time was made in this process)."""
        return dict(cls._counts) if cls._counting else None

    @classmethod
    def logged(cls) -> dict[str, int]:
        """Lines this process has logged so far, per logger (none when nothing is counted
        here): the lines its own nodes sent, never those that another process's node of the
        same name sent, which this process's /rosout subscription hears as well."""
        return dict(cls._logged) if cls._counting else {}

    @classmethod
    def for_this_process(cls) -> Optional['JudgeTime']:
        """The judge's time when this process is a judge's subject, else None."""
        cls.claim()
        return None if cls._claimed is None else cls(cls._claimed)

    @classmethod
    def _count_publishing(cls) -> None:
        """Count every message published and every line logged from Python, at the source:
        a line counted when it reaches this process's own /rosout subscription may still be
        on its way when the step is acknowledged."""
        if cls._counting:
            return
        cls._counting = True
        publish, emit = Publisher.publish, rclpy_implementation.rclpy_logging_rcutils_log

        def counted(self: Publisher, msg: Any) -> None:
            publish(self, msg)
            cls._counts[self.topic_name] += 1

        # rclpy's logger calls this once it decided to log, with the caller found already:
        # counting here leaves the file and line every /rosout message names unchanged.
        def logged(severity: Any, name: str, *rest: Any) -> Any:
            made = emit(severity, name, *rest)
            cls._logged[name] += 1
            return made

        Publisher.publish = counted  # type: ignore[method-assign]  # every publisher, counted
        rclpy_implementation.rclpy_logging_rcutils_log = logged

    def on_clock(self, msg: Clock) -> None:
        """Take one step of the judge's clock (the ``/clock`` subscription's callback)."""
        now = msg.clock.sec * 1_000_000_000 + msg.clock.nanosec
        self.heard += 1
        if self.latest_ns is None or now > self.latest_ns:
            self.latest_ns = now

    def ack(self, now_ns: int, wants_ns: Optional[int], failures: list[logs.CallbackFailure],
            ours: Callable[[str], bool]) -> None:
        """Tell the judge that every callback due at ``now_ns`` has run (an
        :class:`Acknowledgement`).

        :param wants_ns: how far the running spin wants the clock to go (None: no further).
        :param ours: which loggers' lines to count: those of the nodes the runtime runs (a
            logger of no node's, or of a node without /rosout, logs nothing the judge hears).
        :param failures: the callbacks that raised so far; the first is told (:func:`told`).
        """
        self._say(Acknowledgement(
            t=now_ns, wants=wants_ns, published=dict(self._counts),
            logged={name: count for name, count in self._logged.items() if ours(name)},
            failure=told(failures[0]) if failures else None))

    # ------------------------------------------------------------ what the runtime asks
    def follow(self, runtime: Any) -> None:
        """Subscribe ``runtime``'s own node to the judge's ``/clock`` and take its time now:
        waits for the judge's latest step (kept for late joiners), and says so on the judge's
        pipe meanwhile (:data:`WAITING_FOR_CLOCK`): a process that sits idle there waits for
        the judge, not for the learner's code."""
        runtime.node.create_subscription(Clock, '/clock', self.on_clock, JUDGE_CLOCK_QOS)
        if self.latest_ns is None:
            self._say(Waiting(WAITING_FOR_CLOCK))
            while self.latest_ns is None:
                runtime._run_one(JUDGE_STEP_WAIT_S)
            self._say(Waiting(None))
        runtime.sim_now_ns = self.latest_ns

    def _say(self, what: Union[Acknowledgement, Waiting]) -> None:
        """One line of JSON on the judge's pipe."""
        line = json.dumps(dataclasses.asdict(what)) + '\n'
        with contextlib.suppress(OSError):  # the judge went away: nothing left to tell
            os.write(self._fd, line.encode())

    def take_latest(self, runtime: Any) -> None:
        """Move ``runtime`` to the judge's latest step, if the judge's clock moved on."""
        with runtime.exclusive():
            runtime.drain()
            if self.latest_ns is not None and self.latest_ns > runtime.sim_now_ns:
                runtime.sim_now_ns = self.latest_ns
                runtime._publish_clock()

    @staticmethod
    def deafen(node: Node) -> None:
        """A node's time moves only when the runtime takes the judge's step, never on its
        own: its time source's ``/clock`` subscription would let its timers run a step early,
        while the runtime still waits."""
        source = getattr(node, '_time_source', None)
        subscription = getattr(source, '_clock_sub', None)
        if subscription is not None:
            node.destroy_subscription(subscription)
            source._clock_sub = None  # type: ignore[union-attr]  # found on it just above

    def advance(self, runtime: Any, end_ns: int, until: Optional[Callable[[], bool]],
                on_step: Optional[Callable[[], None]]) -> None:
        """``runtime.advance_sim_time`` in a judge's subject: wait for each step of the
        judge's clock, run what became due, and tell the judge, until ``end_ns`` or
        ``until()``.

        How far each step goes is the judge's to decide; this process only says how far its
        spin wants to go (the judge may stop sooner, and then this waits for ever: the judge
        ends the process).
        """
        with runtime.exclusive():
            _reach_judge(runtime, self.topics)
            runtime.drain()
            self.ack(runtime.sim_now_ns, end_ns, runtime.failures, runtime.is_ours)
            while runtime.sim_now_ns < end_ns and not (until and until()):
                while self.latest_ns is None or self.latest_ns <= runtime.sim_now_ns:
                    runtime.stop_button.point()
                    runtime._run_one(JUDGE_STEP_WAIT_S)
                runtime.sim_now_ns = self.latest_ns
                runtime._publish_clock()
                runtime.drain()
                if on_step is not None:
                    on_step()
                self.ack(runtime.sim_now_ns, end_ns, runtime.failures, runtime.is_ours)
            released = self.heard
            self.ack(runtime.sim_now_ns, None, runtime.failures, runtime.is_ours)

            def taken(condition: Callable[[], bool], seconds: float) -> bool:
                deadline = time.monotonic() + seconds
                while not condition() and time.monotonic() < deadline:
                    runtime.stop_button.point()
                    runtime._run_one(min(JUDGE_STEP_WAIT_S, seconds))
                return condition()

            # Go on (the caller may destroy the nodes next, and with them their lines not yet
            # delivered) once the judge says it heard all of it, at most JUDGE_MATCH_WAIT_S.
            wait_for_work(lambda: self.heard != released, [os.getpid()], JUDGE_MATCH_WAIT_S,
                          look=taken)


def _reach_judge(runtime: Any, topics: frozenset[str]) -> None:
    """Wait (at most :data:`JUDGE_MATCH_WAIT_S`) until each publisher of ``runtime``'s on a
    topic the judge hears has matched a subscription: a message published before the judge's
    subscription was discovered would never reach it (a volatile topic keeps nothing for late
    joiners), however idle or busy the machine."""
    publishers = [p for node in (runtime.node, *runtime.nodes.values()) for p in node.publishers
                  if p.topic_name in topics]
    wait_for_work(lambda: all(p.get_subscription_count() >= 1 for p in publishers),
                  [os.getpid()], JUDGE_MATCH_WAIT_S)


def install() -> None:
    """Claim the judge's pipe for this process (:meth:`JudgeTime.claim`) and make every
    runtime it starts follow the judge's time
    (:func:`ros2nb.runtime.simulated_clock.follow_judge_time`).  A subject calls it first
    thing, before the learner's code runs."""
    JudgeTime.claim()
    follow_judge_time(JudgeTime.for_this_process)
