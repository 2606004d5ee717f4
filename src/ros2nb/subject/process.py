"""What a subject process does for the judge: load the learner's code, run it, report raw facts.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs one).

A check never runs the learner's code in its own process, and never trusts a verdict
from this one.  The judge (:mod:`ros2nb.judge`) starts this process, sends it commands as
JSON lines on file descriptor IN and reads one JSON reply per command on OUT.  Here the
learner's file is imported or their answer cells executed, their node runs on simulated
time in ros2nb's runtime, and only raw facts come back: what the node created (for the
judge to find in its own view of the graph), how many messages it published and logged
(how long the judge waits for them).  The learner's import can rewrite any reply, so none
passes a check: the judge decides from what it observes over ROS and from the learner's
file read as text.
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import random
import sys
import time
import traceback
from pathlib import Path
from types import ModuleType
from typing import Any, Callable, Optional

from rclpy.executors import Executor
from rclpy.node import Node
from std_msgs.msg import Float32
from rclpy.qos import QoSProfile

from .. import domains
from ..endpoints import node_endpoints
from ..errors import Ros2nbError
from ..explain.exceptions import explain_exception, is_library_file, learner_line
from ..qos import profile_fields
from ..runtime import Runtime, current, enable_field_checks
from ..runtime.nodes import KEEP_STOPPED_ENV
from ..runtime.rates import callback_groups, timer_runs

#: Exit code when a command could not even be read.
PROTOCOL_ERROR = 3


def encode(value: Any) -> Any:
    """Return a JSON-safe description of a value the learner's code returned."""
    if value is None or isinstance(value, (bool, int, str)):
        return {'type': type(value).__name__, 'value': value}
    if isinstance(value, float):
        return {'type': 'float', 'value': value if math.isfinite(value) else repr(value)}
    if isinstance(value, Path):
        return {'type': 'Path', 'value': str(value)}
    if isinstance(value, (list, tuple)):
        return {'type': type(value).__name__, 'value': [encode(v) for v in value]}
    if isinstance(value, QoSProfile):  # notebook 09: its policies, which the judge rebuilds
        return {'type': 'QoSProfile', 'value': profile_fields(value)}
    return {'type': type(value).__name__, 'value': repr(value)[:200]}


def decode_argument(value: Any) -> Any:
    """Turn a command's argument into a Python value (``{"path": p}`` becomes a Path)."""
    if isinstance(value, dict) and set(value) == {'path'}:
        return Path(value['path'])
    return value


def describe_error(error: BaseException) -> dict:
    """The learner-facing facts of an exception: type, message, explanation, their traceback."""
    frames = [f for f in traceback.extract_tb(error.__traceback__)
              if not is_library_file(f.filename) and not f.filename.startswith('<ros2nb')]
    lines = ['Traceback (most recent call last):'] if frames else []
    for text in traceback.format_list(frames):
        lines.extend(text.rstrip('\n').splitlines())
    try:
        explanation = explain_exception(error)
    except Exception:
        explanation = None
    return {'type': type(error).__name__, 'message': str(error)[:500],
            'explanation': explanation, 'traceback': lines, 'where': learner_line(error)}


def _without_magics(source: str) -> str:
    """Cell source with IPython line magics and shell escapes commented out."""
    if source.lstrip().startswith('%%'):
        return ''
    return '\n'.join('# ' + line if line.lstrip().startswith(('%', '!')) else line
                     for line in source.splitlines())


def _placeholder(name: str) -> Callable[..., None]:
    """A method that does nothing, named like the one it stands in for."""
    def method(self: Any, *args: Any) -> None:
        return None

    method.__name__ = method.__qualname__ = name
    return method


