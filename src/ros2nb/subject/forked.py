"""Subjects and programs forked from a process that has imported ROS, not started afresh.

Part of the subjects (:mod:`ros2nb.subject`); the judge (:mod:`ros2nb.judge`) starts its
subjects and the learner's programs here when it runs them without a sandbox command.

A subject spends most of its CPU time starting: Python, ``rclpy`` (with PyYAML and the
message types) and ``ros2nb`` take most of a short subject's CPU time to import and start
(docs/decisions.md), and ``make test`` starts hundreds.  A fork server
(:mod:`ros2nb.subject.fork_server`) holds those imports and forks each child from there:
the child is then the process ``python -P -m ros2nb.subject`` (or ``python -P -m
ros2nb.subject.program``) would be (its own session, working folder, environment,
``sys.path`` and output pipe), without the imports.

A judge process (``python -m ros2nb.judge``, what a check in the learner's kernel starts)
forks its server from itself first thing (:func:`serve_from_here`), before ROS or any
thread starts: a few milliseconds, so even a check's one subject is forked.  Elsewhere
(a test process that judges, a script) the server is started afresh with the first forked
child (``python -m ros2nb.subject.fork_server``), which repays itself from the second on.
The server answers on a socket of its parent's only and ends when its parent does.

While grading, each subject and program runs in a sandbox of its own (the judge's
``ROS2NB_SUBJECT_PREFIX``), which a fork cannot enter: the judge starts those afresh.
"""

from __future__ import annotations

import dataclasses
import errno
import functools
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from typing import IO, Optional, Sequence

from ..processes import die_with_parent
from ..typed_json import decoded
from . import fork_server
from .fork_server import ForkRequest
from .out_of_reach import answers_loaded

#: JSON list put in front of every subject's command while grading (the grader's sandbox):
#: a sandboxed subject is started afresh, since a fork cannot enter a sandbox.
SUBJECT_PREFIX_ENV = 'ROS2NB_SUBJECT_PREFIX'
#: Seconds a forked child gets to become the leader of its own session.
SESSION_WAIT_S = 5.0
#: What :func:`_site_path` runs: a new Python prints its ``sys.path`` after the first entry,
#: as a :class:`SitePath` (its one field written by hand: the program imports nothing of ours).
SITE_PATH_PROGRAM = 'import json, sys\nprint(json.dumps({"entries": sys.path[1:]}))'


@dataclass(frozen=True)
class SitePath:
    """What :data:`SITE_PATH_PROGRAM` prints, read back with :func:`ros2nb.typed_json.decoded`
    in the process that asks for children: ``entries``, a new process's ``sys.path`` after
    its first entry (:attr:`~ros2nb.subject.fork_server.ForkRequest.site_path`)."""

    entries: list[str]


class ForkedProcess:
    """A child of the fork server, with the part of :class:`subprocess.Popen` the
    judge and :mod:`ros2nb.processes` use: ``pid`` (also its process group), ``stdout``,
    ``returncode``, ``poll()`` and ``wait(timeout)``.  Its exit code comes from the server,
    its parent, on a pipe of its own."""

    def __init__(self, pid: int, stdout: IO[str], status: int, args: list[str]) -> None:
        self.pid = pid
        self.stdout = stdout
        self.args = args
        #: The exit code once it ended (negative: the signal that ended it), else None.
        self.returncode: Optional[int] = None
        self._status = status
        self._said = b''

    def _read_status(self, timeout: Optional[float]) -> None:
        if self.returncode is not None:
            return
        ready, _, _ = select.select([self._status], [], [], timeout)
        if not ready:
            return
        chunk = os.read(self._status, 64)
        self._said += chunk
        if chunk:
            return
        os.close(self._status)
        # The server writes the code, then closes; nothing at all: the server itself ended
        # (killed with its judge's process group), and so was its child's reaper.
        self.returncode = int(self._said) if self._said.strip() else -signal.SIGKILL

    def poll(self) -> Optional[int]:
        """The exit code (negative: the signal that ended it), or None while it runs."""
        self._read_status(0)
        return self.returncode

    def wait(self, timeout: Optional[float] = None) -> int:
        """Wait for the exit code, at most ``timeout`` seconds.

        :raises subprocess.TimeoutExpired: when it still runs after ``timeout`` seconds.
        """
        deadline = None if timeout is None else time.monotonic() + timeout
        while self.returncode is None:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
            self._read_status(left)
        return self.returncode


class ForkServer:
    """The parent's end of a fork server: a socket to ask for children on.

    :param sock: the connected socket (``SOCK_SEQPACKET``: one request, one answer).
    :param process: the server when it was started afresh (None when forked from here).
    """

    def __init__(self, sock: socket.socket, process: Optional[subprocess.Popen[bytes]] = None
                 ) -> None:
        self._sock, self._process = sock, process
        self._lock = threading.Lock()
        self._failed = False

    def alive(self) -> bool:
        """Whether the server still answers (as far as this side knows)."""
        return not self._failed and (self._process is None or self._process.poll() is None)

    def fork(self, fds: tuple[int, ...], request: ForkRequest) -> tuple[int, int]:
        """Ask for a child; return its pid and the read end of its exit-code pipe.

        :param fds: the child's own pipes (a subject's command, reply and acknowledgement),
            then its output.
        :raises OSError: when the server is gone.
        """
        status_read, status_write = os.pipe()
        try:
            with self._lock:
                socket.send_fds(self._sock, [json.dumps(dataclasses.asdict(request)).encode()],
                                [*fds, status_write])
                answer = self._sock.recv(64)
            if not answer:
                raise OSError('the fork server ended')
        except BaseException:
            self._failed = True
            os.close(status_read)
            raise
        finally:
            os.close(status_write)
        return int(answer), status_read


