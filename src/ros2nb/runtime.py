"""Run ROS 2 nodes inside a Jupyter kernel: one executor, one thread, logs in the cell.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

The kernel owns one :class:`Runtime`.  It initialises rclpy without signal handlers on
the kernel's own ROS domain (:mod:`ros2nb.domains`), spins every node handed to it with
ONE ``SingleThreadedExecutor`` in ONE background thread, and prints the nodes' log lines
(read back from ``/rosout``) in the cell that made them.

The kernel's clock is chosen once, by :func:`start`: simulated or wall-clock time.  On
simulated time the nodes are frozen between cells; inside :func:`spin` (and the graph
verbs) the main thread pauses the background thread, steps ``/clock`` from one timer
deadline to the next and runs every callback until the graph is idle, so the output is
identical on every run when ``random`` is seeded.  ``spin(..., sim_time=False)`` in a
simulated-time kernel runs the nodes on the wall clock for that call only.
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import gc
import math
import os
import sys
import threading
import time
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator, Optional, Union

import rclpy
from rclpy.executors import (ExternalShutdownException, ShutdownException,
                             SingleThreadedExecutor, TimeoutException)
from rclpy.clock import ROSClock
from rclpy.event_handler import PublisherEventCallbacks, SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from rclpy.time import Time

from . import domains
from .errors import Ros2nbError, UsageError

#: Hidden name of the kernel's own node (names starting with ``_`` are hidden
#: from ``ros2 node list``, as the ros2cli daemon's are).
INTERNAL_NODE_NAME = '_ros2nb'
#: How long the background thread waits for work before checking for a pause (s); a
#: pause (every spin, add, stop) waits this long at most.
BACKGROUND_WAIT_S = 0.02
#: Longest silence a simulated-time run skips in one step when no timer is due (s).
MAX_SIM_STEP_S = 1.0
#: Log lines kept while no cell is reading them; older ones are counted, not kept.
MAX_PENDING_LOG_LINES = 2000
#: Callbacks one idle-wait may run before ros2nb calls it a loop that never ends (a burst
#: of a few thousand messages to many subscriptions stays well below).
MAX_CALLBACKS_PER_DRAIN = 10_000
#: rcl_interfaces/msg/Log levels -> the console's severity names.
SEVERITY_NAMES = {10: 'DEBUG', 20: 'INFO', 30: 'WARN', 40: 'ERROR', 50: 'FATAL'}
SHUT_DOWN_MESSAGE = ('ROS 2 was shut down in this kernel (rclpy.shutdown() was called): run '
                     'ros2nb.shutdown(); ros2nb.start() to bring it back, then re-run the cells '
                     'that create your nodes.')

NodeOrName = Union[Node, str]
#: For ros2nb's own subscriptions: no QoS event handlers (rclpy's default warns of
#: incompatible QoS, which the kernel's own subscriptions choose to accept).
QUIET_SUBSCRIPTION = SubscriptionEventCallbacks(use_default_callbacks=False)


@dataclass(frozen=True)
class CallbackFailure:
    """A callback that raised inside the executor.

    :ivar node: fully qualified name of the node whose callback raised.
    :ivar callback: qualified name of the callback, e.g. ``TemperatureMonitor.temperature_callback``.
    :ivar error: ``ExceptionType: message``, or ros2nb's one-line explanation of it.
    :ivar where: the learner's own line, ``FILE line N: source``; empty when none was found.
    """

    node: str
    callback: str
    error: str
    where: str

    def __str__(self) -> str:
        text = (f'[ERROR] [{self.node.lstrip("/")}]: callback {self.callback} raised '
                f'{self.error}')
        if self.where:
            text += f'\n    {self.where}'
        return (text + f'\n    ros2nb stopped node {self.node}; the other nodes keep running. '
                'Fix the callback, re-run the cell that creates the node and hand it over again.')


class Runtime:
    """The kernel's ROS 2 runtime: rclpy context, one executor, one spin thread.

    Create it with :func:`start`; use the module-level functions, not this class.
    """

    def __init__(self, *, domain_id: int, sim_time: bool, background: bool = True) -> None:
        #: The kernel's clock: True for simulated time, False for the wall clock.
        self.sim_time = sim_time
        self.sim_now_ns = 0
        self._nodes: dict[str, Node] = {}
        self._on_sim: set[str] = set()
        self._retired: dict[str, list[Node]] = {}
        self._our_loggers: set[str] = set()
        #: /rosout lines received so far, per logger name (the checks count with it).
        self.log_counts: collections.Counter[str] = collections.Counter()
        # (cell epoch, logger name | None for our own lines | CallbackFailure, level, text)
        self._log_lines: collections.deque[tuple] = collections.deque()
        self._overflow = 0
        self._epoch = 0
        self._lock = threading.Lock()
        self._pause_requested = threading.Event()
        self._paused = threading.Event()
        self._resume = threading.Event()
        self._stopping = False
        self._exclusive_depth = 0
        #: Called with (node name, callback name, exception) when a callback raises.
        self.on_failure: Optional[Callable[[str, str, BaseException], None]] = None
        #: This process's DDS participant (the first 12 bytes of its endpoints' GIDs).
        self.participant_prefix: Optional[bytes] = None

        rclpy.init(args=['--ros-args', '--disable-stdout-logs', '--disable-external-lib-logs'],
                   domain_id=domain_id, signal_handler_options=SignalHandlerOptions.NO)
        self.context = rclpy.get_default_context()
        self.domain_id = self.context.get_domain_id()
        from rcl_interfaces.msg import Log
        from rosgraph_msgs.msg import Clock
        self._clock_type = Clock
        self.executor = SingleThreadedExecutor()
        # The kernel's own node serves nothing and logs nothing: every entity a node has is
        # one more in every wait of the executor, and it waits thousands of times a second.
        self.node = Node(INTERNAL_NODE_NAME, start_parameter_services=False, enable_rosout=False,
                         parameter_overrides=[Parameter('start_type_description_service',
                                                        Parameter.Type.BOOL, False)])
        self._clock_publisher = self.node.create_publisher(
            Clock, '/clock', 10, event_callbacks=PublisherEventCallbacks(use_default_callbacks=False))
        rosout_qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                                durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(Log, '/rosout', self._on_log, rosout_qos,
                                      event_callbacks=QUIET_SUBSCRIPTION)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin_in_background,
                                        name='ros2nb-executor', daemon=True)
        if background:  # without it, callbacks run only in drain() (a check's subject)
            self._thread.start()

    @property
    def alive(self) -> bool:
        """False once ROS was shut down under ros2nb (e.g. by ``rclpy.shutdown()``)."""
        return self.context.ok() and not self._stopping

    def ensure_alive(self) -> None:
        """:raises Ros2nbError: when ROS 2 was shut down under ros2nb."""
        if not self.alive:
            raise Ros2nbError(SHUT_DOWN_MESSAGE)

    # ----------------------------------------------------------------- logs
    def begin_cell(self) -> None:
        """A new cell starts: lines made before it are no longer news (IPython pre_run_cell)."""
        self._epoch += 1

    def _on_log(self, msg) -> None:
        with self._lock:
            self.log_counts[msg.name] += 1
            if len(self._log_lines) >= MAX_PENDING_LOG_LINES:
                self._log_lines.popleft()
                self._overflow += 1
            self._log_lines.append((self._epoch, msg.name, msg.level, msg.msg))

    def emit(self, text: str) -> None:
        """Queue a line of our own (e.g. an echoed message) in order with the log lines."""
        with self._lock:
            self._log_lines.append((self._epoch, None, 0, text))

    def _report_failure(self, failure: CallbackFailure) -> None:
        with self._lock:
            self._log_lines.append((self._epoch, CallbackFailure, 0, failure))

    def is_ours(self, logger_name: str) -> bool:
        """True for the loggers of nodes handed over (and their child loggers)."""
        return any(logger_name == n or logger_name.startswith(n + '.')
                   for n in self._our_loggers)

    def print_pending(self, *, show_logs: bool = True) -> int:
        """Print (from the calling thread) the log lines and callback failures of this cell.

        Lines made while no cell was running (nodes on the wall clock keep running between
        cells) are not shown as if they were new: one line says how many there were.

        :param show_logs: ``False`` hides the log lines; failures are always shown.
        :return: the number of log lines of this cell taken (printed or hidden).
        """
        with self._lock:
            queued, self._log_lines = list(self._log_lines), collections.deque()
            overflow, self._overflow = self._overflow, 0
        earlier = overflow
        taken = 0
        lines: list[str] = []
        for epoch, name, level, text in queued:
            if name is CallbackFailure:
                sys.stdout.flush()
                print(text, file=sys.stderr)
                sys.stderr.flush()
            elif name is None or self.is_ours(name):
                if epoch < self._epoch:
                    earlier += 1
                    continue
                taken += 1
                lines.append(text if name is None else
                             f'[{SEVERITY_NAMES.get(level, level)}] [{name}]: {text}')
        if earlier and show_logs:
            print(f'({earlier} log lines made while no cell was running were not shown)')
        if show_logs and lines:
            print('\n'.join(lines))
        sys.stdout.flush()
        return taken

    # ------------------------------------------------------------- executor
    def _run_one(self, timeout_sec: float) -> Optional[str]:
        """Run one ready callback; return its name, or None when none became ready in time."""
        try:
            handler, entity, node = self.executor.wait_for_ready_callbacks(timeout_sec=timeout_sec)
            handler()
        except TimeoutException:
            return None
        except KeyboardInterrupt:  # the Stop button, while rclpy waited or ran a callback
            self._recover_from_interrupt()
            raise
        callback = getattr(entity, 'callback', None)
        label = getattr(callback, '__qualname__', repr(callback))
        error = handler.exception()
        if error is not None:
            from .explain import explain_exception, learner_line
            self._report_failure(CallbackFailure(
                node=node.get_fully_qualified_name(), callback=label,
                error=explain_exception(error) or f'{type(error).__name__}: {error}',
                where=learner_line(error)))
            if self.on_failure is not None:
                self.on_failure(node.get_fully_qualified_name(), label, error)
            if node is not self.node:
                self._discard(node)
        return label

    def _recover_from_interrupt(self) -> None:
        """Undo what an interrupted callback left half done in rclpy's executor.

        rclpy marks an entity as taken and its callback group as busy before it calls the
        callback, and clears both after; a KeyboardInterrupt in between (the Stop button)
        leaves them set, and that node's timers and subscriptions never run again.  Only
        this thread runs callbacks here, so after an interrupt none is running: every
        entity is free again, and unfinished work is dropped (a message not taken stays in
        its queue, a timer not called stays due, so the next wait finds them again).
        """
        with contextlib.suppress(AttributeError):
            self.executor._tasks = []
        for node in [self.node, *self._nodes.values()]:
            for entity in (*node.timers, *node.subscriptions, *node.services, *node.clients,
                           *node.guards, *node.waitables):
                entity._executor_event = False
                group = entity.callback_group
                if getattr(group, '_active_entity', None) is not None:
                    group._active_entity = None

    def _spin_in_background(self) -> None:
        while not self._stopping:
            if self._pause_requested.is_set():
                self._paused.set()
                self._resume.wait()
                self._resume.clear()
                continue
            try:
                self._run_one(BACKGROUND_WAIT_S)
            except (ShutdownException, ExternalShutdownException):
                break
            except Exception:  # the context was shut down under us (rclpy.shutdown())
                if self.context.ok():
                    raise
                break
        self._paused.set()  # nobody waits for a pause of a thread that has ended

    def _pause(self) -> None:
        if self._exclusive_depth == 0 and self._thread.is_alive():
            self._paused.clear()
            self._pause_requested.set()
            self.executor.wake()
            self._paused.wait()
        self._exclusive_depth += 1

    def _unpause(self) -> None:
        self._exclusive_depth -= 1
        if self._exclusive_depth == 0:
            self._pause_requested.clear()
            self._resume.set()

    def drain(self) -> int:
        """Run ready callbacks from this thread until none is ready; return how many ran.

        Only call while the background thread is paused (inside :meth:`exclusive`).

        :raises Ros2nbError: when callbacks keep making work for each other without end
            (e.g. a node that answers every message on its own topic).
        """
        counts: collections.Counter[str] = collections.Counter()
        while True:
            # With a zero timeout rclpy ends every wait round with TimeoutException, even
            # one that ran callbacks, so "idle" is a round in which nothing ran.
            in_round = 0
            while (label := self._run_one(0.0)) is not None:
                in_round += 1
                counts[label] += 1
                if sum(counts.values()) > MAX_CALLBACKS_PER_DRAIN:
                    busiest, times = counts.most_common(1)[0]
                    raise Ros2nbError(
                        f'{busiest} ran {times} times without the clock moving: a callback keeps '
                        'triggering itself (e.g. publishing on the topic it subscribes to); '
                        'stop that node with ros2nb.stop() and fix it.')
            if in_round == 0:
                return sum(counts.values())

    @contextlib.contextmanager
    def exclusive(self) -> Iterator['Runtime']:
        """Context manager: pause the spin thread so this thread may spin the executor."""
        self._pause()
        try:
            yield self
        finally:
            self._unpause()

    # ---------------------------------------------------------------- nodes
    def add(self, node: Node) -> Node:
        """Hand ``node`` over, replacing a running node of the same name; see :func:`add`."""
        self.ensure_alive()
        from .explain import check_node
        check_node(node, self)
        name = node.get_fully_qualified_name()
        with self.exclusive():
            old = self._nodes.get(name)
            if old is not None and old is not node:
                self._retire(old)
            self._nodes[name] = node
            self._our_loggers.add(node.get_logger().name)
            self.executor.add_node(node)
            self._set_clock([node], self.sim_time)
            self.drain()
        return node

    def _forget(self, node: Node) -> str:
        name = node.get_fully_qualified_name()
        self._nodes.pop(name, None)
        self._on_sim.discard(name)
        self.executor.remove_node(node)
        return name

    def _retire(self, node: Node) -> None:
        """Take a replaced node out of service without destroying the node itself.

        rcl registers one /rosout publisher per logger name; destroying the old node would
        unregister it for the new node of the same name too, and its logs would vanish.
        So every timer, publisher, subscription and service of the old node is destroyed
        (nothing stale keeps running) and the empty node is kept until no live node has
        that name.
        """
        name = self._forget(node)
        for timer in list(node.timers):
            node.destroy_timer(timer)
        for publisher in list(node.publishers):
            node.destroy_publisher(publisher)
        for subscription in list(node.subscriptions):
            node.destroy_subscription(subscription)
        for service in list(node.services):
            node.destroy_service(service)
        for client in list(node.clients):
            node.destroy_client(client)
        self._retired.setdefault(name, []).append(node)

    def _discard(self, node: Node) -> None:
        """Stop a node for good, with the retired nodes of its name: it leaves the graph."""
        name = self._forget(node)
        for shell in self._retired.pop(name, []) + [node]:
            shell.destroy_node()

    def stop(self, node: Optional[NodeOrName] = None) -> list[str]:
        """Stop one running node (or all); see :func:`stop`."""
        with self.exclusive():
            targets = list(self._nodes.values()) if node is None else [self.find(node)]
            names = [target.get_name() for target in targets]
            for target in targets:
                self._discard(target)
            if self.alive:
                self.drain()
        return names

    def find(self, node: NodeOrName) -> Node:
        """Return the running node given as a node or a name.

        :raises Ros2nbError: naming the running nodes when there is none of that name.
        """
        if isinstance(node, Node):
            key = node.get_fully_qualified_name()
        elif isinstance(node, str):
            key = node if node.startswith('/') else '/' + node
        else:
            raise UsageError(f'Give a node or its name, not {type(node).__name__}.')
        try:
            return self._nodes[key]
        except KeyError:
            running = ', '.join(sorted(self._nodes)) or 'none'
            raise Ros2nbError(f'No running node named {key!r} (running: {running}); '
                              'hand it over with ros2nb.add(node) first.') from None

    @property
    def nodes(self) -> dict[str, Node]:
        """The running nodes handed over, by fully qualified name."""
        return dict(self._nodes)

    # ----------------------------------------------------------------- clock
    def _publish_clock(self) -> None:
        """Tell everyone the simulated time: ``/clock``, and the kernel's own nodes at once.

        The nodes of this kernel would learn it from ``/clock`` a callback later; setting
        their ROS clocks directly (rclpy's own ``set_ros_time_override``, what their time
        source does with the message) lets their timers fire in the same wait round.  The
        message still goes out, for processes and for clocks ros2nb does not know.
        """
        msg = self._clock_type()
        msg.clock.sec, msg.clock.nanosec = divmod(self.sim_now_ns, 1_000_000_000)
        now = Time(nanoseconds=self.sim_now_ns)
        for name in self._on_sim:
            clock = self._nodes[name].get_clock()
            if isinstance(clock, ROSClock) and clock.ros_time_is_active:
                clock.set_ros_time_override(now)
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
    def clock(self, sim: bool) -> Iterator['Runtime']:
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
        """
        start = self.sim_now_ns
        end = start + round(seconds * 1e9)
        with self.exclusive():
            self.drain()
            while self.sim_now_ns < end and not (until and until()):
                step = self._next_timer_ns()
                if step is None or step > MAX_SIM_STEP_S * 1e9:
                    step = round(MAX_SIM_STEP_S * 1e9)
                self.sim_now_ns = min(end, self.sim_now_ns + max(step, 1))
                self._publish_clock()
                self.drain()
                if on_step is not None:
                    on_step()
        return (self.sim_now_ns - start) / 1e9

    # ------------------------------------------------------------ shutdown
    def shutdown(self) -> None:
        """Stop every node, stop the executor, join its thread and shut rclpy down."""
        self._stopping = True
        self._pause_requested.clear()
        self._resume.set()
        with contextlib.suppress(Exception):  # a shut-down context cannot be woken
            self.executor.wake()
        if self._thread.is_alive():
            self._thread.join()
        for node in list(self._nodes.values()):
            self._discard(node)
        for shells in self._retired.values():
            for shell in shells:
                shell.destroy_node()
        self._retired.clear()
        self.executor.remove_node(self.node)
        self.node.destroy_node()
        self.executor.shutdown()
        _destroy_stray_nodes(self.context)
        rclpy.try_shutdown()


