"""The judge: decides whether the learner's code does what a check asks, from outside it.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs here).

The judge is a process of its own, started for a check cell by the kernel, and once per
notebook by the grader.  It never imports or executes the learner's code itself: that
runs in subject processes (:mod:`ros2nb.subject`), which the judge watches over ROS with a
node of its own (the graph, ``/temperature``, ``/rosout``) and asks for raw facts only.
The verdict is computed here, so nothing a notebook does to its own kernel (replacing the
checks, hooks, exceptions) changes it.  While grading, every subject also runs in a
sandbox of its own (the grader passes the sandbox command in ``ROS2NB_SUBJECT_PREFIX``)
and cannot see, signal or trace the judge.

Command line (``python -m ros2nb.judge``):

- ``check NAME KWARGS_JSON``: run ``ros2nb.checks.NAME(**kwargs)``; print one JSON line.
- ``grade SOURCE.ipynb SUBMISSION.ipynb``: run every graded cell of the course's source
  notebook (hidden tests included) against the learner's submission and workspace; print
  one JSON object, ``{grade_id: result}``.

Both take the learner's workspace from ``ROS2NB_WORKSPACE``.
"""

from __future__ import annotations

import ast
import contextlib
import io
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Optional

from . import course, domains
from .errors import CheckFailed, LearnerCodeError, Ros2nbError
from .processes import kill_process_group, stop_process_group

#: Set in the judge process: checks then run here instead of starting a judge.
IN_JUDGE_ENV = 'ROS2NB_JUDGE'
#: JSON list put in front of every subject's command (the grader's sandbox).
SUBJECT_PREFIX_ENV = 'ROS2NB_SUBJECT_PREFIX'
#: Seconds a subject may take to answer one command before it counts as hanging.
REPLY_TIMEOUT_S = 30.0
#: Seconds the judge waits for what a subject published to arrive over ROS, and for ROS
#: discovery to show a subject's node; the wait ends as soon as it is there, so a long
#: limit costs time only on a busy machine or when the thing never comes.  Generous: the
#: learner's verdict must not depend on how busy the machine is.
ARRIVAL_TIMEOUT_S = 60.0
#: Seconds one check may take in all when the kernel runs it.
CHECK_TIMEOUT_S = 300.0
#: Lines of a subject's own output kept for hints.
KEPT_OUTPUT_LINES = 200
#: Tag of the course's cells a graded answer may rely on (imports, constants).
CONTEXT_TAG = 'grading-context'


def in_judge() -> bool:
    """True in the judge process."""
    return os.environ.get(IN_JUDGE_ENV) == '1'


@dataclass(frozen=True)
class AnswerRef:
    """A name the learner defined in their answer cells, as the judge knows it: by source.

    :ivar name: e.g. ``'LoudListener'``.
    :ivar sources: the course's context cells, then the learner's answer cells, in order.
    """

    name: str
    sources: tuple[str, ...]

    @property
    def __name__(self) -> str:  # messages name it like the function or class itself
        return self.name


