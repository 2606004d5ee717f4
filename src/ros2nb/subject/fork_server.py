"""The fork server's side: a process that has imported ROS and forks the judge's subjects.

Part of the subjects (:mod:`ros2nb.subject`); the judge's side, and why, is
:mod:`ros2nb.subject.forked`.  Each request names what the child becomes: ``python -m
ros2nb.subject IN OUT`` (a subject) or ``python -m ros2nb.subject.program FILE [CLASS]`` (a
learner's ``main()``, run as ``ros2 run`` would), started in its folder with its
environment.  The server never runs the learner's code, never starts ROS and holds no
thread, so every fork starts from the same clean state.
"""

from __future__ import annotations

import atexit
import contextlib
import importlib
import io
import json
import os
import select
import signal
import socket
import sys
import threading
import traceback
from dataclasses import dataclass, field
from typing import Any, Callable, NoReturn, Optional, Union

from ..processes import die_with_parent
from ..typed_json import Unreadable, decoded

#: What the server imports before it forks the first child: the subject's own modules and
#: what rclpy imports when the first node starts (the parameter services' types, numpy for
#: their arrays, rosidl's type support with its parser).  numpy starts no thread with
#: ``OPENBLAS_NUM_THREADS=1``, which every way of running the course sets.
PRELOAD = ['ros2nb.subject.__main__', 'ros2nb.subject.program', 'rclpy.node',
           'rcl_interfaces.srv', 'numpy', 'rosidl_generator_py.import_type_support_impl',
           'std_msgs.msg']
#: The variable generated message modules read once, when imported (rosidl_generator_py):
#: a forked child sets what they read from its own environment.
CHECK_FIELDS_ENV = 'ROS_PYTHON_CHECK_FIELDS'
#: Largest request the server reads (a child's whole environment, as JSON).
MAX_REQUEST_BYTES = 1 << 20
#: What a child becomes: ``python -m`` of one of these modules.
SUBJECT, PROGRAM = 'ros2nb.subject', 'ros2nb.subject.program'
#: Most file descriptors one request brings: a subject's three pipes, its output, its status.
MAX_FDS = 5


@dataclass(frozen=True, kw_only=True)
class ForkRequest:
    """What a child of the fork server is to become: ``python -P -m MODULE ARGS``.

    Sent by the process that asks for children (:class:`ros2nb.subject.forked.ForkServer`,
    the judge's side) on the server's socket, as JSON (``dataclasses.asdict``), and read in
    the forked child with :func:`ros2nb.typed_json.decoded`, every field checked.

    :ivar module: :data:`SUBJECT` or :data:`PROGRAM`.
    :ivar cwd: its working folder.
    :ivar env: its whole environment.
    :ivar site_path: the ``sys.path`` a new process of this Python has after its first entry,
        without ``PYTHONPATH`` (which ``env`` puts in front).
    :ivar clock_env: (a subject) the variable that names its acknowledgement pipe.
    :ivar args: (a program) its arguments: the learner's file, and its class.
    """

    module: str
    cwd: str
    env: dict[str, str]
    site_path: list[str]
    clock_env: Optional[str] = None
    args: list[str] = field(default_factory=list)


