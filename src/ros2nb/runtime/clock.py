"""The kernel's clock: simulated time stepped by ros2nb, or the wall clock, or a judge's.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`SimulatedClock` side of it); the one
place that decides a node's clock.  On simulated time the nodes are frozen between cells;
inside a spin the main thread pauses the background thread, steps ``/clock`` from one
timer deadline to the next and runs every callback until the graph is idle, so the output
is identical on every run when ``random`` is seeded.

In a judge's subject (the process that runs the learner's code for a check, see
:mod:`ros2nb.judge`) simulated time is the judge's, never this process's: the runtime
follows the judge's ``/clock`` (:class:`JudgeTime`), publishes none, and after each step it
finished (every callback due then has run) it says so on a pipe of the judge's.  What it
says there only tells the judge when to look and how long to wait: the judge stamps what
it hears with its own clock.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import time
from collections import Counter
from typing import Any, Callable, Iterable, Iterator, Optional

from rclpy.clock import ROSClock
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.publisher import Publisher
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.time import Time
from rosgraph_msgs.msg import Clock

from .nodes import drop_qos_warnings, rclpys_own_entities

#: Longest silence a simulated-time run skips in one step when no timer is due (s).
MAX_SIM_STEP_S = 1.0
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
#: Wall-clock seconds a subject's spin waits at most for its publishers to reach the judge.
JUDGE_MATCH_WAIT_S = 30.0
#: Seconds one wait for the judge's next step lasts before it is waited for again.
JUDGE_STEP_WAIT_S = 0.5


class JudgeTime:
    """A judge's simulated time, as a subject's runtime follows it.

    The runtime takes each ``/clock`` step the judge publishes (:meth:`on_clock`), runs what
    became due, then writes one line of JSON to the judge's pipe (:meth:`ack`): the step it
    finished, how far it still wants the clock to go, and how many messages this process
    has published per topic and logged per logger so far.  Every ``Publisher.publish`` of the
    process is counted (class-wide, once): the judge waits for that many to arrive before
    its next step, so that it stamps each with the step that made it.
    """

    _counts: Counter = Counter()
    _logged: Counter = Counter()
    _counting = False
    _claimed: Optional[int] = None
    #: The topics the judge hears (:data:`JUDGE_TOPICS_ENV`).
    topics: frozenset = frozenset()

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
    def published(cls) -> Optional[dict[str, int]]:
        """Messages this process has published so far, per topic; None when nothing is
        counted here (no judge's time was made in this process)."""
        return dict(cls._counts) if cls._counting else None

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

        Publisher.publish = counted  # type: ignore[method-assign]
        rclpy_implementation.rclpy_logging_rcutils_log = logged

    def on_clock(self, msg: Clock) -> None:
        """Take one step of the judge's clock (the ``/clock`` subscription's callback)."""
        now = msg.clock.sec * 1_000_000_000 + msg.clock.nanosec
        self.heard += 1
        if self.latest_ns is None or now > self.latest_ns:
            self.latest_ns = now

    def ack(self, now_ns: int, wants_ns: Optional[int], failures: list[Any],
            ours: Callable[[str], bool]) -> None:
        """Tell the judge that every callback due at ``now_ns`` has run.

        :param wants_ns: how far the running spin wants the clock to go (None: no further).
        :param ours: which loggers' lines to count: those of the nodes the runtime runs (a
            logger of no node's, or of a node without /rosout, logs nothing the judge hears).
        :param failures: the callbacks that raised so far
            (:class:`~ros2nb.runtime.logs.CallbackFailure`); the first is told.
        """
        first = dataclasses.asdict(failures[0]) if failures else None
        if first is not None:
            first['traceback'] = list(first['traceback'])
        line = json.dumps({'t': now_ns, 'wants': wants_ns, 'published': dict(self._counts),
                           'logged': {name: count for name, count in self._logged.items()
                                      if ours(name)},
                           'failure': first}) + '\n'
        with contextlib.suppress(OSError):  # the judge went away: nothing left to tell
            os.write(self._fd, line.encode())


#: A node's lists of parameter callbacks (rclpy's own, the time source's among them).
_PARAMETER_CALLBACKS = ('_pre_set_parameters_callbacks', '_on_set_parameters_callbacks',
                        '_post_set_parameters_callbacks')


@contextlib.contextmanager
def _rclpy_callbacks_only(node: Node) -> Iterator[None]:
    """Inside, the node's parameter callbacks are rclpy's own: ros2nb's switch of
    ``use_sim_time`` reaches the learner's as ``-p use_sim_time:=true`` at start-up does in
    ROS, i.e. never (a callback that reads only the thresholds, or refuses what it does not
    know, would otherwise fail or keep the node off the clock)."""
    saved = {}
    for name in _PARAMETER_CALLBACKS:
        callbacks = getattr(node, name, None)
        if isinstance(callbacks, list):
            saved[name] = list(callbacks)
            callbacks[:] = [c for c in callbacks if getattr(getattr(c, '__func__', c),
                                                            '__module__', '').startswith('rclpy.')]
    try:
        yield
    finally:
        for name, callbacks in saved.items():
            getattr(node, name)[:] = callbacks


def _deaf_to_clock(node: Node) -> None:
    """In a judge's subject, a node's time moves only when the runtime takes the judge's step
    (:meth:`SimulatedClock._publish_clock`), never on its own: its time source's ``/clock``
    subscription would let its timers run a step early, while the runtime still waits."""
    source = getattr(node, '_time_source', None)
    subscription = getattr(source, '_clock_sub', None)
    if subscription is not None:
        node.destroy_subscription(subscription)
        source._clock_sub = None  # type: ignore[union-attr]


class SimulatedClock:
    """Simulated time: its current value, the nodes on it, and stepping it.

    Needs, from the runtime it is part of: ``_nodes``, ``exclusive``, ``drain``, ``alive``
    and ``_clock_publisher`` (a ``/clock`` publisher).
    """

    def __init__(self, sim_time: bool) -> None:
        #: The kernel's clock: True for simulated time, False for the wall clock.
        self.sim_time = sim_time
        #: Simulated time now, in nanoseconds since the kernel started (in a judge's subject:
        #: the judge's time).
        self.sim_now_ns = 0
        self._on_sim: set[str] = set()
        #: The judge's time, in a judge's subject (None elsewhere).
        self.judge_time = JudgeTime.for_this_process()

    def follow_judge_clock(self) -> None:
        """In a judge's subject: subscribe to the judge's ``/clock`` and take its time now.

        Called once the runtime's own node exists; waits for the judge's latest step (kept
        for late joiners), so that nodes added from here on start at the judge's time.
        """
        judge = self.judge_time
        if judge is None:
            return
        self.node.create_subscription(Clock, '/clock', judge.on_clock, JUDGE_CLOCK_QOS)
        while judge.latest_ns is None:
            self._run_one(JUDGE_STEP_WAIT_S)
        self.sim_now_ns = judge.latest_ns

    def catch_up_with_judge(self) -> None:
        """In a judge's subject: take the judge's latest step (its clock may have moved on for
        another subject since), so that a node added next starts its timers at the judge's
        time now.  Elsewhere nothing happens."""
        judge = self.judge_time
        if judge is None:
            return
        with self.exclusive():
            self.drain()
            if judge.latest_ns is not None and judge.latest_ns > self.sim_now_ns:
                self.sim_now_ns = judge.latest_ns
                self._publish_clock()

    def _publish_clock(self) -> None:
        """Tell everyone the simulated time: ``/clock``, and the kernel's own nodes at once.

        The nodes of this kernel would learn it from ``/clock`` a callback later; setting
        their ROS clocks directly (rclpy's own ``set_ros_time_override``, what their time
        source does with the message) lets their timers fire in the same wait round.  The
        message goes out when anyone else listens: a process, a subscription of a node, a
        node on simulated time that ros2nb did not put there.  Each node told here listens
        too, through its time source's one subscription, whose callback would only set the
        same time again: a simulated hour of notebook 03 spent an eighth of its CPU time so.
        """
        now = Time(nanoseconds=self.sim_now_ns)
        told = 0
        for name in self._on_sim:
            clock = self._nodes[name].get_clock()
            if isinstance(clock, ROSClock) and clock.ros_time_is_active:
                clock.set_ros_time_override(now)
                told += 1
        if self.judge_time is None and self._clock_publisher.get_subscription_count() > told:
            msg = Clock()
            msg.clock.sec, msg.clock.nanosec = divmod(self.sim_now_ns, 1_000_000_000)
            self._clock_publisher.publish(msg)

    def _set_clock(self, nodes: Iterable[Node], sim: bool) -> None:
        """Put nodes on simulated (or wall-clock) time; the one place that changes a node's clock.

        Timers restart on the new clock, so a period counts from the switch.  Only call
        while the background thread is paused.
        """
        changed = []
        for node in nodes:
            name = node.get_fully_qualified_name()
            if (name in self._on_sim) == sim:
                continue
            with _rclpy_callbacks_only(node):
                node.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, sim)])
            if sim and self.judge_time is not None:
                _deaf_to_clock(node)
            # rclpy's own endpoints without their QoS warnings: a kernel's simulated hour of a
            # sensor and a monitor costs 1.6 CPU-s instead of 2.0 (a judge's subject of
            # notebook 10, whose nodes have no time source, 4.1 instead of 4.2); the learner's
            # own publishers and subscriptions keep theirs (notebook 09).
            drop_qos_warnings(node, rclpys_own_entities(node))
            (self._on_sim.add if sim else self._on_sim.discard)(name)
            changed.append(node)
        if not changed:
            return
        if sim:
            self._publish_clock()
            self.drain()
        for node in changed:
            for timer in node.timers:
                if not timer.is_canceled():
                    timer.reset()

    @contextlib.contextmanager
    def clock(self, sim: bool) -> Iterator['SimulatedClock']:
        """Run the nodes on the given clock inside the block, then on the kernel's clock again."""
        with self.exclusive():
            self._set_clock(self._nodes.values(), sim)
        try:
            yield self
        finally:
            if self.alive:
                with self.exclusive():
                    self._set_clock(self._nodes.values(), self.sim_time)

    def _next_timer_ns(self) -> Optional[int]:
        """Simulated nanoseconds until the next timer of a node is due, or None."""
        due = [timer.time_until_next_call()
               for node in self._nodes.values() for timer in node.timers
               if not timer.is_canceled()]
        due = [d for d in due if d is not None]
        return max(0, min(due)) if due else None

    def advance_sim_time(self, seconds: float, *, until: Optional[Callable[[], bool]] = None,
                         on_step: Optional[Callable[[], None]] = None) -> float:
        """Step ``/clock`` by ``seconds``, running every callback that becomes due.

        The nodes must be on simulated time (inside :meth:`clock`, or a simulated-time kernel).

        :return: simulated seconds actually advanced (less when ``until()`` became true).
        :raises KeyboardInterrupt: the Stop button, once every callback due at ``sim_now_ns``
            has run.
        """
        start = self.sim_now_ns
        end = start + round(seconds * 1e9)
        if self.judge_time is not None:
            self._follow_judge(end, until, on_step)
            return (self.sim_now_ns - start) / 1e9
        with self.exclusive():
            self.drain()
            try:
                while self.sim_now_ns < end and not (until and until()):
                    step = self._next_timer_ns()
                    if step is None or step > MAX_SIM_STEP_S * 1e9:
                        step = round(MAX_SIM_STEP_S * 1e9)
                    self.sim_now_ns = min(end, self.sim_now_ns + max(step, 1))
                    self._publish_clock()
                    self.drain()
                    if on_step is not None:
                        on_step()
            except KeyboardInterrupt:
                # The Stop button: run, here and now, what the clock already made due, or the
                # thread that spins between cells would run it after the caller's last line.
                self.drain()
                raise
        return (self.sim_now_ns - start) / 1e9

    def _reach_judge(self, topics: frozenset) -> None:
        """Wait (at most :data:`JUDGE_MATCH_WAIT_S` of the wall clock) until each publisher
        here on a topic the judge hears has matched a subscription: a message published
        before the judge's subscription was discovered would never reach it (a volatile
        topic keeps nothing for late joiners), however idle or busy the machine."""
        publishers = [p for node in (self.node, *self._nodes.values()) for p in node.publishers
                      if p.topic_name in topics]
        deadline = time.monotonic() + JUDGE_MATCH_WAIT_S
        while any(p.get_subscription_count() < 1 for p in publishers) and \
                time.monotonic() < deadline:
            time.sleep(0.01)

    def _follow_judge(self, end: int, until: Optional[Callable[[], bool]],
                      on_step: Optional[Callable[[], None]]) -> None:
        """:meth:`advance_sim_time` in a judge's subject: wait for each step of the judge's
        clock, run what became due, and tell the judge, until ``end`` (ns) or ``until()``.

        How far each step goes is the judge's to decide; this process only says how far its
        spin wants to go (the judge may stop sooner, and then this waits for ever: the judge
        ends the process).
        """
        judge = self.judge_time
        assert judge is not None
        with self.exclusive():
            self._reach_judge(judge.topics)
            self.drain()
            judge.ack(self.sim_now_ns, end, self.failures, self.is_ours)
            while self.sim_now_ns < end and not (until and until()):
                while judge.latest_ns is None or judge.latest_ns <= self.sim_now_ns:
                    self.stop_button.point()
                    self._run_one(JUDGE_STEP_WAIT_S)
                self.sim_now_ns = judge.latest_ns
                self._publish_clock()
                self.drain()
                if on_step is not None:
                    on_step()
                judge.ack(self.sim_now_ns, end, self.failures, self.is_ours)
            released = judge.heard
            judge.ack(self.sim_now_ns, None, self.failures, self.is_ours)
            # Go on (the caller may destroy the nodes next, and with them their lines not yet
            # delivered) once the judge says it heard all of it, at most JUDGE_MATCH_WAIT_S.
            deadline = time.monotonic() + JUDGE_MATCH_WAIT_S
            while judge.heard == released and time.monotonic() < deadline:
                self.stop_button.point()
                self._run_one(JUDGE_STEP_WAIT_S)