# ------------------------------------------------------------------ observer
class Observer:
    """The judge's own ROS node on the judge's domain: graph, readings, logs, probes."""

    def __init__(self) -> None:
        import rclpy
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from rclpy.signals import SignalHandlerOptions
        self.domain_id = domains.domain_id()
        self.context = rclpy.Context()
        rclpy.init(context=self.context, domain_id=self.domain_id,
                   signal_handler_options=SignalHandlerOptions.NO)
        self.node = Node('_ros2nb_judge', context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.changed = threading.Condition()
        self.readings: list[float] = []
        self.logs: list[tuple[str, int, str]] = []
        self._watching: set[str] = set()
        self._stop = False
        self._thread = threading.Thread(target=self._spin, name='ros2nb-judge', daemon=True)
        self._thread.start()
        self.watch_logs()

    def _spin(self) -> None:
        while not self._stop:
            with contextlib.suppress(Exception):
                self.executor.spin_once(timeout_sec=0.05)

    def _note(self, store: list, item: Any) -> None:
        with self.changed:
            store.append(item)
            self.changed.notify_all()

    def watch_logs(self) -> None:
        """Collect every /rosout line (as ``ros2 topic echo /rosout`` would see it)."""
        from rcl_interfaces.msg import Log
        from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
        qos = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                         durability=DurabilityPolicy.TRANSIENT_LOCAL)
        self.node.create_subscription(Log, '/rosout',
                                      lambda m: self._note(self.logs, (m.name, m.level, m.msg)),
                                      qos)

    def watch_readings(self, topic: str) -> None:
        """Collect every Float32 on ``topic``, reliably (a long queue, nothing dropped)."""
        if topic in self._watching:
            return
        from rclpy.qos import QoSProfile, ReliabilityPolicy
        from std_msgs.msg import Float32
        self._watching.add(topic)
        self.node.create_subscription(
            Float32, topic, lambda m: self._note(self.readings, float(m.data)),
            QoSProfile(depth=10000, reliability=ReliabilityPolicy.RELIABLE))

    def wait_until(self, condition: Callable[[], bool], seconds: float) -> bool:
        """Wait until ``condition()`` holds (checked whenever something arrives)."""
        deadline = time.monotonic() + seconds
        with self.changed:
            while not condition():
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self.changed.wait(min(left, 0.05))
        return True

    def lines_of(self, logger: str, start: int = 0) -> list[str]:
        """Log lines of one logger received so far, from position ``start`` on."""
        with self.changed:
            return [text for name, _level, text in self.logs[start:] if name == logger]

    def endpoints(self, name: str, namespace: str, expected: list[list[str]],
                  seconds: float = ARRIVAL_TIMEOUT_S) -> list[tuple[str, str, str]]:
        """The node's publishers and subscriptions as the ROS graph shows them.

        Waits until the graph holds at least ``expected`` (what the subject said it made)
        or ``seconds`` pass.
        """
        want = {tuple(e) for e in expected}
        deadline = time.monotonic() + seconds
        found: set[tuple[str, str, str]] = set()
        while True:
            try:
                pubs = self.node.get_publisher_names_and_types_by_node(name, namespace)
                subs = self.node.get_subscriber_names_and_types_by_node(name, namespace)
                found = {('publisher', t, ty) for t, types in pubs for ty in types} | \
                        {('subscription', t, ty) for t, types in subs for ty in types}
            except Exception:  # the node is not discovered yet
                found = set()
            if want <= found:
                return sorted(e for e in found if e[1] not in ('/rosout', '/parameter_events',
                                                                '/clock'))
            if time.monotonic() > deadline:  # not the learner's mistake: say what happened
                missing = ', '.join(f'{kind} on {topic}' for kind, topic, _ in sorted(want - found))
                raise CheckFailed(f'The grader could not see the {missing} of {name} in the ROS '
                                  f'graph within {seconds:g} s (is the machine very busy?): run '
                                  'this check again.')
            time.sleep(0.02)

    def spins(self, name: str, namespace: str = '/', seconds: float = ARRIVAL_TIMEOUT_S) -> bool:
        """True once the node ``name`` answers a call of its ``list_parameters`` service.

        Every rclpy node serves its parameters while it spins, and only then: an answer
        proves that the process got past creating the node and into its spin.  False when no
        answer came in ``seconds`` (or the node serves no parameters).
        """
        from rcl_interfaces.srv import ListParameters
        service = f'{namespace.rstrip("/")}/{name}/list_parameters'
        client = self.node.create_client(ListParameters, service)
        try:
            deadline = time.monotonic() + seconds
            while time.monotonic() < deadline:
                # Ask again now and then: a request goes only to the servers discovered
                # when it is sent (a node of that name that just ended may be one of them).
                if client.wait_for_service(timeout_sec=0.1):
                    answer = client.call_async(ListParameters.Request())
                    if self.wait_until(answer.done, min(1.0, max(0.0, deadline - time.monotonic()))):
                        return True
            return False
        finally:
            self.node.destroy_client(client)

    def has_node(self, name: str) -> bool:
        return any(n == name for n, _ns in self.node.get_node_names_and_namespaces())

    def close(self) -> None:
        import rclpy
        self._stop = True
        self._thread.join()
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)


