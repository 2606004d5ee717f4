"""Subjects forked from a process that has imported ROS already, instead of started afresh.

Part of the subjects (:mod:`ros2nb.subject`); the judge (:mod:`ros2nb.judge.subjects`)
starts its subjects here when it runs them without a sandbox command.

A subject spends most of its CPU time starting: Python, ``rclpy`` (with PyYAML and the
message types) and ``ros2nb`` take about 0.2 CPU-s to import, measured, of a subject's
0.3-0.45 CPU-s in ``make test``, where a judge starts hundreds.  multiprocessing's fork
server (:mod:`multiprocessing.forkserver`) imports them once per judge process and forks
each subject from there: the subject is then the process ``python -m ros2nb.subject`` would
be (its own session, working folder, environment, ``sys.path`` and output pipe), without
the imports.  The server never runs the learner's code, never starts ROS and holds no
thread, so every fork starts from the same clean state.

While grading, each subject runs in a sandbox of its own (the judge's
``ROS2NB_SUBJECT_PREFIX``), which a fork cannot enter: the judge starts those afresh.
"""

from __future__ import annotations

import contextlib
import functools
import io
import json
import multiprocessing
import os
import subprocess
import sys
import time
from multiprocessing.connection import Connection
from typing import IO, Optional

#: What the fork server imports before it forks the first subject: the subject's own
#: modules and what rclpy imports when the first node starts (the parameter services' types,
#: numpy for their arrays, rosidl's type support with its parser).  numpy starts no thread
#: with ``OPENBLAS_NUM_THREADS=1``, which every way of running the course sets.
PRELOAD = ['ros2nb.subject.__main__', 'rclpy.node', 'rcl_interfaces.srv', 'numpy',
           'rosidl_generator_py.import_type_support_impl', 'std_msgs.msg']
#: The variable generated message modules read once, when imported (rosidl_generator_py):
#: a forked subject sets what they read from its own environment.
CHECK_FIELDS_ENV = 'ROS_PYTHON_CHECK_FIELDS'
#: Seconds a forked subject gets to become the leader of its own session.
SESSION_WAIT_S = 5.0

_context = multiprocessing.get_context('forkserver')
_context.set_forkserver_preload(PRELOAD)


def forkable() -> bool:
    """Whether subjects forked from this process start clean.  multiprocessing runs the
    parent's main module again in each child, as ``__mp_main__``, unless it is ``-c`` code or
    a package's ``__main__`` (a judge's ``python -m ros2nb.judge``, pytest's and its
    workers'): a judge run from a script file (a benchmark, ``tests/corpora.py``) starts its
    subjects afresh, so that no code of its own runs in them."""
    main = sys.modules['__main__']
    name = getattr(getattr(main, '__spec__', None), 'name', None)
    if name is not None:
        return name == '__main__' or name.endswith('.__main__')
    return getattr(main, '__file__', None) is None


class ForkedProcess:
    """A subject forked by the fork server, with the part of :class:`subprocess.Popen` the
    judge and :mod:`ros2nb.processes` use: ``pid`` (also its process group), ``stdout``,
    ``poll()`` and ``wait(timeout)``."""

    def __init__(self, process: multiprocessing.process.BaseProcess, stdout: IO[str]) -> None:
        self._process = process
        self.pid: int = process.pid  # type: ignore[assignment]
        self.stdout = stdout
        self.args = ['python', '-m', 'ros2nb.subject']

    @property
    def returncode(self) -> Optional[int]:
        """The exit code once it ended (negative: the signal that ended it), else None."""
        return self._process.exitcode

    def poll(self) -> Optional[int]:
        """The exit code (negative: the signal that ended it), or None while it runs."""
        return self._process.exitcode

    def wait(self, timeout: Optional[float] = None) -> int:
        """Wait for the exit code, at most ``timeout`` seconds.

        :raises subprocess.TimeoutExpired: when it still runs after ``timeout`` seconds.
        """
        self._process.join(timeout)
        if self._process.exitcode is None:
            raise subprocess.TimeoutExpired(self.args, timeout or 0.0)
        return self._process.exitcode


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
    pipes = [Connection(os.dup(fd)) for fd in (*fds, write_output)]
    try:
        process = _context.Process(target=_become_subject, name='ros2nb.subject', daemon=False,
                                   args=(*pipes, cwd, env, clock_env, _site_path()))
        process.start()
    finally:
        for pipe in pipes:
            pipe.close()
        os.close(write_output)
    _await_session(process)
    return ForkedProcess(process, os.fdopen(read_output, 'r'))


def _await_session(process: multiprocessing.process.BaseProcess) -> None:
    """Wait until the forked subject leads its own process group (so that the judge can
    signal the group, as with ``start_new_session``) or has ended."""
    deadline = time.monotonic() + SESSION_WAIT_S
    while time.monotonic() < deadline and process.exitcode is None:
        try:
            if os.getpgid(process.pid) == process.pid:  # type: ignore[arg-type]
                return
        except ProcessLookupError:
            return
        time.sleep(0.001)


def _become_subject(commands: Connection, replies: Connection, acks: Connection,
                    output: Connection, cwd: str, env: dict[str, str], clock_env: str,
                    site_path: list[str]) -> None:
    """In the forked child: become ``python -m ros2nb.subject IN OUT`` started in ``cwd``
    with ``env``, then run it to its end (this never returns)."""
    os.setsid()
    out = _take(output)
    devnull = os.open(os.devnull, os.O_RDONLY)
    os.dup2(devnull, 0)
    os.dup2(out, 1)
    os.dup2(out, 2)
    os.close(devnull)
    os.close(out)
    os.chdir(cwd)
    in_fd, out_fd, acks_fd = _take(commands), _take(replies), _take(acks)
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


def _take(pipe: Connection) -> int:
    """The file descriptor a pipe came as, as this process's own (the wrapper is closed)."""
    fd = os.dup(pipe.fileno())
    pipe.close()
    return fd


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
