"""Subjects forked from a process that has imported ROS already, instead of started afresh.

Part of the subjects (:mod:`ros2nb.subject`); the judge (:mod:`ros2nb.judge.subjects`)
starts its subjects here when it runs them without a sandbox command.

A subject spends most of its CPU time starting: Python, ``rclpy`` (with PyYAML and the
message types) and ``ros2nb`` take about 0.3 CPU-s to import and start, of a short
subject's 0.35-0.45 CPU-s, where ``make test`` starts hundreds.  A fork server (a
:class:`ForkServer`) holds those imports and forks each subject from there: the subject is
then the process ``python -m ros2nb.subject`` would be (its own session, working folder,
environment, ``sys.path`` and output pipe), without the imports.  The server never runs the
learner's code, never starts ROS and holds no thread, so every fork starts from the same
clean state.

A judge process (``python -m ros2nb.judge``, what a check in the learner's kernel starts)
forks its server from itself first thing (:func:`serve_from_here`), before ROS or any
thread starts: a few milliseconds, so even a check's one subject is forked.  Elsewhere
(a test process that judges, a script) the server is started afresh with the first forked
subject (``python -m ros2nb.subject.forked``), which repays itself from the second subject
on.  The server answers on a socket of its parent's only and ends when its parent does.

While grading, each subject runs in a sandbox of its own (the judge's
``ROS2NB_SUBJECT_PREFIX``), which a fork cannot enter: the judge starts those afresh.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
import io
import json
import os
import select
import signal
import socket
import subprocess
import sys
import threading
import time
from typing import IO, Optional

#: What an afresh-started server imports before it forks the first subject: the subject's
#: own modules and what rclpy imports when the first node starts (the parameter services'
#: types, numpy for their arrays, rosidl's type support with its parser).  numpy starts no
#: thread with ``OPENBLAS_NUM_THREADS=1``, which every way of running the course sets.
PRELOAD = ['ros2nb.subject.__main__', 'rclpy.node', 'rcl_interfaces.srv', 'numpy',
           'rosidl_generator_py.import_type_support_impl', 'std_msgs.msg']
#: The variable generated message modules read once, when imported (rosidl_generator_py):
#: a forked subject sets what they read from its own environment.
CHECK_FIELDS_ENV = 'ROS_PYTHON_CHECK_FIELDS'
#: Seconds a forked subject gets to become the leader of its own session.
SESSION_WAIT_S = 5.0
#: Largest request the server reads (a subject's whole environment, as JSON).
MAX_REQUEST_BYTES = 1 << 20


class ForkedProcess:
    """A subject forked by the fork server, with the part of :class:`subprocess.Popen` the
    judge and :mod:`ros2nb.processes` use: ``pid`` (also its process group), ``stdout``,
    ``returncode``, ``poll()`` and ``wait(timeout)``.  Its exit code comes from the server,
    its parent, on a pipe of its own."""

    def __init__(self, pid: int, stdout: IO[str], status: int) -> None:
        self.pid = pid
        self.stdout = stdout
        self.args = ['python', '-m', 'ros2nb.subject']
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
        # (killed with its judge's process group), and so was its subject's reaper.
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
    """The parent's end of a fork server: a socket to ask for subjects on.

    :param sock: the connected socket (``SOCK_SEQPACKET``: one request, one answer).
    :param process: the server when it was started afresh (None when forked from here).
    """

    def __init__(self, sock: socket.socket, process: Optional[subprocess.Popen] = None,
                 pid: Optional[int] = None) -> None:
        self._sock, self._process = sock, process
        self._lock = threading.Lock()
        self._failed = False
        #: The server's process id.
        self.pid = process.pid if process is not None else pid

    def alive(self) -> bool:
        """Whether the server still answers (as far as this side knows)."""
        return not self._failed and (self._process is None or self._process.poll() is None)

    def fork(self, fds: tuple[int, ...], request: dict) -> tuple[int, int]:
        """Ask for a subject; return its pid and the read end of its exit-code pipe.

        :param fds: the subject's pipes (command, reply, acknowledgement, output).
        :raises OSError: when the server is gone.
        """
        status_read, status_write = os.pipe()
        try:
            with self._lock:
                socket.send_fds(self._sock, [json.dumps(request).encode()],
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
    process is then forked, the first too.  Never in a process with threads.
    """
    global _server
    if threading.active_count() > 1:
        return  # a fork would hold only this thread, and any lock another one held
    parent_end, server_end = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
    pid = os.fork()
    if pid == 0:
        try:
            parent_end.close()
            # Not the parent's output: whoever reads that waits for its end, not the server's.
            devnull = os.open(os.devnull, os.O_RDWR)
            for fd in (0, 1, 2):
                os.dup2(devnull, fd)
            os.close(devnull)
            _preload()
            _serve(server_end)
        finally:
            os._exit(0)
    server_end.close()
    _server = ForkServer(parent_end, pid=pid)


