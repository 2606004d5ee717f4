"""What a subject process does for the judge: load the learner's code, run it, say what it did.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs one).

A check never runs the learner's code in its own process, and never believes this one.
The judge (:mod:`ros2nb.judge`) starts this process, sends it commands as JSON lines on
file descriptor IN and reads one JSON reply per command on OUT.  The first command loads
the learner's code (their file imported, or their answer cells run), before anything of the
command loop exists; then their nodes run here on the judge's clock (the runtime follows the
judge's ``/clock``, :mod:`ros2nb.subject.judge_time`), with the course's stand-ins in place of
the parts a check does not grade (their code sent by the judge,
:mod:`ros2nb.judge.stand_ins`).  The judge watches the nodes over ROS itself; a reply only
tells it how long to wait, or which mistake to name.
"""

from __future__ import annotations

import importlib.util
import json
import linecache
import os
import random
import signal
import sys
import time
import types
from pathlib import Path
from types import ModuleType
from typing import Any, Callable, Optional

from rclpy.node import Node

from .. import domains
from ..endpoints import node_endpoints
from ..errors import Ros2nbError
from ..patience import wait_for_work
from ..runtime import Runtime, enable_field_checks
from ..subject_interface import (COMMANDS, Call, Command, ExecCells, GetCounts, LoadFile,
                                 NewNode, Run, Serve, Serves, SetAttribute, StandIns,
                                 WaitMatched, WaitPublishers, WaitReceived, command_of, wire)
from ..explain.exceptions import describe_error
from ..subject_replies import (CallbackFailure, Called, CellsRun, Counts, Loaded, NodeMade,
                               Output, Reply)
from .judge_time import JudgeTime
from .replies import decode_argument, described, encode
from .seen import STAND_IN_FILE
from .trials import Trials

#: Exit code when a command could not even be read.
PROTOCOL_ERROR = 3
#: What the command loop compiles, runs and speaks with, bound when this module is imported,
#: before the learner's code is loaded: a ``compile``, ``exec`` or ``json`` the learner's
#: code replaces later (on ``builtins``, on the ``json`` module) changes nothing here.  They
#: keep no secret: what the stand-ins' code holds is the course's version of a part this
#: subject does not grade, and nothing this process writes reaches another (its own folder).
_COMPILE, _EXEC, _LOADS, _DUMPS = compile, exec, json.loads, json.dumps
#: Longest wait for a message in one round of :meth:`Subject.wait_received` (s): a message
#: ends the wait at once.
RECEIVE_WAIT_S = 0.05


def _waited(condition: Callable[[], bool], seconds: float) -> bool:
    """Whether ``condition()`` came true before this process had ``seconds`` of work or idle
    waiting for it (:func:`ros2nb.patience.wait_for_work`, its own threads watched): a
    subject the machine starves, or that waits for a judge the machine starves, waits on."""
    return wait_for_work(condition, [os.getpid()], seconds)


def _without_magics(source: str) -> str:
    """Cell source with IPython line magics and shell escapes commented out."""
    if source.lstrip().startswith('%%'):
        return ''
    return '\n'.join('# ' + line if line.lstrip().startswith(('%', '!')) else line
                     for line in source.splitlines())


def _named(function: Callable[..., Any], name: str, qualname: str) -> Callable[..., Any]:
    """A copy of a stand-in ``function`` named as the method it stands in for (``qualname``
    in a report): an error is reported as the course's method of the learner's class, never
    as a function of ours."""
    named = types.FunctionType(function.__code__, function.__globals__, name,
                               function.__defaults__, function.__closure__)
    named.__qualname__ = qualname
    return named


# ------------------------------------------------------------------ loading (first command)
def load(command: Command[Any]) -> tuple[dict[str, Any], Reply]:
    """Run the first command (:data:`~ros2nb.subject_interface.LOADERS`), which loads the
    learner's code; return (namespace, reply).

    Called before the command loop exists: code of the learner's that looks up the stack
    while it is imported finds this function's frame, the process's ``main()`` and what
    started the process (``runpy``, or the fork server's, :mod:`.fork_server`), never the loop.
    """
    namespace: dict[str, Any] = {'__name__': '__main__'}
    if isinstance(command, LoadFile):
        file = Path(command.path)
        if not file.is_file():
            return namespace, Loaded(ok=False, missing=True)
        spec = importlib.util.spec_from_file_location(command.module, file)
        assert spec is not None and spec.loader is not None
        loaded: ModuleType = importlib.util.module_from_spec(spec)
        sys.modules[command.module] = loaded
        try:
            spec.loader.exec_module(loaded)
        except BaseException as error:  # the learner's import may raise anything
            return namespace, Loaded(ok=False, error=described(error))
        namespace.update(vars(loaded))
        return namespace, Loaded(ok=True)
    assert isinstance(command, ExecCells)  # the only other loader
    errors = []
    for index, source in enumerate(command.sources):
        text, name = _without_magics(source), f'<cell {index + 1}>'
        # its lines for tracebacks and explanations, as a kernel keeps a cell's
        linecache.cache[name] = (len(text), None, text.splitlines(keepends=True), name)
        try:
            _EXEC(_COMPILE(text, name, 'exec'), namespace)
        except BaseException as error:  # the learner's cell may raise anything
            errors.append(described(error))
    return namespace, CellsRun(ok=True, cell_errors=errors)


