"""Run ROS 2 nodes inside a Jupyter kernel: one executor, one thread, logs in the cell.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

The kernel owns one :class:`Runtime`.  It initialises rclpy without signal
handlers, spins every node handed to it with ONE ``SingleThreadedExecutor`` in
ONE background thread, and prints the nodes' log lines (read back from
``/rosout``) in the cell that called :func:`spin`.  On simulated time the main
thread pauses that background thread, steps ``/clock`` itself from one timer
deadline to the next and runs every callback until the graph is idle, so the
output is identical on every run when ``random`` is seeded.
"""

from __future__ import annotations

import atexit
import collections
import contextlib
import os
import sys
import threading
import time
import traceback
from dataclasses import dataclass
from typing import Callable, Iterable, Iterator, Optional, Union

import rclpy
from rclpy.executors import (ExternalShutdownException, ShutdownException,
                             SingleThreadedExecutor, TimeoutException)
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions

#: Hidden name of the kernel's own node (names starting with ``_`` are hidden
#: from ``ros2 node list``, as the ros2cli daemon's are).
INTERNAL_NODE_NAME = '_ros2nb'
#: How long the background thread waits for work before checking for a pause (s).
BACKGROUND_WAIT_S = 0.1
#: Longest silence a simulated-time run skips in one step when no timer is due (s).
MAX_SIM_STEP_S = 1.0
#: Log lines kept while no cell is reading them; older ones are counted, not kept.
MAX_PENDING_LOG_LINES = 2000
#: rcl_interfaces/msg/Log levels -> the console's severity names.
SEVERITY_NAMES = {10: 'DEBUG', 20: 'INFO', 30: 'WARN', 40: 'ERROR', 50: 'FATAL'}

NodeOrName = Union[Node, str]


class Ros2nbError(RuntimeError):
    """A ros2nb call could not be done; the message says what to do next."""


