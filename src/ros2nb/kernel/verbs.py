"""The learner's verbs for ROS in a kernel: start, add, stop, spin, shutdown.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.  They run the kernel's one
:class:`ros2nb.runtime.Runtime` and print what happens in the cell that asked.
"""

from __future__ import annotations

import atexit
import contextlib
import difflib
import io
import itertools
import math
import sys
import os
import time
from typing import Callable, Optional

import rclpy
from rclpy.node import Node

from .. import domains, working
from ..errors import Ros2nbError, UsageError
from ..explain.guards import guard_endpoint_types
from ..explain.plots import guard_pyplot
from ..runtime import NodeOrName, Runtime, current_runtime, enable_field_checks, kernel_runtime
from ..runtime.current import participant_prefix, set_kernel_runtime
from . import ipython

def _describe(rt: Runtime) -> str:
    clock = 'simulated time' if rt.sim_time else 'wall-clock time'
    own = ' (claimed for this kernel alone)' if domains.claimed_domain() == rt.domain_id else ''
    return f'domain {rt.domain_id}{own}, {clock}'


def start(*, domain_id: Optional[int] = None, sim_time: Optional[bool] = None) -> Runtime:
    """Bring ROS 2 up for this kernel and say on which domain; calling it again is harmless.

    Initialises rclpy with no signal handlers (the kernel's Stop button must not shut ROS
    down), turns on message field checks (``ROS_PYTHON_CHECK_FIELDS=1``), keeps discovery
    on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``) unless you set that
    variable yourself, puts the kernel on a ROS domain of its own (see
    :func:`ros2nb.domains.domain_id`) and starts the background executor thread.  A second
    message type on a topic is refused with one line when the endpoint is created (rcl
    would print a C error dump), and in a notebook ``rclpy.spin(node)`` explains itself
    instead of blocking the cell.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param domain_id: ROS domain id (0-232, 0-101 safe on Linux); ``None`` uses
        ``ROS_DOMAIN_ID`` if set, else a domain claimed for this kernel alone.
    :param sim_time: ``True`` for simulated time (nodes frozen between calls, the same
        output on every run), ``False`` for the wall clock; ``None`` keeps the clock of a
        running kernel (wall clock the first time).
    :return: the kernel's runtime.
    :raises Ros2nbError: if ROS is already up on another domain.
    :raises DomainsExhaustedError: when every safe domain is taken.
    """
    rt = kernel_runtime()
    if rt is not None and not rt.alive:
        print('ROS 2 had been shut down in this kernel; starting it again.')
        shutdown()
        rt = None
    if rt is not None:
        return _already_up(rt, domain_id, sim_time)
    if domain_id is not None and not (isinstance(domain_id, int) and 0 <= domain_id <= 232):
        raise UsageError(f'domain_id must be a whole number from 0 to 232, and 0-101 is safe on '
                         f'Linux (got {domain_id!r}).')
    if rclpy.ok():  # rclpy.init() was called in this kernel: take over cleanly
        # rclpy.shutdown(), not try_shutdown(): it also takes out rclpy's Ctrl+C handler,
        # which shuts every context down (the Stop button would then end ROS here)
        rclpy.shutdown()
        print('rclpy.init() had been called in this kernel; ros2nb shut that down and starts '
              'ROS 2 itself (in a notebook, call ros2nb.start() instead of rclpy.init()).')
    if domain_id is None:
        domain_id = domains.domain_id()
    else:
        os.environ[domains.DOMAIN_ENV] = str(domain_id)
    enable_field_checks()
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    rt = Runtime(domain_id=domain_id, sim_time=bool(sim_time))
    set_kernel_runtime(rt)
    atexit.register(shutdown)
    guard_endpoint_types(participant_prefix)
    guard_pyplot()  # plt.pause / plt.show in a callback: one line, not a minute of copies
    ipython.install()  # inside IPython: cell hooks, one-line errors, %%part, rclpy.spin explained
    print(f'ROS 2 is up in this kernel: {_describe(rt)}.')
    return rt


def _already_up(rt: Runtime, domain_id: Optional[int], sim_time: Optional[bool]) -> Runtime:
    """:func:`start` called again: keep the runtime, change its clock if asked."""
    if domain_id is not None and domain_id != rt.domain_id:
        raise Ros2nbError(f'ROS is already up on domain {rt.domain_id}; call '
                          'ros2nb.shutdown() first to change the domain id.')
    if sim_time is not None and sim_time != rt.sim_time:
        rt.sim_time = sim_time
        with rt.exclusive():
            rt._set_clock(rt.nodes.values(), sim_time)
    print(f'ROS 2 is up in this kernel: {_describe(rt)}.')
    return rt