_server: Optional[ForkServer] = None
_server_lock = threading.Lock()


def serve_from_here() -> None:
    """Fork this process's fork server from itself, now.

    Call it first thing in a process whose imports are a subject's (the judge's main),
    before ROS or any thread starts: the fork costs milliseconds and every subject of this
    process is then forked, the first too.  Never in a process with threads, nor in one that
    imported a course answer (the checks, the rules, ...): every subject would hold it in its
    memory (:mod:`.out_of_reach`); such a process's subjects come from a server started
    afresh.
    """
    global _server
    if _server is not None or threading.active_count() > 1 or answers_loaded():
        return  # a fork would hold only this thread, and any lock another one held
    parent_end, server_end = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    if os.fork() == 0:
        try:
            die_with_parent(signal.SIGKILL)  # the judge that ended takes its server along
            parent_end.close()
            # Not the parent's output: whoever reads that waits for its end, not the server's.
            devnull = os.open(os.devnull, os.O_RDWR)
            for fd in (0, 1, 2):
                os.dup2(devnull, fd)
            os.close(devnull)
            fork_server.serve(server_end)
        finally:
            os._exit(0)
    server_end.close()
    _server = ForkServer(parent_end)


def has_server() -> bool:
    """Whether this process has a fork server already (its subjects are all forked)."""
    return _server is not None and _server.alive()


def _started_server() -> ForkServer:
    """This process's fork server: the one it has (forked from here, or started before), else
    one started afresh (``python -m ros2nb.subject.fork_server``)."""
    global _server
    with _server_lock:
        if _server is None or not _server.alive():
            parent_end, server_end = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            process = subprocess.Popen(
                [sys.executable, '-m', fork_server.__name__, str(server_end.fileno())],
                pass_fds=(server_end.fileno(),), stdin=subprocess.DEVNULL)
            server_end.close()
            _server = ForkServer(parent_end, process)
        return _server


def fork_subject(fds: tuple[int, int, int], cwd: str, env: dict[str, str],
                 clock_env: str) -> ForkedProcess:
    """Fork ``python -P -m ros2nb.subject IN OUT`` from the fork server.

    :param fds: the subject's command, reply and acknowledgement pipes (this process keeps
        its own copies: close them after the call, as after ``Popen(pass_fds=...)``).
    :param cwd: its working folder.
    :param env: its whole environment; ``clock_env`` is added, naming its acknowledgement
        pipe.
    :return: the running subject, in a session of its own; its output (standard output and
        error) is ``stdout``.
    :raises OSError: when the fork server cannot be started.
    """
    return _fork(fork_server.SUBJECT, cwd, env, fds, clock_env=clock_env)


def fork_program(args: list[str], cwd: str, env: dict[str, str]) -> ForkedProcess:
    """Fork ``python -P -m ros2nb.subject.program ARGS`` (a learner's ``main()``) from the fork
    server, in a session of its own, with exactly ``env``; its output is ``stdout``.

    Introduced in ``03-write-the-publisher.ipynb`` (main() stopped with Ctrl+C).

    :raises OSError: when the fork server cannot be started.
    """
    return _fork(fork_server.PROGRAM, cwd, env, (), args=args)


def _fork(module: str, cwd: str, env: dict[str, str], fds: tuple[int, ...], *,
          clock_env: Optional[str] = None, args: Sequence[str] = ()) -> ForkedProcess:
    """Ask the fork server (this process's, started if need be) for a child that becomes
    ``python -P -m module args`` (a :class:`~ros2nb.subject.fork_server.ForkRequest`).

    :raises FileNotFoundError: when its folder does not exist (as ``subprocess.Popen``).
    """
    if not os.path.isdir(cwd):
        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), cwd)
    read_output, write_output = os.pipe()
    request = ForkRequest(module=module, cwd=cwd, env=env, site_path=_site_path(),
                          clock_env=clock_env, args=list(args))
    try:
        try:
            pid, status = _started_server().fork((*fds, write_output), request)
        except OSError:  # the server went away (killed?): a new one, once
            pid, status = _started_server().fork((*fds, write_output), request)
    except BaseException:
        os.close(read_output)
        raise
    finally:
        os.close(write_output)
    process = ForkedProcess(pid, os.fdopen(read_output, 'r'), status,
                            ['python', '-m', module, *args])
    _await_session(process)
    return process


def _await_session(process: ForkedProcess) -> None:
    """Wait until the forked child leads its own process group (so that the judge can
    signal the group, as with ``start_new_session``) or has ended."""
    deadline = time.monotonic() + SESSION_WAIT_S
    while time.monotonic() < deadline and process.poll() is None:
        try:
            if os.getpgid(process.pid) == process.pid:
                return
        except ProcessLookupError:
            return
        time.sleep(0.001)


@functools.lru_cache(maxsize=1)
def _site_path() -> list[str]:
    """The ``sys.path`` this Python gives a new process after its first entry, without
    ``PYTHONPATH`` (the standard library, site-packages and their ``.pth`` files): the fork
    server's own is the judge's, with whatever the judge added to it."""
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONPATH'}
    done = subprocess.run([sys.executable, '-c', SITE_PATH_PROGRAM], env=env,
                          capture_output=True, text=True, check=True)
    site: SitePath = decoded(SitePath, json.loads(done.stdout))
    return site.entries