@dataclass(frozen=True)
class CallbackFailure:
    """A callback that raised inside the executor.

    :ivar node: fully qualified name of the node whose callback raised.
    :ivar callback: qualified name of the callback, e.g. ``TemperatureMonitor.temperature_callback``.
    :ivar error: ``ExceptionType: message``.
    :ivar where: the learner's own line, ``line N: source``; empty when none was found.
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


def _fully_qualified_name(node: Node) -> str:
    return node.get_fully_qualified_name()


def _learner_frame(exc: BaseException) -> str:
    """Return ``line N: source`` for the innermost frame outside rclpy and ros2nb."""
    here = os.path.dirname(os.path.abspath(__file__))
    rclpy_dir = os.path.dirname(os.path.abspath(rclpy.__file__))
    found = ''
    for frame in traceback.extract_tb(exc.__traceback__):
        path = os.path.abspath(frame.filename)
        if path.startswith(here) or path.startswith(rclpy_dir):
            continue
        shown = os.path.basename(path) if os.path.isfile(path) and 'ipykernel' not in path else 'cell'
        found = f'in {shown}, line {frame.lineno}: {(frame.line or "").strip()}'
    return found


class Runtime:
    """The kernel's ROS 2 runtime: rclpy context, one executor, one spin thread.

    Create it with :func:`start`; use the module-level functions, not this class.
    """

    def __init__(self, *, domain_id: Optional[int], sim_time: bool) -> None:
        self.sim_time_default = sim_time
        self.sim_now_ns = 0
        self._nodes: dict[str, Node] = {}
        self._sim_enabled: set[str] = set()
        self._retired: dict[str, list[Node]] = {}
        # (logger name | None for our own lines | CallbackFailure, level, text or failure)
        self._log_lines: collections.deque[tuple] = collections.deque()
        self._dropped_log_lines = 0
        self._lock = threading.Lock()
        self._pause_requested = threading.Event()
        self._paused = threading.Event()
        self._resume = threading.Event()
        self._stopping = False
        self._exclusive_depth = 0

        rclpy.init(args=['--ros-args', '--disable-stdout-logs', '--disable-external-lib-logs'],
                   domain_id=domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.domain_id = rclpy.get_default_context().get_domain_id()
        from rcl_interfaces.msg import Log
        from rosgraph_msgs.msg import Clock
        self._clock_type = Clock
        self.executor = SingleThreadedExecutor()
        self.node = Node(INTERNAL_NODE_NAME)
        self._clock_publisher = self.node.create_publisher(Clock, '/clock', 10)
        rosout_qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                                durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(Log, '/rosout', self._on_log, rosout_qos)
        self.executor.add_node(self.node)
        self._thread = threading.Thread(target=self._spin_in_background,
                                        name='ros2nb-executor', daemon=True)
        self._thread.start()

    # ----------------------------------------------------------------- logs
    def _on_log(self, msg) -> None:
        with self._lock:
            if len(self._log_lines) >= MAX_PENDING_LOG_LINES:
                self._log_lines.popleft()
                self._dropped_log_lines += 1
            self._log_lines.append((msg.name, msg.level, msg.msg))

    def emit(self, text: str) -> None:
        """Queue a line of our own (e.g. an echoed message) in order with the log lines."""
        with self._lock:
            self._log_lines.append((None, 0, text))

    def _is_ours(self, logger_name: str) -> bool:
        """True for the loggers of nodes handed over (and their child loggers)."""
        names = [node.get_logger().name for node in list(self._nodes.values())]
        return any(logger_name == n or logger_name.startswith(n + '.') for n in names)

    def print_pending(self, *, show_logs: bool = True) -> int:
        """Print (from the calling thread) log lines and callback failures collected so far.

        :return: the number of log lines taken (printed or, with ``show_logs=False``, hidden).
        """
        with self._lock:
            queued, self._log_lines = list(self._log_lines), collections.deque()
            dropped, self._dropped_log_lines = self._dropped_log_lines, 0
        if show_logs and dropped:
            print(f'({dropped} older log lines were not kept)')
        taken = dropped
        for name, level, text in queued:
            if name is CallbackFailure:
                sys.stdout.flush()
                print(text, file=sys.stderr)
                sys.stderr.flush()
            elif name is None or self._is_ours(name):
                taken += 1
                if show_logs:
                    print(text if name is None else
                          f'[{SEVERITY_NAMES.get(level, level)}] [{name}]: {text}')
        sys.stdout.flush()
        return taken

    # ------------------------------------------------------------- executor
    def _run_one(self, timeout_sec: float) -> bool:
        """Run one ready callback; return False when none became ready in time."""
        try:
            handler, entity, node = self.executor.wait_for_ready_callbacks(timeout_sec=timeout_sec)
        except TimeoutException:
            return False
        handler()
        error = handler.exception()
        if error is not None:
            callback = getattr(entity, 'callback', None)
            failure = CallbackFailure(
                node=_fully_qualified_name(node),
                callback=getattr(callback, '__qualname__', repr(callback)),
                error=f'{type(error).__name__}: {error}',
                where=_learner_frame(error))
            with self._lock:
                self._log_lines.append((CallbackFailure, 0, failure))
            if node is not self.node:
                self._retire(node)
        return True

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
        """
        total = 0
        while True:
            # With a zero timeout rclpy ends every wait round with TimeoutException, even
            # one that ran callbacks, so "idle" is a round in which nothing ran.
            in_round = 0
            while self._run_one(0.0):
                in_round += 1
            if in_round == 0:
                return total
            total += in_round

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
        if not isinstance(node, Node):
            raise TypeError(f'ros2nb.add() takes an rclpy Node, not {type(node).__name__}: '
                            'create the node first, e.g. add(TemperatureSensor()).')
        name = _fully_qualified_name(node)
        with self.exclusive():
            old = self._nodes.get(name)
            if old is not None and old is not node:
                self._retire(old)
            self._nodes[name] = node
            self.executor.add_node(node)
            if self.sim_time_default:
                self._use_sim_time([node], True)
            self.drain()
        return node

    def _retire(self, node: Node) -> None:
        """Take a replaced or failed node out of service without destroying the node itself.

        rcl registers one /rosout publisher per logger name; destroying the old node would
        unregister it for the new node of the same name too, and its logs would vanish.
        So every timer, publisher, subscription and service of the old node is destroyed
        (nothing stale keeps running) and the empty node is kept until no live node has
        that name.
        """
        name = _fully_qualified_name(node)
        del self._nodes[name]
        self._sim_enabled.discard(name)
        self.executor.remove_node(node)
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

    def _destroy(self, node: Node) -> None:
        """Stop a running node for good, with the retired nodes of its name."""
        name = _fully_qualified_name(node)
        del self._nodes[name]
        self._sim_enabled.discard(name)
        self.executor.remove_node(node)
        for shell in self._retired.pop(name, []) + [node]:
            shell.destroy_node()

    def stop(self, node: Optional[NodeOrName] = None) -> list[str]:
        with self.exclusive():
            if node is None:
                targets = list(self._nodes.values())
            else:
                targets = [self.find(node)]
            names = [target.get_name() for target in targets]
            for target in targets:
                self._destroy(target)
            self.drain()
        return names

    def find(self, node: NodeOrName) -> Node:
        if isinstance(node, Node):
            key = _fully_qualified_name(node)
        else:
            key = node if node.startswith('/') else '/' + node
        try:
            return self._nodes[key]
        except KeyError:
            running = ', '.join(sorted(self._nodes)) or 'none'
            raise Ros2nbError(f'No running node named {key!r} (running: {running}); '
                              'hand it over with ros2nb.add(node) first.') from None

    @property
    def nodes(self) -> dict[str, Node]:
        return dict(self._nodes)

    # ------------------------------------------------------------ sim time
    def _publish_clock(self) -> None:
        msg = self._clock_type()
        msg.clock.sec, msg.clock.nanosec = divmod(self.sim_now_ns, 1_000_000_000)
        self._clock_publisher.publish(msg)

    def _use_sim_time(self, nodes: Iterable[Node], enabled: bool) -> None:
        """Switch nodes to (or from) simulated time; timers restart on the new clock."""
        changed = []
        for node in nodes:
            name = _fully_qualified_name(node)
            if (name in self._sim_enabled) == enabled:
                continue
            node.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, enabled)])
            (self._sim_enabled.add if enabled else self._sim_enabled.discard)(name)
            changed.append(node)
        if not changed:
            return
        if enabled:
            self._publish_clock()
            self.drain()
        for node in changed:
            for timer in node.timers:
                if not timer.is_canceled():
                    timer.reset()

    def _next_timer_ns(self) -> Optional[int]:
        due = [timer.time_until_next_call()
               for node in self._nodes.values() for timer in node.timers
               if not timer.is_canceled()]
        due = [d for d in due if d is not None]
        return max(0, min(due)) if due else None

    def advance_sim_time(self, seconds: float, *, until: Optional[Callable[[], bool]] = None,
                         on_step: Optional[Callable[[], None]] = None) -> float:
        """Step ``/clock`` by ``seconds``, running every callback that becomes due.

        :return: simulated seconds actually advanced (less when ``until()`` became true).
        """
        start = self.sim_now_ns
        end = start + round(seconds * 1e9)
        with self.exclusive():
            self._use_sim_time(self._nodes.values(), True)
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

    def use_wall_time(self) -> None:
        with self.exclusive():
            self._use_sim_time(self._nodes.values(), False)
            self.drain()

    # ------------------------------------------------------------ shutdown
    def shutdown(self) -> None:
        self._stopping = True
        self._pause_requested.clear()
        self._resume.set()
        self.executor.wake()
        self._thread.join()
        for node in list(self._nodes.values()):
            self._destroy(node)
        for shells in self._retired.values():
            for shell in shells:
                shell.destroy_node()
        self._retired.clear()
        self.executor.remove_node(self.node)
        self.node.destroy_node()
        self.executor.shutdown()
        rclpy.try_shutdown()