# ------------------------------------------------------------------ subjects
def subject_prefix() -> list[str]:
    """The sandbox command every subject runs under (empty outside grading)."""
    value = os.environ.get(SUBJECT_PREFIX_ENV)
    return json.loads(value) if value else []


def subject_env(extra: Optional[dict[str, str]] = None) -> dict[str, str]:
    """The environment of a subject: the judge's domain, field checks on, plain logs."""
    env = {k: v for k, v in os.environ.items() if k not in (IN_JUDGE_ENV, SUBJECT_PREFIX_ENV)}
    env.update({'ROS_DOMAIN_ID': str(domains.domain_id()), 'PYTHONUNBUFFERED': '1',
                'ROS_PYTHON_CHECK_FIELDS': '1', 'RCUTILS_COLORIZED_OUTPUT': '0',
                'RCUTILS_CONSOLE_OUTPUT_FORMAT': '[{severity}] [{name}]: {message}'})
    env.update(extra or {})  # discovery range and transports: the judge's own
    return env


class _Output:
    """The last lines a process printed, read in a thread of their own."""

    def __init__(self, stream: Any) -> None:
        self.lines: list[str] = []
        self._thread = threading.Thread(target=self._read, args=(stream,), daemon=True)
        self._thread.start()

    def _read(self, stream: Any) -> None:
        for line in stream:
            self.lines.append(line.rstrip('\n'))
            del self.lines[:-KEPT_OUTPUT_LINES]

    def text(self) -> str:
        self._thread.join(0.5)
        return '\n'.join(self.lines)


class SubjectHung(CheckFailed):
    """The learner's code did not answer in time."""


class SubjectProcess:
    """A running ``ros2nb.subject``: one JSON command, one JSON reply."""

    def __init__(self, workspace: Path) -> None:
        to_subject, self._commands = os.pipe()
        self._replies, from_subject = os.pipe()
        argv = [*subject_prefix(), sys.executable, '-m', 'ros2nb.subject',
                str(to_subject), str(from_subject)]
        self.proc = subprocess.Popen(argv, cwd=workspace, env=subject_env(), text=True,
                                     stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, start_new_session=True,
                                     pass_fds=(to_subject, from_subject))
        os.close(to_subject)
        os.close(from_subject)
        self.output = _Output(self.proc.stdout)
        self._buffer = b''

    def request(self, op: str, *, timeout: float = REPLY_TIMEOUT_S, **arguments: Any) -> dict:
        """Send one command and return its reply.

        :raises SubjectHung: when no reply comes within ``timeout`` seconds, or the
            process died (its last output line is in the message).
        """
        try:
            os.write(self._commands, (json.dumps({'op': op, **arguments}) + '\n').encode())
        except BrokenPipeError:
            raise self._died() from None
        deadline = time.monotonic() + timeout
        while b'\n' not in self._buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                kill_process_group(self.proc)
                raise SubjectHung(f'Your code did not finish within {timeout:g} s (an endless '
                                  'loop, or a call that waits for ever?): look for a loop that '
                                  'never ends in the part you wrote.')
            ready, _, _ = select.select([self._replies], [], [], min(left, 0.5))
            if ready:
                chunk = os.read(self._replies, 65536)
                if not chunk:
                    raise self._died()
                self._buffer += chunk
        line, self._buffer = self._buffer.split(b'\n', 1)
        return json.loads(line)

    def _died(self) -> CheckFailed:
        code = self.proc.wait(5)
        last = [line for line in self.output.text().splitlines() if line.strip()][-1:]
        return CheckFailed(f'The process running your code ended (exit code {code})'
                           + (f': {last[0].strip()}' if last else '') +
                           ' (does your code call exit() or kill its own process?).')

    def close(self) -> None:
        with contextlib.suppress(OSError):
            os.write(self._commands, b'{"op": "quit"}\n')
        with contextlib.suppress(OSError):
            os.close(self._commands)
        try:
            self.proc.wait(5)
        except subprocess.TimeoutExpired:
            pass
        stop_process_group(self.proc)
        with contextlib.suppress(OSError):
            os.close(self._replies)


