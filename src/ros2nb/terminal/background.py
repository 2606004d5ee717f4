"""``ros2 run`` in a terminal left open: a node process that runs until you stop it.

Introduced in ``06-five-promises.ipynb``.  :func:`ros2nb.ros2_run` runs processes for a
number of seconds and then presses Ctrl+C for all of them; here each process runs on
until its :meth:`NodeProcess.stop`, while the notebook goes on, so one can be stopped and
started again while the others keep running.  Their output is collected, not printed:
:meth:`NodeProcess.new_lines` shows what came since the last look.  Stopping goes through
:mod:`ros2nb.processes`, like every process ros2nb starts; any left running are stopped
when the kernel ends.
"""

from __future__ import annotations

import atexit
import subprocess
import threading
from typing import Any, Callable, Optional

from ..errors import UsageError
from ..explain.ros_settings import output_mistake
from ..patience import wait_for_work
from ..processes import stop_process_group
from .colcon import source_workspace
from .run import _command, node_process_env
from .workspace import PathLike, workspace_or_current

_running: list['NodeProcess'] = []


def running_pids() -> list[int]:
    """The processes started in the background that still run (what waits attend to)."""
    return [node.proc.pid for node in _running if node.proc.poll() is None]


def failures() -> list[str]:
    """Why each process started in the background (and not stopped) ended by itself, one
    line each (:meth:`NodeProcess.failure`)."""
    return [said for said in (node.failure() for node in _running) if said]


class NodeProcess:
    """One executable started like ``ros2 run PKG EXE ARGS``, running in the background.

    :ivar label: ``EXE`` (as ``ros2 launch`` prefixes its lines).
    :ivar lines: every line it printed so far.
    """

    def __init__(self, argv: list[str], label: str, env: dict[str, str]) -> None:
        self.label = label
        self.lines: list[str] = []
        self._shown = 0
        self._ended = False  # its output closed: it exited (or closed stdout)
        self._changed = threading.Condition()
        self.proc = subprocess.Popen(argv, env=env, text=True, stdout=subprocess.PIPE,
                                     stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                     start_new_session=True)
        threading.Thread(target=self._read, daemon=True).start()
        if not _running:
            atexit.register(stop_all)  # once per batch; stop_all is safe to repeat
        _running.append(self)

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            with self._changed:
                self.lines.append(line.rstrip('\n'))
                self._changed.notify_all()
        with self._changed:
            self._ended = True
            self._changed.notify_all()

    @property
    def running(self) -> bool:
        """True while the process has not exited."""
        return self.proc.poll() is None

    def count(self, text: str) -> int:
        """How many of its lines so far contain ``text``."""
        with self._changed:
            return sum(text in line for line in self.lines)

    def wait_for(self, text: str, *, count: int = 1, timeout: float = 60.0) -> bool:
        """Wait until ``count`` of its lines contain ``text``, while the background processes
        work towards it (``timeout``: seconds of their work, or of their idle waiting, as
        :class:`~ros2nb.patience.Patience` counts: a busy machine is slow, not wrong).

        :return: True when they did; False on timeout or when the process ended first.
        """
        def said() -> bool:
            return self._ended or sum(text in line for line in self.lines) >= count

        def look(condition: Callable[[], Any], seconds: float) -> bool:
            with self._changed:
                return self._changed.wait_for(condition, seconds)

        wait_for_work(said, running_pids(), timeout, look=look)
        with self._changed:
            return sum(text in line for line in self.lines) >= count

    def failure(self) -> Optional[str]:
        """Why it ended by itself, in one line (``LABEL exited with code N: ...``, the fix for
        a known mistake in its output, else its last line), or None while it runs or when it
        ended cleanly.  Introduced in ``06-five-promises.ipynb``."""
        code = self.proc.poll()
        if code in (None, 0) or not self._ended:
            return None
        with self._changed:
            lines = list(self.lines)
        said = output_mistake(lines) or next((line for line in reversed(lines) if line.strip()),
                                             'no output')
        return f'{self.label} exited with code {code}: {said}'

    def new_lines(self) -> list[str]:
        """Print and return the lines that came since the last call, prefixed with the label."""
        with self._changed:
            fresh = self.lines[self._shown:]
            self._shown = len(self.lines)
        for line in fresh:
            print(f'[{self.label}] {line}')
        return fresh

    def stop(self) -> Optional[int]:
        """Press Ctrl+C for it (SIGINT; SIGTERM, then SIGKILL if it hangs); return the exit code.

        Safe to call again: it returns the same code.
        """
        code = stop_process_group(self.proc)
        if self in _running:
            _running.remove(self)
        return code


def ros2_start(package: str, executable: str, *args: str,
               workspace_path: Optional[PathLike] = None) -> NodeProcess:
    """Start ``ros2 run PACKAGE EXECUTABLE ARGS...`` and return at once, leaving it running.

    The process runs in the sourced workspace, on the kernel's ROS domain, like a terminal
    you leave open; stop it with ``.stop()`` (Ctrl+C).  ``args`` go to the node, e.g.
    ``'--ros-args', '-r', '__ns:=/kitchen'``.

    Introduced in ``06-five-promises.ipynb``.

    :param workspace_path: the workspace; ``None`` is the current one.
    :return: the running process.
    :raises Ros2nbError: ``Package 'PKG' not found`` / ``No executable found`` (the CLI's
        texts), or an unbuilt workspace.
    :raises UsageError: when an argument is not a string.
    """
    if not all(isinstance(a, str) for a in (package, executable, *args)):
        raise UsageError('Every argument of ros2_start is a string, e.g. '
                         "ros2_start('sensor_simulator', 'temperature_publisher', '--ros-args', "
                         "'-r', '__ns:=/kitchen').")
    env = node_process_env(source_workspace(workspace_path))
    env.setdefault('ROS_LOG_DIR', str(workspace_or_current(workspace_path) / 'log' / 'ros'))
    return NodeProcess(_command(package, executable, list(args), env), executable, env)


def stop_all() -> list[Optional[int]]:
    """Stop every process :func:`ros2_start` started that is still running; their exit codes.

    Introduced in ``06-five-promises.ipynb``.
    """
    return [process.stop() for process in list(_running)]