def has_server() -> bool:
    """Whether this process has a fork server already (its subjects are all forked)."""
    return _server is not None and _server.alive()


def _started_server() -> ForkServer:
    """This process's fork server, started afresh (``python -m ros2nb.subject.forked``) the
    first time."""
    global _server
    with _server_lock:
        if _server is None or not _server.alive():
            parent_end, server_end = socket.socketpair(socket.AF_UNIX, socket.SOCK_SEQPACKET)
            process = subprocess.Popen(
                [sys.executable, '-m', 'ros2nb.subject.forked', str(server_end.fileno())],
                pass_fds=(server_end.fileno(),), stdin=subprocess.DEVNULL)
            server_end.close()
            _server = ForkServer(parent_end, process)
        return _server


def fork_subject(fds: tuple[int, int, int], cwd: str, env: dict[str, str],
                 clock_env: str) -> ForkedProcess:
    """Fork ``python -m ros2nb.subject IN OUT`` from the fork server.

    :param fds: the subject's command, reply and acknowledgement pipes (this process keeps
        its own copies: close them after the call, as after ``Popen(pass_fds=...)``).
    :param cwd: its working folder.
    :param env: its whole environment; ``clock_env`` is added, naming its acknowledgement
        pipe.
    :return: the running subject, in a session of its own; its output (standard output and
        error) is ``stdout``.
    :raises OSError: when the fork server cannot be started.
    """
    read_output, write_output = os.pipe()
    request = {'cwd': cwd, 'env': env, 'clock_env': clock_env, 'site_path': _site_path()}
    try:
        try:
            pid, status = (_server if has_server() else _started_server()).fork(
                (*fds, write_output), request)
        except OSError:  # the server went away (killed?): a new one, once
            pid, status = _started_server().fork((*fds, write_output), request)
    except BaseException:
        os.close(read_output)
        raise
    finally:
        os.close(write_output)
    process = ForkedProcess(pid, os.fdopen(read_output, 'r'), status)
    _await_session(process)
    return process


def _await_session(process: ForkedProcess) -> None:
    """Wait until the forked subject leads its own process group (so that the judge can
    signal the group, as with ``start_new_session``) or has ended."""
    deadline = time.monotonic() + SESSION_WAIT_S
    while time.monotonic() < deadline and process.poll() is None:
        try:
            if os.getpgid(process.pid) == process.pid:
                return
        except ProcessLookupError:
            return
        time.sleep(0.001)