def learner_error(what: str, error: dict, *, context: str = '') -> CheckFailed:
    """The CheckFailed for an exception the learner's code raised in a subject.

    A gap left unwritten says which one; a known mistake gets its one line; anything else
    shows the learner's own traceback (their frames only).

    :param what: whose code raised, e.g. ``TemperatureSensor.publish_temperature``.
    :param error: the subject's description of the exception.
    :param context: what it was doing, e.g. `` for 19.99 °C``.
    """
    if error.get('type') == 'NotImplementedError':
        return CheckFailed(f'{what} still raises NotImplementedError{context}: write your code '
                           'where it says YOUR CODE HERE and run that cell again.')
    if error.get('explanation'):
        where = error.get('where')
        return CheckFailed(f'{what} raised{context}: {error["explanation"]}'
                           + (f' ({where})' if where else ''))
    return LearnerCodeError(f'{what} raised{context}: {error["type"]}: {error["message"]}',
                            error.get('traceback', []))


# ------------------------------------------------------------------ session
class Session:
    """Everything one judge process shares between checks: observer, subjects, builds."""

    def __init__(self, workspace: Path) -> None:
        self.workspace = workspace
        self.scratch = Path(tempfile.mkdtemp(prefix='ros2nb-judge-'))
        self._observer: Optional[Observer] = None
        self._subjects: dict[tuple, SubjectProcess] = {}
        self._probe: Any = None
        self.builds: dict[str, Any] = {}

    @property
    def observer(self) -> Observer:
        if self._observer is None:
            self._observer = Observer()
        return self._observer

    @property
    def probe_publisher(self) -> Any:
        """The judge's own Float32 publisher on /temperature (it plays the sensor)."""
        if self._probe is None:
            from rclpy.qos import QoSProfile, ReliabilityPolicy
            from std_msgs.msg import Float32
            self._probe = self.observer.node.create_publisher(
                Float32, '/' + course.TOPIC,
                QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE))
        return self._probe

    def subject(self, key: tuple, load: Callable[[SubjectProcess], None]) -> SubjectProcess:
        """A subject for ``key``, started and loaded once per session."""
        subject = self._subjects.get(key)
        if subject is None or subject.proc.poll() is not None:
            subject = SubjectProcess(self.workspace)
            self._subjects[key] = subject
            try:
                load(subject)
            except BaseException:
                self.drop(key)
                raise
        return subject

    def drop(self, key: tuple) -> None:
        subject = self._subjects.pop(key, None)
        if subject is not None:
            subject.close()

    def file_subject(self, relative: str) -> SubjectProcess:
        """A subject with the learner's file imported (``relative`` to the workspace)."""
        path = self.workspace / relative

        def load(subject: SubjectProcess) -> None:
            reply = subject.request('load_file', path=str(path), module=path.stem)
            if reply.get('missing'):
                raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that '
                                  'write it, from part 1 on.')
            if not reply['ok']:
                raise learner_error(path.name, reply['error'], context=' on import')

        return self.subject(('file', relative), load)

    def answer_subject(self, ref: AnswerRef) -> SubjectProcess:
        """A subject with the course's context cells and the learner's answer cells run."""
        def load(subject: SubjectProcess) -> None:
            subject.request('exec_cells', sources=list(ref.sources))

        return self.subject(('cells', ref.sources), load)

    def start(self, argv: list[str], *, cwd: Path,
              env: Optional[dict[str, str]] = None) -> tuple[subprocess.Popen, '_Output']:
        """Start a program of the learner's (sandboxed while grading) in a session of its own.

        :return: the process, and its output (stdout and stderr), collected as it comes.
        """
        proc = subprocess.Popen([*subject_prefix(), *argv], cwd=cwd, env=env or subject_env(),
                                text=True, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                                stderr=subprocess.STDOUT, start_new_session=True)
        return proc, _Output(proc.stdout)

    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None) -> tuple[int, str]:
        """Run a program of the learner's (sandboxed while grading); return code and output."""
        proc, output = self.start(argv, cwd=cwd, env=env)
        try:
            code = proc.wait(seconds)
        except subprocess.TimeoutExpired:
            code = kill_process_group(proc)
            raise SubjectHung(f'{Path(argv[-1]).name} did not finish within {seconds:g} s.') \
                from None
        return code, output.text()

    def close(self) -> None:
        for key in list(self._subjects):
            self.drop(key)
        if self._observer is not None:
            self._observer.close()
        shutil.rmtree(self.scratch, ignore_errors=True)