def _destroy_stray_nodes(context: rclpy.context.Context) -> None:
    """Destroy every node still alive on ``context``: made in a cell, never handed over, or kept
    in a variable after ``rclpy.shutdown()``.

    rcl keeps one /rosout publisher per logger name for the whole process.  A node of an
    ended context that Python's garbage collector frees later (whenever that happens)
    unregisters its name's publisher, which by then belongs to the new node of that name:
    the new node's log lines would stop reaching the cell part-way through a spin.
    """
    for candidate in gc.get_objects():
        if isinstance(candidate, Node) and candidate.context is context:
            with contextlib.suppress(Exception):  # already destroyed, or half-built
                candidate.destroy_node()


_runtime: Optional[Runtime] = None
_original_spin = rclpy.spin


def _enable_field_checks() -> None:
    """Turn on rosidl's generated type/range checks, also for already imported messages."""
    os.environ['ROS_PYTHON_CHECK_FIELDS'] = '1'
    for module in list(sys.modules.values()):
        if getattr(module, 'ros_python_check_fields', None) == '':
            module.ros_python_check_fields = '1'


def _spin_in_a_cell(node, executor=None) -> None:
    """``rclpy.spin`` as ros2nb installs it in a kernel: from a cell it explains instead of blocking."""
    if _runtime is not None and threading.current_thread() is threading.main_thread():
        raise Ros2nbError('rclpy.spin(node) never returns in a notebook cell (it spins until '
                          'Ctrl+C): hand the node over with ros2nb.add(node) and let it run with '
                          'ros2nb.spin(seconds).')
    return _original_spin(node, executor)


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
    global _runtime
    if _runtime is not None and not _runtime.alive:
        print('ROS 2 had been shut down in this kernel; starting it again.')
        shutdown()
    if _runtime is not None:
        if domain_id is not None and domain_id != _runtime.domain_id:
            raise Ros2nbError(f'ROS is already up on domain {_runtime.domain_id}; call '
                              'ros2nb.shutdown() first to change the domain id.')
        if sim_time is not None and sim_time != _runtime.sim_time:
            _runtime.sim_time = sim_time
            with _runtime.exclusive():
                _runtime._set_clock(_runtime.nodes.values(), sim_time)
        print(f'ROS 2 is up in this kernel: {_describe(_runtime)}.')
        return _runtime
    if domain_id is not None and not (isinstance(domain_id, int) and 0 <= domain_id <= 232):
        raise UsageError(f'domain_id must be a whole number from 0 to 232, and 0-101 is safe on '
                         f'Linux (got {domain_id!r}).')
    if rclpy.ok():  # rclpy.init() was called in this kernel: take over cleanly
        rclpy.try_shutdown()
        print('rclpy.init() had been called in this kernel; ros2nb shut that down and starts '
              'ROS 2 itself (in a notebook, call ros2nb.start() instead of rclpy.init()).')
    if domain_id is None:
        domain_id = domains.domain_id()
    else:
        os.environ[domains.DOMAIN_ENV] = str(domain_id)
    _enable_field_checks()
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    _runtime = Runtime(domain_id=domain_id, sim_time=bool(sim_time))
    atexit.register(shutdown)
    from . import explain, kernel
    explain.guard_endpoint_types()
    if kernel.install():  # inside IPython: cell hooks, one-line errors, %%part
        rclpy.spin = _spin_in_a_cell
    print(f'ROS 2 is up in this kernel: {_describe(_runtime)}.')
    return _runtime