def _serve(sock: socket.socket) -> None:
    """The fork server: fork a subject for each request on ``sock``, tell each one's exit
    code on the pipe that came with it, and end when the parent closes its end (never
    returns).  Ctrl+C in the terminal is its parent's to handle, not the server's."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    wake_read, wake_write = os.pipe()
    for fd in (wake_read, wake_write):
        os.set_blocking(fd, False)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    status: dict[int, int] = {}  # subject's pid -> the write end of its exit-code pipe
    while True:
        ready, _, _ = select.select([sock, wake_read], [], [])
        if wake_read in ready:
            with contextlib.suppress(BlockingIOError):
                os.read(wake_read, 4096)
        _reap(status)
        if sock not in ready:
            continue
        try:
            message, fds, _, _ = socket.recv_fds(sock, MAX_REQUEST_BYTES, 5)
        except OSError:
            message, fds = b'', []
        if not message or len(fds) != 5:
            os._exit(0)  # the parent is gone: its subjects are its to end
        pid = os.fork()
        if pid == 0:
            sock.detach()  # closed with the server's other files in _become_subject
            signal.set_wakeup_fd(-1)
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            signal.signal(signal.SIGINT, signal.default_int_handler)
            request = json.loads(message)
            _become_subject(*fds[:4], request['cwd'], request['env'], request['clock_env'],
                            request['site_path'])
        for fd in fds[:4]:
            os.close(fd)
        status[pid] = fds[4]
        sock.send(str(pid).encode())


def _reap(status: dict[int, int]) -> None:
    """Tell the exit code of every subject that ended, on its pipe."""
    while status:
        try:
            pid, code = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        fd = status.pop(pid, None)
        if fd is not None:
            with contextlib.suppress(OSError):
                os.write(fd, str(os.waitstatus_to_exitcode(code)).encode())
            os.close(fd)


def _become_subject(in_fd: int, out_fd: int, acks_fd: int, out: int, cwd: str,
                    env: dict[str, str], clock_env: str, site_path: list[str]) -> None:
    """In the forked child: become ``python -m ros2nb.subject IN OUT`` started in ``cwd``
    with ``env``, then run it to its end (this never returns)."""
    os.setsid()
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.dup2(out, 1)
    os.dup2(out, 2)
    os.close(devnull)
    os.close(out)
    os.chdir(cwd)
    os.environ.clear()
    os.environ.update({**env, clock_env: str(acks_fd)})
    _standard_streams(unbuffered=bool(env.get('PYTHONUNBUFFERED')))
    _close_all_but({0, 1, 2, in_fd, out_fd, acks_fd})  # e.g. the server's pipes
    wanted = os.environ.get(CHECK_FIELDS_ENV, '')
    for module in list(sys.modules.values()):
        if 'ros_python_check_fields' in getattr(module, '__dict__', {}):
            module.ros_python_check_fields = wanted
    sys.path[:] = [cwd, *filter(None, env.get('PYTHONPATH', '').split(os.pathsep)), *site_path]
    sys.argv = [sys.modules['ros2nb.subject.__main__'].__file__ or '', str(in_fd), str(out_fd)]
    from ..processes import end_this_process
    from .__main__ import main
    end_this_process(main(sys.argv[1:]))


def _standard_streams(unbuffered: bool) -> None:
    """New ``sys.stdin``, ``sys.stdout`` and ``sys.stderr`` on file descriptors 0-2, as a
    process started with this environment makes them (``PYTHONUNBUFFERED``: written at once)."""
    streams, encoding = [], getattr(sys.__stdout__, 'encoding', None) or 'utf-8'
    for fd, mode, errors in ((0, 'r', 'strict'), (1, 'w', 'strict'), (2, 'w', 'backslashreplace')):
        raw = io.FileIO(fd, mode, closefd=False)
        buffered = raw if unbuffered and fd else (
            io.BufferedReader(raw) if fd == 0 else io.BufferedWriter(raw))
        streams.append(io.TextIOWrapper(
            buffered, encoding=encoding, errors=errors,  # type: ignore[arg-type]
            write_through=unbuffered and fd > 0, line_buffering=fd == 2 and not unbuffered))
    sys.stdin, sys.stdout, sys.stderr = streams


def _close_all_but(kept: set[int]) -> None:
    """Close every file descriptor of this process but ``kept``."""
    for fd in sorted(int(name) for name in os.listdir('/proc/self/fd')):
        if fd not in kept:
            with contextlib.suppress(OSError):  # the listing's own descriptor
                os.close(fd)


@functools.lru_cache(maxsize=1)
def _site_path() -> list[str]:
    """The ``sys.path`` this Python gives a new process after its first entry, without
    ``PYTHONPATH`` (the standard library, site-packages and their ``.pth`` files): the fork
    server's own is the judge's, with whatever the judge added to it."""
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONPATH'}
    program = 'import json, sys\nprint(json.dumps(sys.path[1:]))'
    done = subprocess.run([sys.executable, '-c', program], env=env, capture_output=True,
                          text=True, check=True)
    return json.loads(done.stdout)


def _preload() -> None:
    """Import what every subject imports (:data:`PRELOAD`), once, in the server."""
    for module in PRELOAD:
        importlib.import_module(module)


def main(argv: list[str]) -> int:
    """``python -m ros2nb.subject.forked SOCKET_FD``: a fork server started afresh."""
    _preload()
    _serve(socket.socket(fileno=int(argv[0])))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
