"""The kernel's clock: simulated time stepped by ros2nb, or the wall clock.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`SimulatedClock` side of it); the one
place that decides a node's clock.  On simulated time the nodes are frozen between cells;
inside a spin the main thread pauses the background thread, steps ``/clock`` from one
timer deadline to the next and runs every callback until the graph is idle, so the output
is identical on every run when ``random`` is seeded.
"""

from __future__ import annotations

import contextlib
from typing import Callable, Iterable, Iterator, Optional

from rclpy.clock import ROSClock
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.time import Time
from rosgraph_msgs.msg import Clock

#: Longest silence a simulated-time run skips in one step when no timer is due (s).
MAX_SIM_STEP_S = 1.0


class SimulatedClock:
    """Simulated time: its current value, the nodes on it, and stepping it.

    Needs, from the runtime it is part of: ``_nodes``, ``exclusive``, ``drain``, ``alive``
    and ``_clock_publisher`` (a ``/clock`` publisher).
    """

    def __init__(self, sim_time: bool) -> None:
        #: The kernel's clock: True for simulated time, False for the wall clock.
        self.sim_time = sim_time
        #: Simulated time now, in nanoseconds since the kernel started.
        self.sim_now_ns = 0
        self._on_sim: set[str] = set()

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
        if self._clock_publisher.get_subscription_count() > told:
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
            node.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, sim)])
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