def current_runtime() -> Runtime:
    """Return the kernel's runtime.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :raises Ros2nbError: if :func:`start` has not been called, or ROS was shut down.
    """
    if _runtime is None:
        raise Ros2nbError('ROS 2 is not up in this kernel yet: run ros2nb.start() first.')
    _runtime.ensure_alive()
    return _runtime


def add(node: Node) -> Node:
    """Hand a node to the kernel's executor, replacing a running node of the same name.

    Re-running the cell that creates a node therefore never doubles it: the old node
    (its timers and subscriptions) is taken out of service first.  What the node logs
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

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node: the node or its name (``'temperature_sensor'``); ``None`` stops all nodes.
    :return: names of the nodes stopped.
    :raises Ros2nbError: if no running node has that name, or ROS is not up.
    """
    rt = current_runtime()
    names = rt.stop(node)
    rt.print_pending()
    return names


def _check_seconds(seconds: float) -> None:
    if isinstance(seconds, bool) or not isinstance(seconds, (int, float)) \
            or not math.isfinite(seconds) or seconds < 0:
        raise UsageError(f'seconds must be a number of seconds, zero or more (got {seconds!r}).')


def spin(seconds: float, *, sim_time: Optional[bool] = None, show_logs: bool = True) -> float:
    """Let the nodes run for ``seconds`` and print their log lines in this cell.

    Log lines use the ROS console format without timestamps
    (``[INFO] [temperature_sensor]: Publishing: 22.31C``).  A callback that raises is
    reported here with its node, callback and line, and only that node is stopped.
    The Stop button ends the spin with one line; the nodes then wait.

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
    taken = 0

    def flush() -> None:
        nonlocal taken
        taken += rt.print_pending(show_logs=show_logs)

    flush()
    ran = 0.0
    started_ns, started_wall = rt.sim_now_ns, time.monotonic()
    try:
        with rt.clock(use_sim):
            if use_sim:
                ran = rt.advance_sim_time(seconds, on_step=flush)
            else:
                deadline = time.monotonic() + seconds
                while (left := deadline - time.monotonic()) > 0:
                    time.sleep(min(0.1, left))
                    flush()
                ran = float(seconds)
    except KeyboardInterrupt:
        ran = ((rt.sim_now_ns - started_ns) / 1e9 if use_sim
               else time.monotonic() - started_wall)
        flush()
        print(f'Interrupted after {ran:.1f} of {seconds:g} {"simulated " if use_sim else ""}'
              's; the nodes wait until the next spin (ros2nb.stop() stops them).')
        return ran
    flush()
    if not show_logs:
        print(f'({taken} log lines hidden)')
    elif taken == 0:
        print(f'(no log lines in {seconds:g} s; running: {", ".join(sorted(rt.nodes))})')
    return ran


def shutdown() -> None:
    """Stop every node, stop the executor, join its thread and shut rclpy down.

    Safe to call twice, and after ``rclpy.shutdown()``; :func:`start` works again
    afterwards (on the same domain).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.
    """
    global _runtime
    if _runtime is not None:
        rt, _runtime = _runtime, None
        rt.shutdown()