_runtime: Optional[Runtime] = None


def _enable_field_checks() -> None:
    """Turn on rosidl's generated type/range checks, also for already imported messages."""
    os.environ['ROS_PYTHON_CHECK_FIELDS'] = '1'
    for module in list(sys.modules.values()):
        if getattr(module, 'ros_python_check_fields', None) == '':
            module.ros_python_check_fields = '1'


def start(*, domain_id: Optional[int] = None, sim_time: bool = False) -> Runtime:
    """Bring ROS 2 up for this kernel; calling it again is harmless.

    Initialises rclpy with no signal handlers (the kernel's Stop button must not shut ROS
    down), turns on message field checks (``ROS_PYTHON_CHECK_FIELDS=1``), keeps discovery
    on this machine (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST``) unless you set that
    variable yourself, and starts the background executor thread.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param domain_id: ROS domain id (0-101); ``None`` uses ``ROS_DOMAIN_ID`` or 0.
    :param sim_time: ``True`` puts every node handed over on simulated time, frozen
        between calls, so that :func:`spin` and the graph verbs print the same output
        on every run.
    :return: the kernel's runtime.
    :raises Ros2nbError: if ROS is already up with another domain id, or rclpy was
        initialised outside ros2nb.
    """
    global _runtime
    if _runtime is not None:
        if domain_id is not None and domain_id != _runtime.domain_id:
            raise Ros2nbError(f'ROS is already up on domain {_runtime.domain_id}; call '
                              'ros2nb.shutdown() first to change the domain id.')
        _runtime.sim_time_default = sim_time
        return _runtime
    if rclpy.ok():
        raise Ros2nbError('rclpy was initialised outside ros2nb (rclpy.init() was called); '
                          'restart the kernel and call ros2nb.start() instead.')
    if domain_id is not None and not 0 <= domain_id <= 232:
        raise ValueError(f'domain_id must be between 0 and 232, and 0-101 is safe on Linux '
                         f'(got {domain_id}).')
    _enable_field_checks()
    os.environ.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    _runtime = Runtime(domain_id=domain_id, sim_time=sim_time)
    atexit.register(shutdown)
    return _runtime