def add(node: Node) -> Node:
    """Hand a node to the kernel's executor, replacing a running node of the same name.

    Re-running the cell that creates a node therefore never doubles it: the old node
    (its timers and subscriptions) is taken out of service first, and so is any other node
    of that name made in this kernel and never handed over (one whose ``__init__`` failed
    part-way, say).  What the node logs
    while it starts is printed here.  Common mistakes are refused with one line: a timer
    of period 0, a callback that is not callable (``self.tick()`` instead of
    ``self.tick``), a message passed instead of its type (``Float32()``), a topic used
    with another type by another node, a node whose ``__init__`` never called
    ``super().__init__``.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node: the node to spin in the background.
    :return: the same node, so ``sensor = ros2nb.add(TemperatureSensor())`` works.
    :raises Ros2nbError: if :func:`start` has not been called, or for the mistakes above.
    """
    rt = current_runtime()
    rt.add(node)
    rt.print_pending()
    return node


def stop(node: Optional[NodeOrName] = None) -> list[str]:
    """Stop and destroy one running node, or all of them; ROS itself stays up.

    Every other node of a stopped node's name made in this kernel is destroyed with it
    (rcl's one /rosout publisher per name ends with the first of them destroyed, so none
    of them is left to log without it).

    Their log lines are no longer shown here afterwards (a process started with
    :func:`ros2nb.ros2_start` may run a node of the same name: its lines are not this
    kernel's).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node: the node or its name (``'temperature_sensor'``); ``None`` stops all nodes.
    :return: names of the nodes stopped.
    :raises Ros2nbError: if no running node has that name, or ROS is not up.
    """
    rt = current_runtime()
    names = rt.stop(node)
    rt.print_pending()
    rt.disown_loggers_except({n.get_logger().name for n in rt.nodes.values()})
    return names


def _check_seconds(seconds: float) -> None:
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) \
            or not math.isfinite(seconds) or seconds < 0:
        raise UsageError(f'seconds must be a number of seconds, zero or more (got {seconds!r}).')


class _HeldOutput:
    """What a simulated spin prints, held in order until the spin ends."""

    def __init__(self) -> None:
        self.writes: list[tuple[str, str]] = []
        self.stdout, self.stderr = (_HeldStream(self.writes, 'stdout'),
                                    _HeldStream(self.writes, 'stderr'))

    def replay(self, *, errors_only: bool = False) -> int:
        """Write what was held, in order (only callback failures if ``errors_only``).

        :return: the number of lines of standard output left out.
        """
        writes, self.writes[:] = list(self.writes), []
        dropped = ''.join(text for name, text in writes if name == 'stdout') if errors_only else ''
        kept = [(name, text) for name, text in writes if not (errors_only and name == 'stdout')]
        for name, group in itertools.groupby(kept, key=lambda write: write[0]):
            stream = getattr(sys, name)
            stream.write(''.join(text for _name, text in group))  # one output per run of lines
            stream.flush()
        return len(dropped.splitlines())


class _HeldStream(io.TextIOBase):
    def __init__(self, writes: list[tuple[str, str]], name: str) -> None:
        super().__init__()
        self._writes, self._name = writes, name

    def write(self, text: str) -> int:
        if text:
            self._writes.append((self._name, text))
        return len(text)


def _unheard_subscriptions(rt: Runtime) -> list[str]:
    """One line per subscription of the kernel's nodes whose topic has no publisher while a
    topic of a similar name (a misspelling) has one."""
    graph = rt.node
    published = [name for name, _types in graph.get_topic_names_and_types()
                 if graph.count_publishers(name)]
    lines = []
    for node in rt.nodes.values():
        for subscription in node.subscriptions:
            topic = subscription.topic_name
            if topic in published:
                continue
            close = difflib.get_close_matches(topic, published, n=1, cutoff=0.8)
            if close:
                lines.append(f'{node.get_name()} subscribes to {topic}, which has no '
                             f'publisher, but {close[0]} has one: check the topic name in '
                             'create_subscription.')
    return lines


