"""``ros2 run``: the real ``ros2`` when it is on PATH, otherwise resolved as ros2cli does it.

Introduced in ``05-entry-points-and-run.ipynb``.  ros2nb finds the executable the way
``ros2 run`` does (ament index, then ``<prefix>/lib/<package>/<executable>``), with the
same error texts, and starts each process in a session of its own (:mod:`ros2nb.processes`
stops them).  The kernel's own nodes keep running meanwhile.
"""

from __future__ import annotations

import os
import queue
import shutil
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Mapping, Optional, Sequence

from ament_index_python.packages import PackageNotFoundError, get_package_prefix

from .. import domains, runtime
from ..errors import Ros2nbError, UsageError
from ..explain.ros_settings import output_mistake
from ..patience import Patience
from ..processes import STOP_GRACE_S, signal_group, stop_process_group
from .colcon import source_workspace
from .workspace import PathLike, workspace_or_current

#: Seconds a process may take to print its first line before Ctrl+C's countdown starts anyway:
#: of its work while it works, of the wall clock while it waits (patience.Patience).
START_UP_S = 60.0
#: Console format for processes started by ros2nb (timestamps removed, as in the kernel).
CONSOLE_FORMAT = '[{severity}] [{name}]: {message}'


def stream_lines(proc: subprocess.Popen[str], index: int, prefix: str,
                 lines: queue.Queue[tuple[int, Optional[str]]]) -> None:
    """Put ``(index, prefix + line)`` in ``lines`` for each line ``proc`` prints; ``(index, None)``
    when it closes its output."""
    assert proc.stdout is not None
    for line in proc.stdout:
        lines.put((index, prefix + line.rstrip('\n')))
    lines.put((index, None))


def node_process_env(base: Mapping[str, str]) -> dict[str, str]:
    """Return ``base`` plus what a node process started from a notebook needs.

    The kernel's ROS domain (claimed now if it was not yet, see :mod:`ros2nb.domains`),
    unbuffered output (lines arrive as they are printed), no colours, the course's
    console format without timestamps and discovery on this machine, unless already
    chosen in ``base``.
    """
    env = dict(base, PYTHONUNBUFFERED='1', RCUTILS_COLORIZED_OUTPUT='0')
    env.setdefault(domains.DOMAIN_ENV, str(domains.domain_id()))
    env.setdefault('RCUTILS_CONSOLE_OUTPUT_FORMAT', CONSOLE_FORMAT)
    env.setdefault('ROS_AUTOMATIC_DISCOVERY_RANGE', 'LOCALHOST')
    return env


_environ_lock = threading.Lock()


def find_executable(package: str, executable: str, env: Mapping[str, str]) -> Path:
    """Resolve ``ros2 run PACKAGE EXECUTABLE`` as ros2cli does, with ``env``'s ament index.

    The package's prefix comes from ``ament_index_python`` (the index that
    ``AMENT_PREFIX_PATH`` lists); the executable is the one file of that name that may be
    executed under ``<prefix>/lib/<package>/``.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :param env: an environment such as :func:`source_workspace` returns.
    :return: the executable's path.
    :raises Ros2nbError: ``Package 'PKG' not found``, ``No executable found`` or
        ``Multiple executables found``, the CLI's texts.
    """
    with _environ_lock:  # ament_index_python reads AMENT_PREFIX_PATH from os.environ
        saved = os.environ.get('AMENT_PREFIX_PATH')
        os.environ['AMENT_PREFIX_PATH'] = env.get('AMENT_PREFIX_PATH', '')
        try:
            prefix = Path(get_package_prefix(package))
        except (PackageNotFoundError, ValueError):
            raise Ros2nbError(f"Package '{package}' not found") from None
        finally:
            if saved is None:
                os.environ.pop('AMENT_PREFIX_PATH', None)
            else:
                os.environ['AMENT_PREFIX_PATH'] = saved
    found = sorted(path for path in (prefix / 'lib' / package).rglob(executable)
                   if path.is_file() and os.access(path, os.X_OK)
                   and not any(part.startswith('.') for part in path.parts[len(prefix.parts):]))
    if not found:
        raise Ros2nbError('No executable found')
    if len(found) > 1:
        raise Ros2nbError('Multiple executables found: ' + ', '.join(map(str, found)))
    return found[0]


def _command(package: str, executable: str, args: Sequence[str], env: dict[str, str]) -> list[str]:
    real = shutil.which('ros2', path=env.get('PATH'))
    if real:
        return [real, 'run', package, executable, *args]
    return [str(find_executable(package, executable, env)), *args]


def ros2_run(*commands: Sequence[str], seconds: float = 5.0,
             workspace_path: Optional[PathLike] = None) -> list[int]:
    """Start executables like ``ros2 run PKG EXE`` (one terminal each), then press Ctrl+C.

    Each runs as its own process in the sourced workspace environment; their output is
    shown here as it comes (prefixed ``[EXE-N]`` when there are several, as ``ros2 launch``
    does).  Once every process has printed its first line (it has started, however busy
    the machine is), they run ``seconds`` more, then each gets SIGINT, exactly what Ctrl+C
    sends.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :param commands: one or more ``(package, executable, *args)`` tuples.
    :param seconds: wall-clock seconds they run, once each has printed a line, before SIGINT.
    :param workspace_path: the workspace; ``None`` is the current one.
    :return: the exit codes, in order (0 is a clean exit; negative is a signal number).
    :raises Ros2nbError: ``Package 'PKG' not found`` / ``No executable found`` (the CLI's
        texts), or an unbuilt workspace.
    """
    if not commands or not all(isinstance(c, (tuple, list)) and len(c) >= 2 for c in commands):
        raise UsageError("Give one tuple per process, e.g. ros2_run(('sensor_simulator', "
                         "'temperature_publisher'), seconds=5).")
    env = source_workspace(workspace_path)
    env = node_process_env(env)
    env.setdefault('ROS_LOG_DIR', str(workspace_or_current(workspace_path) / 'log' / 'ros'))
    argvs = [_command(c[0], c[1], list(c[2:]), env) for c in commands]
    return run_and_interrupt(*argvs, labels=[c[1] for c in commands], seconds=seconds, env=env)