class Subject(Trials):
    """The state of this process: the learner's namespace, their node, the runtime."""

    def __init__(self, namespace: dict[str, Any]) -> None:
        self.namespace = namespace
        self._stand_ins: dict[str, tuple[str, Any]] = {}  # name -> (method, function)
        self.rt: Optional[Runtime] = None
        self.node: Optional[Node] = None
        self.received = 0
        self.failure: Optional[CallbackFailure] = None
        self.rooms: list[Node] = []  # stand-in nodes of the reusability check (notebook 06)
        self._spun = None
        self._qos = None

    # ---------------------------------------------------------------- calls
    def call(self, command: Call) -> Called:
        """Call the learner's function once per list of arguments."""
        function = self.namespace.get(command.name)
        if function is None:
            return Called(ok=False, undefined=True)
        outputs = []
        for arguments in command.inputs:
            try:
                outputs.append(Output(result=encode(function(*map(decode_argument, arguments)))))
            except BaseException as error:
                outputs.append(Output(error=described(error)))
        return Called(ok=True, outputs=outputs)

    def stand_ins(self, command: StandIns) -> Reply:
        """Compile the stand-ins the judge sent (:func:`ros2nb.judge.stand_ins.source_of`),
        once the learner's code is loaded: kept here, on no module and under no name that
        code imports."""
        made: dict[str, Any] = {'__name__': 'ros2nb stand-ins'}
        _EXEC(_COMPILE(command.source, STAND_IN_FILE, 'exec'), made)  # the judge's code
        self._stand_ins = dict(made['STAND_INS'])
        return Reply(ok=True)

    # ---------------------------------------------------------------- nodes
    def _runtime(self) -> Runtime:
        if self.rt is None:
            enable_field_checks()
            self.rt = Runtime(domain_id=domains.domain_id(), sim_time=True, background=False)
            self.rt.on_failure = self._on_failure
        return self.rt

    def _on_failure(self, node: str, callback: str, error: BaseException) -> None:
        if self.failure is None:
            self.failure = CallbackFailure(node=node, callback=callback,
                                           **describe_error(error))

    def _count_receipts(self, subscription: Any) -> None:
        original = subscription.callback

        def counted(msg: Any) -> Any:
            self.received += 1
            return original(msg)

        counted.__qualname__ = getattr(original, '__qualname__', 'callback')
        subscription.callback = counted

    def new_node(self, command: NewNode) -> NodeMade:
        """Create ``cls(*args)`` with the named stand-ins (:meth:`stand_ins`) and run it on the
        judge's clock; stop the node made before."""
        cls, stand_ins, seed, args = command.cls, command.stand_ins, command.seed, command.args
        rt = self._runtime()
        if self.node is not None:
            if self.node.get_fully_qualified_name() in rt.nodes:
                rt.stop(self.node)
            self.node = None
        node_class = self.namespace.get(cls)
        if not isinstance(node_class, type) or not issubclass(node_class, Node):
            found = sorted(n for n, v in self.namespace.items()
                           if isinstance(v, type) and issubclass(v, Node) and v is not Node)
            return NodeMade(ok=False, no_class=True, classes=found)
        if stand_ins:  # a subclass with the course's parts in place of the learner's
            methods = {method: _named(function, method,
                                      f"the course's {node_class.__name__}.{method}")
                       for method, function in (self._stand_ins[name] for name in stand_ins)}
            node_class = type(node_class.__name__, (node_class,), methods)
        rt.take_judge_time()
        if seed is not None:
            random.seed(seed)
        self.received, self.failure = 0, None
        logged_before = JudgeTime.logged()
        try:
            node = node_class(*(args or []))
        except BaseException as error:
            return NodeMade(ok=False, error=described(error))
        try:
            rt.add(node)
        except Ros2nbError as error:
            return NodeMade(ok=False, refused=str(error))
        self.node = node
        for subscription in node.subscriptions:
            self._count_receipts(subscription)
        logger = node.get_logger().name
        return NodeMade(ok=True, name=node.get_name(), namespace=node.get_namespace(),
                        started_lines=(JudgeTime.logged().get(logger, 0)
                                       - logged_before.get(logger, 0)),
                        endpoints=node_endpoints(node), **self._counts(),
                        # names a failure, never earns a point (``ros2 param`` reaches it or not)
                        parameter_services=any(service.srv_name.endswith('/set_parameters')
                                               for service in node.services))

    def _counts(self) -> dict[str, Any]:
        """The fields of :class:`~ros2nb.subject_replies.Counts` now (but ``ok``)."""
        logged = JudgeTime.logged().get(self.node.get_logger().name, 0) if self.node else 0
        shown = self._plot_shown.told if self._plot_shown is not None else None
        return {'received': self.received, 'logged': logged, 'failure': self.failure,
                'published': JudgeTime.published(), 'shown': shown}

    def counts(self, command: GetCounts) -> Counts:
        """What this process counted so far."""
        return Counts(ok=True, **self._counts())

    def run(self, command: Run) -> Counts:
        """Let the nodes run ``seconds`` of the judge's clock (the judge moves it on)."""
        if command.seed is not None:
            random.seed(command.seed)
        self._runtime().advance_sim_time(command.seconds)
        return Counts(ok=True, **self._counts())

    def set_attribute(self, command: SetAttribute) -> Reply:
        """Set an attribute of the node made last."""
        if self.node is None:
            return Reply(ok=False)
        setattr(self.node, command.name, command.value)
        return Reply(ok=True)

    def wait_matched(self, command: WaitMatched) -> Reply:
        """Wait until the node's publishers on ``topic`` reach a subscription (the judge's)."""
        node = self.node
        publishers = [p for p in node.publishers
                      if node.resolve_topic_name(p.topic_name) == command.topic] if node else []
        return Reply(ok=bool(publishers) and _waited(
            lambda: all(p.get_subscription_count() >= 1 for p in publishers), command.seconds))

    def wait_publishers(self, command: WaitPublishers) -> Reply:
        """Wait until the node's subscriptions on ``topic`` have matched a publisher (the
        judge's).  Their own match, not the graph's list: in a subject that made a node
        before, the graph already lists the judge's publisher while the new subscription
        has not matched it yet, and a reading sent then was lost."""
        node = self.node
        subscriptions = [s for s in node.subscriptions
                         if node.resolve_topic_name(s.topic_name) == command.topic] if node else []
        return Reply(ok=bool(subscriptions) and _waited(  # none: nothing can match
            lambda: all(s.get_publisher_count() >= 1 for s in subscriptions), command.seconds))

    def wait_received(self, command: WaitReceived) -> Counts:
        """Run callbacks until the node's subscriptions took ``count`` messages (or this
        process sat idle ``seconds`` waiting for them)."""
        rt, count = self._runtime(), command.count

        def drained(condition: Callable[[], bool], seconds: float) -> bool:
            deadline = time.monotonic() + seconds
            while not condition():
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                with rt.exclusive():
                    rt._run_one(min(left, RECEIVE_WAIT_S))  # wakes when a message comes
                    rt.drain()
            return True

        wait_for_work(lambda: self.received >= count, [os.getpid()], command.seconds,
                      look=drained)
        with rt.exclusive():
            rt.drain()
        return Counts(ok=self.received >= count, **self._counts())

    def serve(self, command: Serve) -> Counts:
        """Spin the node in the background from now on: it answers service calls (its
        parameters) whenever the judge makes them."""
        self._runtime().spin_in_background()
        return Counts(ok=True, **self._counts())