_session: Optional[Session] = None


def session() -> Session:
    """The judge process's session (the checks call this when they run in the judge)."""
    global _session
    if _session is None:
        from .workspace import default_workspace
        _session = Session(default_workspace())
    return _session


# ------------------------------------------------------------------ from the kernel
def run_in_judge(check: str, arguments: dict[str, Any]) -> None:
    """Run ``ros2nb.checks.<check>(**arguments)`` in a judge process; print or raise its result.

    Called by the checks in a notebook.  The judge gets a ROS domain of its own (never the
    kernel's, where the learner's nodes may be running) and the kernel's workspace.

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    """
    from .workspace import current_workspace
    env = {k: v for k, v in os.environ.items() if k != domains.DOMAIN_ENV}
    env.update({IN_JUDGE_ENV: '1', 'ROS2NB_WORKSPACE': str(current_workspace()),
                'PYTHONUNBUFFERED': '1'})
    proc = subprocess.Popen([sys.executable, '-m', 'ros2nb.judge', 'check', check,
                             json.dumps(arguments)], env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        out, err = proc.communicate(timeout=CHECK_TIMEOUT_S)
    except KeyboardInterrupt:
        kill_process_group(proc)
        raise CheckFailed('Check interrupted: run the cell again to check.') from None
    except subprocess.TimeoutExpired:
        kill_process_group(proc)
        raise CheckFailed(f'The check did not finish within {CHECK_TIMEOUT_S:g} s: does your '
                          'code wait for something that never happens?') from None
    lines = out.strip().splitlines()
    try:
        result = json.loads(lines[-1])
    except (IndexError, json.JSONDecodeError):
        raise Ros2nbError(f'The check could not run (exit code {proc.returncode}): '
                          f'{(err.strip().splitlines() or ["no output"])[-1]}') from None
    show_result(result)


def show_result(result: dict) -> None:
    """Print a passed result's lines, or raise the failure it describes."""
    if result['passed']:
        print('\n'.join(result['lines']))
        return
    if result['type'] == 'LearnerCodeError':
        raise LearnerCodeError(result['message'], result['traceback'])
    raise CheckFailed(result['message'])


# ------------------------------------------------------------------ in the judge
def _captured(call: Callable[[], Any]) -> dict:
    """Run one check; return its result as JSON-safe data."""
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            call()
    except LearnerCodeError as error:
        return {'passed': False, 'type': 'LearnerCodeError', 'message': str(error),
                'traceback': error.traceback_lines, 'lines': out.getvalue().splitlines()}
    except CheckFailed as error:
        return {'passed': False, 'type': 'CheckFailed', 'message': str(error),
                'lines': out.getvalue().splitlines()}
    except Ros2nbError as error:
        return {'passed': False, 'type': 'CheckFailed', 'message': str(error),
                'lines': out.getvalue().splitlines()}
    return {'passed': True, 'lines': out.getvalue().splitlines()}


def _is_check_call(node: ast.AST) -> Optional[str]:
    """``ros2nb.checks.NAME(...)`` -> NAME, else None."""
    if not (isinstance(node, ast.Expr) and isinstance(node.value, ast.Call)):
        return None
    func = node.value.func
    if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Attribute)
            and isinstance(func.value.value, ast.Name) and func.value.value.id == 'ros2nb'
            and func.value.attr == 'checks'):
        return func.attr
    return None


def _value(node: ast.expr, names: dict[str, Any]) -> Any:
    if isinstance(node, ast.Name):
        if node.id not in names:
            return AnswerRef(node.id, ())  # not defined in any answer cell
        return names[node.id]
    return ast.literal_eval(node)