def spin(seconds: float, *, sim_time: Optional[bool] = None, show_logs: bool = True) -> float:
    """Let the nodes run for ``seconds`` and print their log lines in this cell.

    Log lines use the ROS console format without timestamps
    (``[INFO] [temperature_sensor]: Publishing: 22.31C``).  A callback that raises is
    reported here with its node, callback and line, and only that node is stopped.
    The Stop button ends the spin with one line; then the nodes wait (simulated time) or
    keep running (the wall clock).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param seconds: how long to run, in seconds (simulated or wall-clock).
    :param sim_time: ``True`` steps a simulated ``/clock`` (60 s of a 1 Hz node take a
        fraction of a second and the output is the same on every run); ``False`` waits
        in real time; ``None`` uses the kernel's clock, chosen in :func:`start`.
    :param show_logs: ``False`` hides the log lines and prints how many there were.
    :return: seconds actually run.
    :raises Ros2nbError: if ROS is not up.
    :raises UsageError: if ``seconds`` is negative or not a number.
    """
    rt = current_runtime()
    _check_seconds(seconds)
    use_sim = rt.sim_time if sim_time is None else bool(sim_time)
    if not rt.nodes:
        rt.print_pending(show_logs=show_logs)
        print('No nodes are running in this kernel: hand yours over with ros2nb.add(node), '
              'then spin.')
        return 0.0
    taken, held = 0, _HeldOutput()  # a simulated spin shows its lines when it ends

    def flush() -> None:
        nonlocal taken
        taken += rt.print_pending(show_logs=show_logs)

    def flush_held() -> None:
        with contextlib.redirect_stdout(held.stdout), contextlib.redirect_stderr(held.stderr):
            flush()
        working.say(f'{(rt.sim_now_ns - started_ns) / 1e9:.0f} of {seconds:g} simulated s')

    rt.begin_spin()
    flush()
    ran, started_ns, started_wall = 0.0, rt.sim_now_ns, time.monotonic()
    try:
        # The Stop button is acted on between callbacks and between two looks at the log
        # lines, never inside rclpy or the kernel's output stream (ros2nb.runtime.stop_button).
        with rt.stop_button.held(), rt.clock(use_sim), working.shown('spinning the nodes'):
            if use_sim:
                ran = rt.advance_sim_time(seconds, on_step=flush_held)
                held.replay()
            else:
                ran = _run_on_the_wall_clock(rt, seconds, flush)
    except KeyboardInterrupt:
        ran = ((rt.sim_now_ns - started_ns) / 1e9 if use_sim
               else time.monotonic() - started_wall)
        (flush_held if use_sim else flush)()  # on the wall clock, lines show as they come
        _say_interrupted(rt, held, ran, seconds, use_sim)
        return ran
    flush()
    _say_done(rt, taken, seconds, show_logs)
    return ran


def _run_on_the_wall_clock(rt: Runtime, seconds: float, flush: Callable[[], None]) -> float:
    """Let the background thread run the nodes for ``seconds``, showing their lines as they
    come; the Stop button is acted on between two looks (:raises KeyboardInterrupt:)."""
    deadline = time.monotonic() + seconds
    while (left := deadline - time.monotonic()) > 0:
        time.sleep(min(0.1, left))
        rt.stop_button.point()
        flush()
    return float(seconds)


def _say_interrupted(rt: Runtime, held: '_HeldOutput', ran: float, seconds: float,
                     use_sim: bool) -> None:
    """The one line of a spin ended by the Stop button (a simulated spin's log lines dropped).

    No log line follows it in the cell: lines still on their way over /rosout are dropped,
    and so, on a kernel on the wall clock (whose nodes keep running between spins), are the
    lines its nodes make until the cell's next spin.
    """
    hidden = ' (its log lines are not shown)' if held.replay(errors_only=True) else ''
    rt.mute_cell(until_next_spin=not rt.sim_time)
    after = 'wait until the next spin' if rt.sim_time else 'keep running'
    print(f'Interrupted after {ran:.1f} of {seconds:g} {"simulated " if use_sim else ""}'
          f's{hidden}; the nodes {after} (ros2nb.stop() stops them).')


def _say_done(rt: Runtime, taken: int, seconds: float, show_logs: bool) -> None:
    """What a spin that ran its time adds: unheard subscriptions, hidden or missing log lines."""
    for line in _unheard_subscriptions(rt):
        print(line)
    if not show_logs:
        print(f'({taken} log lines hidden)')
    elif taken == 0:
        print(f'(no log lines in {seconds:g} s; running: {", ".join(sorted(rt.nodes))})')


def shutdown() -> None:
    """Stop every node, stop the executor, join its thread and shut rclpy down.

    Safe to call twice, and after ``rclpy.shutdown()``; :func:`start` works again
    afterwards (on the same domain).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.
    """
    rt = kernel_runtime()
    if rt is not None:
        set_kernel_runtime(None)
        rt.shutdown()
