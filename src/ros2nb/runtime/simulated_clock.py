"""The kernel's clock: simulated time stepped by ros2nb, or the wall clock, or a judge's.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`SimulatedClock` side of it); the one
place that decides a node's clock.  On simulated time the nodes are frozen between cells;
inside a spin the main thread pauses the background thread, steps ``/clock`` from one
timer deadline to the next and runs every callback until the graph is idle, so the output
is identical on every run when ``random`` is seeded.

In a judge's subject (the process that runs the learner's code for a check, see
:mod:`ros2nb.judge`) simulated time is the judge's, never this process's: the subject
installs its judge's time (:func:`follow_judge_time`, with
:class:`ros2nb.subject.judge_time.JudgeTime`), and every runtime of the process then takes
its steps from there and publishes no ``/clock`` of its own.
"""

from __future__ import annotations

import contextlib
from typing import TYPE_CHECKING, Callable, ContextManager, Iterable, Iterator, Optional, Protocol

from rclpy.clock import ROSClock
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.publisher import Publisher
from rclpy.time import Time
from rosgraph_msgs.msg import Clock

from .nodes import drop_qos_warnings, rclpys_own_entities

#: Longest silence a simulated-time run skips in one step when no timer is due (s).
MAX_SIM_STEP_S = 1.0


class JudgeSteps(Protocol):
    """A judge's simulated time, as a runtime in the judge's subject follows it
    (:class:`ros2nb.subject.judge_time.JudgeTime`)."""

    def follow(self, runtime: 'SimulatedClock') -> None: ...
    def take_latest(self, runtime: 'SimulatedClock') -> None: ...
    def deafen(self, node: Node) -> None: ...
    def advance(self, runtime: 'SimulatedClock', end_ns: int,
                until: Optional[Callable[[], bool]],
                on_step: Optional[Callable[[], None]]) -> None: ...


#: Makes the judge's time for each new runtime of this process; None outside a subject.
_judge_time: Optional[Callable[[], Optional[JudgeSteps]]] = None


def follow_judge_time(make: Callable[[], Optional[JudgeSteps]]) -> None:
    """Make every runtime this process starts from now on follow a judge's time.

    A judge's subject calls it first thing (:mod:`ros2nb.subject`); the kernel never does.

    :param make: called once per new runtime; returns the judge's time, or None.
    """
    global _judge_time
    _judge_time = make
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


class SimulatedClock:
    """Simulated time: its current value, the nodes on it, and stepping it.

    Needs, from the runtime it is part of (declared below for the type checker):
    ``_nodes``, ``exclusive``, ``drain``, ``alive`` and ``_clock_publisher`` (a ``/clock``
    publisher).
    """

    _nodes: dict[str, Node]
    _clock_publisher: Publisher

    if TYPE_CHECKING:  # the runtime's other sides define these: only their types here
        @property
        def alive(self) -> bool: ...
        def exclusive(self) -> ContextManager[object]: ...
        def drain(self) -> int: ...

    def __init__(self, sim_time: bool) -> None:
        #: The kernel's clock: True for simulated time, False for the wall clock.
        self.sim_time = sim_time
        #: Simulated time now, in nanoseconds since the kernel started (in a judge's subject:
        #: the judge's time).
        self.sim_now_ns = 0
        self._on_sim: set[str] = set()
        #: The judge's time, in a judge's subject (None elsewhere: :func:`follow_judge_time`).
        self.judge_time: Optional[JudgeSteps] = _judge_time() if _judge_time else None

    def follow_judge_clock(self) -> None:
        """In a judge's subject: take the judge's time from now on (elsewhere nothing).

        Called once the runtime's own node exists, so that nodes added from here on start at
        the judge's time.
        """
        if self.judge_time is not None:
            self.judge_time.follow(self)

    def take_judge_time(self) -> None:
        """In a judge's subject: take the judge's latest step (its clock may have moved on for
        another subject since), so that a node added next starts its timers at the judge's
        time now.  Elsewhere nothing happens."""
        if self.judge_time is not None:
            self.judge_time.take_latest(self)

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
                self.judge_time.deafen(node)
            # rclpy's own endpoints without their QoS warnings, which could only ever warn of
            # another program's endpoint and add entities to every wait of a simulated hour
            # (docs/decisions.md); the learner's own publishers and subscriptions keep theirs
            # (notebook 09).
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
            self.judge_time.advance(self, end, until, on_step)
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