def graded_calls(source: str) -> list[tuple[str, list[ast.expr], list[ast.keyword]]]:
    """The ``ros2nb.checks`` calls of a graded cell, the only statements the judge runs.

    :raises ValueError: for any other statement (a mistake in the course, not the learner's).
    """
    lines = [line for line in source.splitlines() if not line.lstrip().startswith('###')]
    calls = []
    for statement in ast.parse('\n'.join(lines)).body:
        name = _is_check_call(statement)
        if name is None:
            raise ValueError(f'a graded cell may only call ros2nb.checks functions: '
                             f'{ast.unparse(statement)[:80]}')
        call = statement.value  # type: ignore[attr-defined]
        calls.append((name, call.args, call.keywords))
    return calls


def _defined_names(source: str) -> set[str]:
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return set()
    names = set()
    for statement in tree.body:
        if isinstance(statement, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
            names.add(statement.name)
        elif isinstance(statement, ast.Assign):
            names.update(t.id for t in statement.targets if isinstance(t, ast.Name))
    return names


def _cells(notebook: dict) -> list[dict]:
    return [c for c in notebook.get('cells', []) if isinstance(c, dict)]


def _text(cell: dict) -> str:
    source = cell.get('source', '')
    return source if isinstance(source, str) else ''.join(source)


def nbgrader_metadata(cell: dict) -> dict:
    """A notebook cell's nbgrader metadata (empty when it has none, or none that makes sense)."""
    meta = cell.get('metadata', {})
    value = meta.get('nbgrader', {}) if isinstance(meta, dict) else {}
    return value if isinstance(value, dict) else {}


def grade(source: dict, submission: dict) -> dict[str, dict]:
    """Run every graded cell of ``source`` (the course's notebook, hidden tests included).

    Names in a graded call (``LoudListener``) are the learner's: the judge passes an
    :class:`AnswerRef` with the course's context cells and every answer cell of the
    submission, and the check runs it in a subject.

    :param source: the course's source notebook (nbformat JSON).
    :param submission: the learner's notebook (nbformat JSON); only its answer cells
        (nbgrader ``solution: true``) are used.
    :return: ``{grade_id: result}`` with ``passed``, ``lines``, ``type``, ``message``.
    """
    from . import checks
    context = [_text(c) for c in _cells(source) if CONTEXT_TAG in
               c.get('metadata', {}).get('tags', [])]
    answers = [_text(c) for c in _cells(submission) if nbgrader_metadata(c).get('solution')
               and c.get('cell_type') == 'code']
    sources = tuple(context + answers)
    names = {name: AnswerRef(name, sources) for text in answers for name in _defined_names(text)}
    results = {}
    for cell in _cells(source):
        meta = nbgrader_metadata(cell)
        if not meta.get('grade') or cell.get('cell_type') != 'code':
            continue
        results[meta['grade_id']] = result = {'passed': True, 'lines': []}
        for name, args, keywords in graded_calls(_text(cell)):
            function = getattr(checks, name)
            values = [_value(a, names) for a in args]
            options = {k.arg: _value(k.value, names) for k in keywords}
            outcome = _captured(lambda: function(*values, **options))
            result['lines'] += outcome.pop('lines')
            if not outcome['passed']:
                result.update(outcome)
                break
    return results


def main(argv: list[str]) -> int:
    """``python -m ros2nb.judge check NAME KWARGS_JSON`` or ``grade SOURCE SUBMISSION``."""
    os.environ[IN_JUDGE_ENV] = '1'
    try:
        if len(argv) == 3 and argv[0] == 'check':
            from . import checks
            function = getattr(checks, argv[1])
            result: Any = _captured(lambda: function(**json.loads(argv[2])))
        elif len(argv) == 3 and argv[0] == 'grade':
            source, submission = (json.loads(Path(p).read_text()) for p in argv[1:])
            result = grade(source, submission)
        else:
            print('Usage: python -m ros2nb.judge check NAME KWARGS_JSON | grade SOURCE '
                  'SUBMISSION', file=sys.stderr)
            return 2
    finally:
        if _session is not None:
            _session.close()
    print(json.dumps(result))
    return 0


if __name__ == '__main__':
    from ros2nb import judge as _judge  # the module the checks use, not this __main__ copy
    sys.exit(_judge.main(sys.argv[1:]))