def serve(sock: socket.socket) -> None:
    """The fork server: fork a child for each request on ``sock``, tell each one's exit code
    on the pipe that came last with it, and end when the parent closes its end (never
    returns).  Ctrl+C in the terminal is its parent's to handle, not the server's."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    wake_read, wake_write = os.pipe()
    for fd in (wake_read, wake_write):
        os.set_blocking(fd, False)
    signal.set_wakeup_fd(wake_write)
    signal.signal(signal.SIGCHLD, lambda *_: None)
    status: dict[int, int] = {}  # a child's pid -> the write end of its exit-code pipe
    while True:
        watched: list[Any] = [sock, wake_read]
        ready, _, _ = select.select(watched, [], [])
        if wake_read in ready:
            with contextlib.suppress(BlockingIOError):
                os.read(wake_read, 4096)
        _reap(status)
        if sock not in ready:
            continue
        try:
            message, fds, _, _ = socket.recv_fds(sock, MAX_REQUEST_BYTES, MAX_FDS)
        except OSError:
            message, fds = b'', []
        if not message or len(fds) < 2:
            os._exit(0)  # the parent is gone: its children are its to end
        preload()  # once, and only in a server that forks something
        pid = os.fork()
        if pid == 0:
            sock.detach()  # closed with the server's other files in _become
            signal.set_wakeup_fd(-1)
            signal.signal(signal.SIGCHLD, signal.SIG_DFL)
            signal.signal(signal.SIGINT, signal.default_int_handler)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            die_with_parent(signal.SIGTERM)  # a server that ended takes its children along
            try:
                _become(json.loads(message), fds[:-2], fds[-2])
            finally:  # it could not become the child (its folder went away?): say why
                traceback.print_exc()
                os._exit(1)
        for fd in fds[:-1]:
            os.close(fd)
        status[pid] = fds[-1]
        sock.send(str(pid).encode())


def _reap(status: dict[int, int]) -> None:
    """Tell the exit code of every child that ended, on its pipe."""
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


def _become(data: Any, kept: list[int], out: int) -> NoReturn:
    """In the forked child: become ``python -P -m MODULE ARGS`` (the request's) started in
    its folder with its environment, then run it to its end (this never returns).

    :param data: the request as JSON, read as a :class:`ForkRequest` once the child's output
        is its own, so that one of another shape is said there.
    :param kept: the child's own pipes (a subject's command, reply and acknowledgement).
    :param out: where its standard output and error go.
    :raises ros2nb.typed_json.Unreadable: for a request that does not fit its type.
    """
    os.setsid()
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.dup2(out, 1)
    os.dup2(out, 2)
    os.close(devnull)
    os.close(out)
    request: ForkRequest = decoded(ForkRequest, data)
    env = dict(request.env)
    os.chdir(request.cwd)
    if request.module == SUBJECT:
        if request.clock_env is None:
            raise Unreadable('ForkRequest.clock_env is missing: a subject needs one')
        args = [str(kept[0]), str(kept[1])]
        env[request.clock_env] = str(kept[2])
    else:
        args = list(request.args)
    os.environ.clear()
    os.environ.update(env)
    _standard_streams(unbuffered=bool(env.get('PYTHONUNBUFFERED')))
    _close_all_but({0, 1, 2, *kept})  # e.g. the server's pipes
    wanted = os.environ.get(CHECK_FIELDS_ENV, '')
    for module in list(sys.modules.values()):
        if 'ros_python_check_fields' in getattr(module, '__dict__', {}):
            setattr(module, 'ros_python_check_fields', wanted)  # rosidl's module global
    # As ``python -P`` starts: the working folder is not on the path (no module of the
    # learner's there stands in for the standard library's)
    sys.path[:] = [*filter(None, env.get('PYTHONPATH', '').split(os.pathsep)),
                   *request.site_path]
    from ..processes import end_this_process
    if request.module == SUBJECT:
        from .__main__ import main
        sys.argv = [sys.modules['ros2nb.subject.__main__'].__file__ or '', *args]
        end_this_process(main(args))
    from . import program
    sys.argv = [program.__file__ or '', *args]
    _end_as_python_does(lambda: program.main(args))


def _end_as_python_does(call: Callable[[], int]) -> NoReturn:
    """``sys.exit(call())`` as the main code of a process, ended the way Python ends one: an
    exception that escapes is printed (``sys.excepthook``) and exits with 1, ``SystemExit``
    gives its code, the threads that are not daemons are waited for, the exit handlers run,
    and a ``KeyboardInterrupt`` that escaped ends the process with SIGINT itself."""
    interrupted = False
    code: Union[int, str, None]
    try:
        code = call()
    except SystemExit as stop:
        code = stop.code
    except KeyboardInterrupt:
        sys.excepthook(*sys.exc_info())
        code, interrupted = 1, True
    except BaseException:
        sys.excepthook(*sys.exc_info())
        code = 1
    if code is None:
        code = 0
    elif not isinstance(code, int):
        print(code, file=sys.stderr)
        code = 1
    try:
        threading._shutdown()  # type: ignore[attr-defined]  # what Python waits for first
        atexit._run_exitfuncs()
    finally:
        for stream in (sys.stdout, sys.stderr):
            with contextlib.suppress(OSError, ValueError):
                stream.flush()
        if interrupted:
            signal.signal(signal.SIGINT, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGINT)
        os._exit(code & 0xff)


def _standard_streams(unbuffered: bool) -> None:
    """New ``sys.stdin``, ``sys.stdout`` and ``sys.stderr`` on file descriptors 0-2, as a
    process started with this environment makes them (``PYTHONUNBUFFERED``: written at once)."""
    streams, encoding = [], getattr(sys.__stdout__, 'encoding', None) or 'utf-8'
    for fd, mode, errors in ((0, 'r', 'strict'), (1, 'w', 'strict'), (2, 'w', 'backslashreplace')):
        raw = io.FileIO(fd, mode, closefd=False)
        buffered = raw if unbuffered and fd else (
            io.BufferedReader(raw) if fd == 0 else io.BufferedWriter(raw))
        streams.append(io.TextIOWrapper(
            buffered, encoding=encoding, errors=errors,
            write_through=unbuffered and fd > 0, line_buffering=fd == 2 and not unbuffered))
    sys.stdin, sys.stdout, sys.stderr = streams


def _close_all_but(kept: set[int]) -> None:
    """Close every file descriptor of this process but ``kept``."""
    for fd in sorted(int(name) for name in os.listdir('/proc/self/fd')):
        if fd not in kept:
            with contextlib.suppress(OSError):  # the listing's own descriptor
                os.close(fd)


def preload() -> None:
    """Import what every child imports (:data:`PRELOAD`), in the server (again: nothing)."""
    for module in PRELOAD:
        if module not in sys.modules:
            importlib.import_module(module)


def main(argv: list[str]) -> int:
    """``python -m ros2nb.subject.fork_server SOCKET_FD``: a fork server started afresh."""
    die_with_parent(signal.SIGKILL)  # the process that started it takes it along
    preload()
    serve(socket.socket(fileno=int(argv[0])))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