class Subject:
    """The state of this process: the learner's namespace, module and node."""

    def __init__(self) -> None:
        self.namespace: dict[str, Any] = {'__name__': '__main__'}
        self.rt = None
        self.node = None
        self.published: dict[str, int] = {}
        self.received = 0
        self.fired = 0
        self.failure: Optional[dict] = None
        self.rooms: list[Node] = []  # stand-in nodes of the reusability check (notebook 06)

    # -------------------------------------------------------------- loading
    def exec_cells(self, sources: list[str]) -> dict:
        errors = []
        for index, source in enumerate(sources):
            try:
                code = compile(_without_magics(source), f'<cell {index + 1}>', 'exec')
                exec(code, self.namespace)
            except BaseException as error:  # the learner's cell may raise anything
                errors.append(describe_error(error))
        return {'ok': True, 'cell_errors': errors}

    def load_file(self, path: str, module: str) -> dict:
        file = Path(path)
        if not file.is_file():
            return {'ok': False, 'missing': True}
        spec = importlib.util.spec_from_file_location(module, file)
        assert spec is not None and spec.loader is not None
        loaded: ModuleType = importlib.util.module_from_spec(spec)
        sys.modules[module] = loaded
        try:
            spec.loader.exec_module(loaded)
        except BaseException as error:
            return {'ok': False, 'error': describe_error(error)}
        self.namespace.update(vars(loaded))
        return {'ok': True}

    # ---------------------------------------------------------------- calls
    def call(self, name: str, inputs: list[list[Any]]) -> dict:
        function = self.namespace.get(name)
        if function is None:
            return {'ok': False, 'undefined': True}
        outputs = []
        for arguments in inputs:
            try:
                outputs.append({'result': encode(function(*map(decode_argument, arguments)))})
            except BaseException as error:
                outputs.append({'error': describe_error(error)})
        return {'ok': True, 'outputs': outputs}

    # ---------------------------------------------------------------- nodes
    def _runtime(self):
        if self.rt is None:
            enable_field_checks()
            self.rt = Runtime(domain_id=domains.domain_id(), sim_time=True, background=False)
            self.rt.on_failure = self._on_failure
        return self.rt

    def _on_failure(self, node: str, callback: str, error: BaseException) -> None:
        if self.failure is None:
            self.failure = {'node': node, 'callback': callback, **describe_error(error)}

    def _count_publishes(self, publisher: Any, topic: str) -> None:
        original = publisher.publish

        def counted(msg: Any) -> None:
            original(msg)
            self.published[topic] = self.published.get(topic, 0) + 1

        publisher.publish = counted

    def _count_receipts(self, subscription: Any) -> None:
        original = subscription.callback

        def counted(msg: Any) -> Any:
            self.received += 1
            return original(msg)

        counted.__qualname__ = getattr(original, '__qualname__', 'callback')
        subscription.callback = counted

    def _count_firings(self, timer: Any) -> None:
        original = timer.callback

        def counted() -> Any:
            self.fired += 1
            return original()

        counted.__name__ = getattr(original, '__name__', 'callback')
        counted.__qualname__ = getattr(original, '__qualname__', counted.__name__)
        timer.callback = counted

    def new_node(self, cls: str, placeholders: list[str], seed: Optional[int],
                 args: Optional[list] = None) -> dict:
        rt = self._runtime()
        if self.node is not None:
            if self.node.get_fully_qualified_name() in rt.nodes:
                rt.stop(self.node)
            self.node = None
        node_class = self.namespace.get(cls)
        if not isinstance(node_class, type) or not issubclass(node_class, Node):
            found = sorted(n for n, v in self.namespace.items()
                           if isinstance(v, type) and issubclass(v, Node) and v is not Node)
            return {'ok': False, 'no_class': True, 'classes': found}
        missing = [m for m in placeholders if not callable(getattr(node_class, m, None))]
        if missing:  # a later part is not written yet: stand in for it with a no-op
            node_class = type(node_class.__name__, (node_class,),
                              {m: _placeholder(m) for m in missing})
        if seed is not None:
            random.seed(seed)
        self.published, self.received, self.fired, self.failure = {}, 0, 0, None
        logged_before = dict(rt.log_counts)
        try:
            node = node_class(*(args or []))
        except BaseException as error:
            return {'ok': False, 'error': describe_error(error)}
        try:
            rt.add(node)
        except Ros2nbError as error:
            return {'ok': False, 'refused': str(error)}
        self.node = node
        for publisher in node.publishers:
            self._count_publishes(publisher, node.resolve_topic_name(publisher.topic_name))
        for subscription in node.subscriptions:
            self._count_receipts(subscription)
        for timer in node.timers:
            self._count_firings(timer)
        logger = node.get_logger().name
        return {'ok': True, 'name': node.get_name(), 'namespace': node.get_namespace(),
                'started_lines': rt.log_counts[logger] - logged_before.get(logger, 0),
                'placeholders': missing,
                'endpoints': node_endpoints(node), **self._counts()}

    def _counts(self) -> dict:
        rt = self._runtime()
        logged = 0
        if self.node is not None:
            name = self.node.get_logger().name
            logged = rt.log_counts.get(name, 0)
        return {'published': dict(self.published), 'received': self.received, 'fired': self.fired,
                'logged': logged, 't': rt.sim_now_ns / 1e9, 'failure': self.failure}

    def set_attribute(self, name: str, value: Any) -> dict:
        if self.node is None:
            return {'ok': False}
        setattr(self.node, name, value)
        return {'ok': True}

    def wait_matched(self, topic: str, seconds: float) -> dict:
        """Wait until the node's publishers on ``topic`` reach the judge's subscription."""
        deadline = time.monotonic() + seconds
        node = self.node
        publishers = [p for p in node.publishers
                      if node.resolve_topic_name(p.topic_name) == topic] if node else []
        while time.monotonic() < deadline:
            if publishers and all(p.get_subscription_count() >= 1 for p in publishers):
                return {'ok': True}
            time.sleep(0.01)
        return {'ok': False}

    def counts(self) -> dict:
        return {'ok': True, **self._counts()}

    def keep_stopped_nodes(self) -> dict:
        """From now on a node the learner's code stops stays in the graph, emptied, until this
        process ends: the judge still receives its last /rosout lines (notebook 10)."""
        os.environ[KEEP_STOPPED_ENV] = '1'
        return {'ok': True}

    def lines_logged(self, logger: str) -> dict:
        """:meth:`~ros2nb.runtime.Runtime.lines_made` by the learner's ROS here (notebook 10)."""
        rt = current.kernel_runtime()
        return {'ok': True, 'lines': rt.lines_made(logger) if rt is not None else None}

    def serve(self) -> dict:
        """Spin the node in the background from now on: it answers service calls (its
        parameters) whenever the judge makes them."""
        self._runtime().spin_in_background()
        return {'ok': True, **self._counts()}

    def wait_publishers(self, topic: str, seconds: float) -> dict:
        """Wait until the node's subscriptions on ``topic`` have matched a publisher (the
        judge's).  Their own match, not the graph's list: in a subject that made a node
        before, the graph already lists the judge's publisher while the new subscription
        has not matched it yet, and a reading sent then was lost."""
        deadline = time.monotonic() + seconds
        node = self.node
        subscriptions = [s for s in node.subscriptions
                         if node.resolve_topic_name(s.topic_name) == topic] if node else []
        while subscriptions and time.monotonic() < deadline:  # none: nothing can match
            if all(s.get_publisher_count() >= 1 for s in subscriptions):
                return {'ok': True}
            time.sleep(0.01)
        return {'ok': False}

    def attribute(self, name: str) -> dict:
        """The running node's attribute ``name`` (encoded), or ``missing``."""
        if self.node is None or not hasattr(self.node, name):
            return {'ok': True, 'missing': True}
        return {'ok': True, 'value': encode(getattr(self.node, name))}

    def timer_runs(self, name: str, seconds: float) -> dict:
        """Call the learner's ``name()`` for ``(node, executor)``; spin them on the wall clock."""
        function = self.namespace.get(name)
        if not callable(function):
            return {'ok': False, 'undefined': True}
        self._runtime()
        try:
            made = function()
        except BaseException as error:
            return {'ok': False, 'error': describe_error(error)}
        if not (isinstance(made, tuple) and len(made) == 2 and isinstance(made[0], Node)
                and isinstance(made[1], Executor)):
            return {'ok': False, 'returned': encode(made)}
        node, executor = made
        groups = callback_groups(node)
        try:
            runs = timer_runs(node, executor, seconds)
        except BaseException as error:
            return {'ok': False, 'error': describe_error(error)}
        finally:
            node.destroy_node()
        return {'ok': True, 'executor': type(executor).__name__, 'groups': groups,
                'runs': runs}

    def room_nodes(self, arguments: list) -> dict:
        """A stand-in sensor and monitor, each started with ``arguments`` (as ``--ros-args``)."""
        rt = self._runtime()
        made = []
        try:
            for name, kind in (('temperature_sensor', 'publisher'),
                               ('temperature_monitor', 'subscription')):
                node = Node(name, cli_args=[str(a) for a in arguments],
                            use_global_arguments=False, start_parameter_services=False)
                if kind == 'publisher':
                    node.create_publisher(Float32, 'temperature', 10)
                else:
                    node.create_subscription(Float32, 'temperature', lambda msg: None, 10)
                made.append(node)
        except BaseException as error:
            for node in made:
                node.destroy_node()
            return {'ok': False, 'error': describe_error(error)}
        self.rooms.extend(made)
        return {'ok': True, 'nodes': [[n.get_name(), n.get_namespace(), node_endpoints(n)]
                                      for n in made]}

    def advance(self, seconds: float, seed: Optional[int] = None) -> dict:
        if seed is not None:
            random.seed(seed)
        self._runtime().advance_sim_time(seconds)
        return {'ok': True, **self._counts()}

    def wait_received(self, count: int, seconds: float) -> dict:
        """Run callbacks until the node's subscriptions took ``count`` messages (or time is up)."""
        rt = self._runtime()
        deadline = time.monotonic() + seconds
        while self.received < count and time.monotonic() < deadline:
            with rt.exclusive():
                rt.drain()
            time.sleep(0.002)
        with rt.exclusive():
            rt.drain()
        return {'ok': self.received >= count, **self._counts()}


def serve(commands: Any, replies: Any) -> None:
    """Answer one JSON reply per JSON command until ``quit`` or end of input."""
    subject = Subject()
    handlers: dict[str, Callable[..., dict]] = {
        'exec_cells': subject.exec_cells, 'load_file': subject.load_file,
        'call': subject.call, 'new_node': subject.new_node,
        'set_attribute': subject.set_attribute, 'wait_matched': subject.wait_matched,
        'advance': subject.advance, 'wait_received': subject.wait_received,
        'counts': subject.counts, 'serve': subject.serve, 'attribute': subject.attribute,
        'timer_runs': subject.timer_runs, 'room_nodes': subject.room_nodes,
        'wait_publishers': subject.wait_publishers,
        'keep_stopped_nodes': subject.keep_stopped_nodes,
        'lines_logged': subject.lines_logged,
    }
    for line in commands:
        request = json.loads(line)
        op = request.pop('op')
        if op == 'quit':
            break
        try:
            reply = handlers[op](**request)
        except BaseException as error:  # a learner's callback may raise anything, also here
            reply = {'ok': False, 'error': describe_error(error)}
        replies.write(json.dumps(reply) + '\n')
        replies.flush()
    if subject.rt is not None:
        subject.rt.shutdown()