class _KernelNodes:
    """Keeps the kernel's own nodes running, their log lines in order, while processes run.

    On wall-clock time they run anyway; on simulated time their clock is moved on with the
    wall clock, so that they and the processes (which run on the wall clock) meet.
    """

    def __init__(self) -> None:
        rt = runtime.kernel_runtime()
        self.rt = rt if rt is not None and rt.alive and rt.nodes else None
        self.last = time.monotonic()
        if self.rt is not None:
            clock = ('their simulated clock following the wall clock' if self.rt.sim_time
                     else 'on the wall clock')
            print(f'(the nodes in this kernel, {", ".join(sorted(self.rt.nodes))}, keep running '
                  f'meanwhile, {clock})')

    def tick(self) -> None:
        if self.rt is None or not self.rt.alive:
            return
        now = time.monotonic()
        if self.rt.sim_time:
            self.rt.advance_sim_time(now - self.last)
        self.last = now
        self.rt.print_pending()


def run_and_interrupt(*argvs: Sequence[str], labels: Optional[Sequence[str]] = None,
                      seconds: float = 5.0, env: Optional[dict[str, str]] = None) -> list[int]:
    """Run commands as separate processes, show their output, then send SIGINT (Ctrl+C).

    What :func:`ros2_run` does once it has found the executables; use it for a script,
    e.g. ``run_and_interrupt(['python3', 'scripts/demo.py'], seconds=3)``.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :param argvs: one argument list per process.
    :param labels: names for the output prefixes and exit lines; default each argv's
        file name.
    :param seconds: wall-clock seconds they run, once each has printed a line (or after
        :data:`START_UP_S` at most), before SIGINT.
    :param env: the processes' environment; default the kernel's, with unbuffered output
        and the course's console format.
    :return: the exit codes, in order (0 is a clean exit; negative is a signal number).
    """
    if env is None:
        env = node_process_env(os.environ)
    labels = list(labels) if labels is not None else [Path(a[0]).name for a in argvs]
    lines: queue.Queue[tuple[int, Optional[str]]] = queue.Queue()
    procs = []
    said: list[list[str]] = [[] for _ in argvs]  # each process's lines, for its last error
    try:
        for number, (label, argv) in enumerate(zip(labels, argvs), start=1):
            proc = subprocess.Popen(list(argv), env=env, text=True, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            procs.append(proc)
            prefix = f'[{label}-{number}] ' if len(argvs) > 1 else ''
            threading.Thread(target=stream_lines, args=(proc, number - 1, prefix, lines),
                             daemon=True).start()
        _relay(procs, lines, seconds, said)
    except KeyboardInterrupt:
        print('Interrupted: stopping the processes.')
    finally:
        for proc in procs:
            stop_process_group(proc)
    codes = [proc.wait() for proc in procs]
    for label, code, output in zip(labels, codes, said):
        print(f'{label} exited with code {code}')
        mistake = output_mistake(output) if code not in (0, -signal.SIGINT) else None
        if mistake:
            print(f'{label}: {mistake}')
    return codes


def _relay(procs: list[subprocess.Popen[str]], lines: queue.Queue[tuple[int, Optional[str]]],
           seconds: float, said: list[list[str]]) -> None:
    """Print the processes' lines as they come (and keep each one's in ``said``); press
    Ctrl+C for them after ``seconds``.

    The countdown starts when every process has printed a line (or ended), as a person at
    a terminal waits for a program to start before timing it, so a busy machine does not
    decide whether Ctrl+C lands in the start-up; a program that prints nothing gets
    :data:`START_UP_S` (:class:`~ros2nb.patience.Patience`: of its work while it works, of
    the wall clock while it waits).  The kernel's own nodes keep running meanwhile
    (:class:`_KernelNodes`).  Returns when every process has closed its output, or once they
    had :data:`STOP_GRACE_S` after Ctrl+C (patiently too: a slow exit is not a hang).
    """
    open_streams = len(procs)
    started: set[int] = set()
    starting = Patience([proc.pid for proc in procs], START_UP_S)
    deadline: Optional[float] = None
    stopping: Optional[Patience] = None
    kernel_nodes = _KernelNodes()
    while open_streams:
        kernel_nodes.tick()
        if deadline is None and (len(started) == len(procs) or starting.exhausted()):
            deadline = time.monotonic() + seconds
        if stopping is None and deadline is not None and time.monotonic() >= deadline:
            print(f'^C  (ros2nb sent SIGINT after {seconds:g} s, as Ctrl+C does)')
            for proc in procs:
                if proc.poll() is None:
                    signal_group(proc, signal.SIGINT)
            stopping = Patience([proc.pid for proc in procs], STOP_GRACE_S)
        try:
            index, line = lines.get(timeout=0.1)
        except queue.Empty:
            if stopping is not None and stopping.exhausted():
                return
            continue
        started.add(index)
        if line is None:
            open_streams -= 1
        else:
            print(line, flush=True)
            said[index].append(line)