def runtime() -> Runtime:
    """Return the kernel's runtime.

    :raises Ros2nbError: if :func:`start` has not been called.
    """
    if _runtime is None:
        raise Ros2nbError('ROS is not up in this kernel yet: run ros2nb.start() first.')
    return _runtime


def add(node: Node) -> Node:
    """Hand a node to the kernel's executor, replacing a running node of the same name.

    Re-running the cell that creates a node therefore never doubles it: the old node
    (its timers and subscriptions) is destroyed first.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node: the node to spin in the background.
    :return: the same node, so ``sensor = ros2nb.add(TemperatureSensor())`` works.
    :raises Ros2nbError: if :func:`start` has not been called.
    :raises TypeError: if ``node`` is not an rclpy ``Node``.
    """
    return runtime().add(node)


def stop(node: Optional[NodeOrName] = None) -> list[str]:
    """Stop and destroy one running node, or all of them; ROS itself stays up.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node: the node or its name (``'temperature_sensor'``); ``None`` stops all nodes.
    :return: names of the nodes stopped.
    :raises Ros2nbError: if no running node has that name, or ROS is not up.
    """
    return runtime().stop(node)


def spin(seconds: float, *, sim_time: Optional[bool] = None, show_logs: bool = True) -> float:
    """Let the nodes run for ``seconds`` and print their log lines in this cell.

    Log lines use the ROS console format without timestamps
    (``[INFO] [temperature_sensor]: Publishing: 22.31C``).  A callback that raises is
    reported here with its node, callback and line, and only that node is stopped.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param seconds: how long to run, in seconds (simulated or wall-clock).
    :param sim_time: ``True`` steps a simulated ``/clock`` (60 s of a 1 Hz node take a
        fraction of a second and the output is the same on every run); ``False`` waits
        in real time; ``None`` uses the choice given to :func:`start`.
    :param show_logs: ``False`` hides the log lines and prints how many there were.
    :return: seconds actually run.
    :raises Ros2nbError: if ROS is not up.
    :raises ValueError: if ``seconds`` is negative.
    """
    rt = runtime()
    if seconds < 0:
        raise ValueError(f'seconds must be zero or more (got {seconds}).')
    use_sim = rt.sim_time_default if sim_time is None else sim_time
    hidden = 0

    def flush() -> None:
        nonlocal hidden
        hidden += rt.print_pending(show_logs=show_logs)

    flush()
    if use_sim:
        ran = rt.advance_sim_time(seconds, on_step=flush)
    else:
        rt.use_wall_time()
        deadline = time.monotonic() + seconds
        try:
            while (left := deadline - time.monotonic()) > 0:
                time.sleep(min(0.1, left))
                flush()
        except KeyboardInterrupt:
            print('Interrupted: the nodes keep running in the background; '
                  'ros2nb.stop() stops them.')
        ran = seconds - max(0.0, deadline - time.monotonic())
    flush()
    if not show_logs:
        print(f'({hidden} log lines hidden)')
    return ran


def shutdown() -> None:
    """Stop every node, stop the executor, join its thread and shut rclpy down.

    Safe to call twice; :func:`start` works again afterwards.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.
    """
    global _runtime
    if _runtime is not None:
        rt, _runtime = _runtime, None
        rt.shutdown()