class Ended(BaseException):
    """SIGTERM came: the judge ends this subject (``processes.kill_process_group``)."""


#: Set on SIGTERM: a command whose ``except BaseException`` caught :class:`Ended` (the
#: learner's code was running) still ends the subject once it returns.
_ending = False


def _on_sigterm(signum: int, _frame: Any) -> None:
    global _ending
    _ending = True
    signal.signal(signum, signal.SIG_DFL)  # a second SIGTERM ends the process at once
    raise Ended


def serve(commands: Any, replies: Any, namespace: dict[str, Any],
          noted: Callable[[], None] = lambda: None) -> None:
    """Answer one JSON reply per JSON command until ``quit`` or end of input; then, or on
    SIGTERM, take the runtime's nodes down, so that the process's DDS participant tells the
    judge it leaves.

    Ended by SIGTERM's default action (the runtime leaves signals to the process), a
    subject's participant vanished without a word: the judge kept it, its endpoints
    matched, until its lease ran out (20 s), and its ``/clock`` reached the next subjects
    late, once for over 30 s of their patience beside CPU burners (docs/decisions.md).  A
    learner's code that swallows the signal (a bare ``except``) is ended by the SIGKILL that
    follows, as before.

    :param noted: writes the audit hook's last line, every kind's count (:func:`.seen.install`),
        once the loop is done: a subject that ends without it had its channel cut.
    """
    subject = Subject(namespace)
    served: Serves = subject  # the type checker holds every command's method to its types
    handlers: dict[str, Callable[[Any], Reply]] = {op: getattr(served, op) for op in COMMANDS}
    ended = False
    signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        try:
            for line in commands:
                request = _LOADS(line)
                if request.get('op') == 'quit':
                    break
                try:
                    command = command_of(request, COMMANDS)
                    reply = handlers[command.op](command)
                except Ended:
                    raise
                except BaseException as error:  # a learner's callback may raise anything
                    reply = Reply(ok=False, error=described(error))
                if _ending:
                    raise Ended
                replies.write(_DUMPS(wire(reply)) + '\n')
                replies.flush()
        finally:
            signal.signal(signal.SIGTERM, signal.SIG_DFL)  # from here on, SIGTERM ends at once
    except Ended:  # raised where the main thread was: what it held (rclpy's wait) let go
        ended = True
    noted()
    if subject.rt is not None:
        subject.rt.shutdown()
    if ended:
        os.kill(os.getpid(), signal.SIGTERM)  # ended by the signal, as the judge asked
