"""The tutorial's terminal steps, from a notebook: workspace, files, colcon, source, ros2 run.

Introduced in ``01-create-a-workspace.ipynb``.

``colcon`` is always the real colcon.  ``ros2 run`` is the real ``ros2`` when one is on
PATH; otherwise ros2nb resolves the executable the way ``ros2 run`` does (ament index,
then ``<prefix>/lib/<package>/<executable>``) with the same error texts.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import json
import os
import queue
import re
import shlex
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path
from types import ModuleType
from typing import Iterable, Iterator, Mapping, Optional, Sequence, Union

from . import domains
from .errors import ColconBuildError, FileProtectedError, Ros2nbError, UsageError
from .processes import STOP_GRACE_S, signal_group, stop_process_group

PathLike = Union[str, os.PathLike]

#: Environment variable that moves the course workspace (tests point it at a temp dir).
WORKSPACE_ENV = 'ROS2NB_WORKSPACE'
#: The tutorial's workspace name.
WORKSPACE_NAME = 'ROS2_and_RL_Tutorials'
#: Folders the tutorial creates with ``mkdir -p src docs scripts resources/images``.
WORKSPACE_FOLDERS = ('src', 'docs', 'scripts', 'resources/images')
#: Where ros2nb records what it wrote, so it never overwrites a file you edited.
WRITTEN_RECORD = '.ros2nb-written.json'
#: Where ``%%part`` keeps the parts of each file, so a kernel restart loses none.
PARTS_RECORD = '.ros2nb-parts.json'
#: nbgrader's marker lines around an answer in the course's own notebooks; not part of a file.
AUTHOR_MARKERS = ('### BEGIN SOLUTION', '### END SOLUTION')
#: Console format for processes started by ros2nb (timestamps removed, as in the kernel).
CONSOLE_FORMAT = '[{severity}] [{name}]: {message}'

_current: Optional[Path] = None


def course_root() -> Path:
    """Return the course repository's root (the folder with ``pyproject.toml``), or the cwd."""
    here = Path.cwd().resolve()
    for folder in (here, *here.parents):
        if (folder / 'pyproject.toml').is_file() and (folder / 'solutions').is_dir():
            return folder
    return here


def default_workspace() -> Path:
    """Return ``$ROS2NB_WORKSPACE`` or ``<course>/workspace/ROS2_and_RL_Tutorials``."""
    configured = os.environ.get(WORKSPACE_ENV)
    if configured:
        return Path(configured).expanduser().resolve()
    return course_root() / 'workspace' / WORKSPACE_NAME


def current_workspace() -> Path:
    """Return the workspace the workspace verbs use (the last one created, else the default).

    Introduced in ``01-create-a-workspace.ipynb``.
    """
    return _current if _current is not None else default_workspace()


def workspace_file(path: PathLike) -> Path:
    """Return ``path`` with ``~`` expanded; a relative path is taken inside the current workspace."""
    path = Path(path).expanduser()
    return path if path.is_absolute() else current_workspace() / path


def _workspace_or_current(workspace_path: Optional[PathLike]) -> Path:
    return Path(workspace_path) if workspace_path is not None else current_workspace()


def shown(path: PathLike) -> str:
    """Return ``path`` as ``<workspace name>/...`` when inside the workspace (same on every machine)."""
    path = Path(path).resolve()
    ws = current_workspace().resolve()
    try:
        return str(Path(ws.name) / path.relative_to(ws))
    except ValueError:
        return str(path)


def create_workspace(path: Optional[PathLike] = None, *,
                     folders: Sequence[str] = WORKSPACE_FOLDERS,
                     allow_outside_course: bool = False) -> Path:
    """Create the workspace and its folders like ``mkdir -p``, and make it the current one.

    Existing folders and files are left as they are, so running it twice is harmless.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param path: where to create it; ``~`` is expanded.  ``None`` uses
        :func:`default_workspace`, a git-ignored folder of the course.
    :param folders: sub-folders to create, relative to the workspace.
    :param allow_outside_course: ``True`` to create it outside the course folder,
        e.g. ``'~/Documents/ROS2_and_RL_Tutorials'``.
    :return: the workspace's absolute path.
    :raises Ros2nbError: if the path is outside the course and you did not allow it, or a
        file stands where a folder should be.
    """
    global _current
    target = default_workspace() if path is None else Path(path).expanduser().resolve()
    root = course_root()
    if path is not None and not allow_outside_course and root not in (target, *target.parents):
        raise Ros2nbError(f'{target} is outside the course folder {root}; pass '
                          'allow_outside_course=True if that is where you want it.')
    for folder in ('.', *folders):
        where = target / folder
        if where.exists() and not where.is_dir():
            raise Ros2nbError(f'{where} exists and is a file, not a folder: move it away and '
                              'run this cell again.')
        where.mkdir(parents=True, exist_ok=True)
    _current = target
    return target


def tree(path: Optional[PathLike] = None, *, skip: Iterable[str] = ('build', 'install', 'log',
                                                                    '__pycache__')) -> None:
    """Print a folder as an indented tree, folders first, sorted (like ``tree``).

    Introduced in ``01-create-a-workspace.ipynb``.

    :param path: the folder; ``None`` is the current workspace.
    :param skip: folder names whose contents are not listed.
    """
    top = Path(path) if path is not None else current_workspace()
    if not top.is_dir():
        raise Ros2nbError(f'{top} is not a folder: create it first.')
    print(shown(top) + '/')

    def walk(folder: Path, depth: int) -> None:
        entries = sorted(p for p in folder.iterdir() if not p.name.startswith('.'))
        for entry in sorted(entries, key=lambda p: (not p.is_dir(), p.name)):
            print('    ' * depth + entry.name + ('/' if entry.is_dir() else ''))
            if entry.is_dir() and entry.name not in skip:
                walk(entry, depth + 1)

    walk(top, 1)


# ------------------------------------------------------------------ protected files
def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def _record_path(path: Path) -> Optional[Path]:
    """The workspace's record file, or None for files outside the workspace (not recorded)."""
    ws = current_workspace().resolve()
    return ws / WRITTEN_RECORD if ws in path.resolve().parents else None


def write_file(path: PathLike, text: str, *, overwrite: bool = False) -> Path:
    """Write a source file, never overwriting changes you made to it yourself.

    A file ros2nb wrote earlier and nobody changed since is replaced; a file you edited
    (or that ros2nb did not write) is only replaced with ``overwrite=True``, and then
    your version is kept beside it as ``<name>.bak``.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the file; relative paths are relative to the current workspace.
    :param text: the new contents.
    :param overwrite: replace the file even if you changed it.
    :return: the file's absolute path.
    :raises FileProtectedError: if the file has changes of yours and ``overwrite`` is false.
    """
    path = workspace_file(path)
    if path.is_file():
        current = path.read_text()
        if current != text and _load_record(path).get(str(path.resolve())) != _digest(current):
            if not overwrite:
                raise FileProtectedError(
                    f'{shown(path)} has changes that ros2nb did not write; to keep them do '
                    'nothing, to replace them run again with overwrite=True, or add --overwrite to the %%part line (your version '
                    'is then kept as .bak).')
            shutil.copy2(path, path.with_name(path.name + '.bak'))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    remember_written(path)
    return path.resolve()


def _load_record(path: Path) -> dict[str, str]:
    record_file = _record_path(path)
    return json.loads(record_file.read_text()) if record_file and record_file.is_file() else {}


def remember_written(path: PathLike) -> None:
    """Record that ros2nb wrote ``path`` as it is now, so a later write may replace it.

    Only files inside the current workspace are recorded; others are never replaced
    without ``overwrite=True``.
    """
    path = Path(path).resolve()
    record_file = _record_path(path)
    if record_file is None:
        return
    record = _load_record(path)
    record[str(path)] = _digest(path.read_text())
    record_file.write_text(json.dumps(record, indent=1, sort_keys=True) + '\n')


def import_file(path: PathLike, module_name: Optional[str] = None) -> ModuleType:
    """Import a Python file afresh (re-running the cell picks up your latest edits).

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the ``.py`` file; relative paths are relative to the current workspace.
    :param module_name: name to register in ``sys.modules``; default the file's stem.
    :return: the module.
    :raises Ros2nbError: if the file does not exist.
    :raises SyntaxError: (and anything the file raises at import) unchanged, with its line.
    """
    path = workspace_file(path)
    if not path.is_file():
        raise Ros2nbError(f'{shown(path)} does not exist: run the cells that write it first.')
    name = module_name or path.stem
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


_parts_outside: dict[str, dict[int, str]] = {}  # files outside the workspace: this kernel only


@contextlib.contextmanager
def _parts_of(path: Path) -> Iterator[dict[int, str]]:
    """The stored parts of ``path`` (kept in the workspace, so a kernel restart loses none).

    Changes made inside the block are saved when it ends without an error.
    """
    ws = current_workspace().resolve()
    resolved = path.resolve()
    if ws not in resolved.parents:
        yield _parts_outside.setdefault(str(resolved), {})
        return
    record_file = ws / PARTS_RECORD
    record = json.loads(record_file.read_text()) if record_file.is_file() else {}
    key = str(resolved.relative_to(ws))
    parts = {int(n): text for n, text in record.get(key, {}).items()}
    yield parts
    record[key] = {str(n): parts[n] for n in sorted(parts)}
    record_file.write_text(json.dumps(record, indent=1, sort_keys=True) + '\n')


def write_part(path: PathLike, number: int, text: str, *, overwrite: bool = False) -> Path:
    """Set part ``number`` of a source file and write the file from all its parts.

    Parts are joined in number order with one blank line between them, so cells can be
    re-run in any order.  nbgrader's answer markers (``### BEGIN SOLUTION``) are left out.  The parts are kept in the workspace (``.ros2nb-parts.json``),
    so after a kernel restart re-running one part keeps all the others.  Like
    :func:`write_file`, it never overwrites a file you changed in an editor.  Used by the
    ``%%part FILE N`` cell magic (``%load_ext ros2nb``).

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the file, as for :func:`write_file`.
    :param number: the part's position (1, 2, ...).
    :param text: the part's source code.
    :param overwrite: as for :func:`write_file`.
    :return: the file's absolute path.
    :raises FileProtectedError: as :func:`write_file`.
    """
    if isinstance(number, bool) or not isinstance(number, int) or number < 1:
        raise UsageError(f'A part number is a whole number from 1 up (got {number!r}).')
    text = '\n'.join(line for line in text.split('\n') if line.strip() not in AUTHOR_MARKERS)
    resolved = workspace_file(path)
    with _parts_of(resolved) as parts:
        replaces = resolved.is_file() and not parts
        new_parts = {**parts, number: text.rstrip('\n') + '\n'}
        written = write_file(resolved, '\n\n'.join(new_parts[n].rstrip('\n')
                                                   for n in sorted(new_parts)) + '\n',
                             overwrite=overwrite)
        parts.clear()
        parts.update(new_parts)
    lines = written.read_text().count('\n')
    print(f'{shown(written)}: part {number} saved (parts {", ".join(map(str, sorted(parts)))}; '
          f'{lines} lines)' + (' (it replaces the file ros2nb wrote there before)' if replaces
                               else ''))
    return written


# ----------------------------------------------------------------------------- colcon
def _venv_tool(name: str) -> Optional[str]:
    beside = Path(sys.executable).with_name(name)
    return str(beside) if beside.is_file() else shutil.which(name)


def _stream(proc: subprocess.Popen, prefix: str, lines: queue.Queue) -> None:
    assert proc.stdout is not None
    for line in proc.stdout:
        lines.put(prefix + line.rstrip('\n'))
    lines.put(None)


_PY_ERROR = re.compile(r'^\s*(\w+(Error|Exception)): ')
_PY_FILE = re.compile(r'^\s*File "([^"]+)", line (\d+)')


def _build_cause(output: list[str]) -> str:
    """Pick the line of a failed colcon build that names the cause.

    A Python error of the package (e.g. ``SyntaxError`` in setup.py) wins over colcon's
    own ``CalledProcessError`` that wraps it; its file and line are added.
    """
    for index in range(len(output) - 1, -1, -1):
        match = _PY_ERROR.match(output[index])
        if match and match.group(1) != 'CalledProcessError':
            where = next((m for m in (_PY_FILE.match(line) for line in
                                      reversed(output[:index])) if m), None)
            place = f' ({Path(where.group(1)).name}, line {where.group(2)})' if where else ''
            return output[index].strip() + place
    for marker in ('ERROR', 'error:', 'Error'):
        for line in reversed(output):
            if marker in line and not line.startswith(('Failed', 'Summary')):
                return line.strip()
    return 'see the output above'


def colcon_build(*args: str, workspace_path: Optional[PathLike] = None) -> None:
    """Run the real ``colcon build`` in the workspace and show its output in this cell.

    Introduced in ``02-create-a-package.ipynb``.

    :param args: extra arguments, e.g. ``'--packages-select', 'sensor_simulator'``.
    :param workspace_path: the workspace; ``None`` is the current one.
    :raises ColconBuildError: with the cause in one line when the build fails or builds
        nothing.
    :raises Ros2nbError: if colcon is not installed or the workspace has no ``src``.
    """
    ws = _workspace_or_current(workspace_path)
    colcon = _venv_tool('colcon')
    if colcon is None:
        raise Ros2nbError('colcon is not installed: run `make lab` (it installs '
                          'colcon-common-extensions from environment/requirements.txt).')
    if not (ws / 'src').is_dir():
        raise Ros2nbError(f'{ws} has no src/ folder: is it a workspace? Run '
                          'ros2nb.create_workspace() first (notebook 01).')
    env = dict(os.environ, PYTHONUNBUFFERED='1')
    proc = subprocess.Popen([colcon, 'build', *args], cwd=ws, env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output = []
    assert proc.stdout is not None
    for line in proc.stdout:
        output.append(line.rstrip('\n'))
        print(line, end='')
    code = proc.wait()
    if code != 0:
        raise ColconBuildError(f'colcon build failed (exit code {code}): {_build_cause(output)}')
    if any(line.startswith('Summary: 0 packages finished') for line in output):
        raise ColconBuildError('colcon build found no package to build: check the package '
                               'name in --packages-select and that src/ holds a package.')


def source_workspace(workspace_path: Optional[PathLike] = None, *,
                     show: bool = False) -> dict[str, str]:
    """Return the environment that ``source install/setup.bash`` gives a terminal.

    It runs the real ``setup.bash`` in bash; the kernel's own environment is unchanged.

    Introduced in ``02-create-a-package.ipynb``.

    :param workspace_path: the workspace; ``None`` is the current one.
    :param show: print the variables that sourcing changed (paths shown per entry).
    :return: the full environment after sourcing.
    :raises Ros2nbError: if the workspace has not been built yet.
    """
    ws = _workspace_or_current(workspace_path)
    setup = ws / 'install' / 'setup.bash'
    if not setup.is_file():
        raise Ros2nbError(f'{shown(setup)} does not exist yet: run ros2nb.colcon_build() '
                          'in the workspace first.')
    done = subprocess.run(['bash', '-c', f'source {shlex.quote(str(setup))} && env -0'],
                          capture_output=True, text=True, check=False, env=dict(os.environ))
    if done.returncode != 0:
        raise Ros2nbError(f'source {shown(setup)} failed: {done.stderr.strip()}')
    env = dict(item.split('=', 1) for item in done.stdout.split('\0') if '=' in item)
    if show:
        for name in sorted(env):
            before = os.environ.get(name)
            if name.startswith(('COLCON', 'AMENT', 'PYTHONPATH', 'CMAKE', 'LD_LIBRARY', 'PATH')) \
                    and env[name] != before:
                old = set((before or '').split(os.pathsep))
                new = [p for p in env[name].split(os.pathsep) if p and p not in old]
                print(f'{name}: added ' + (', '.join(shown(p) if os.path.isabs(p) else p
                                                     for p in new) or env[name]))
    return env


# ------------------------------------------------------------------------- ros2 run
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
    from ament_index_python.packages import PackageNotFoundError, get_package_prefix
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
    does).  After ``seconds`` every process gets SIGINT, exactly what Ctrl+C sends.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :param commands: one or more ``(package, executable, *args)`` tuples.
    :param seconds: wall-clock seconds before SIGINT.
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
    env.setdefault('ROS_LOG_DIR', str(_workspace_or_current(workspace_path) / 'log' / 'ros'))
    argvs = [_command(c[0], c[1], list(c[2:]), env) for c in commands]
    return run_and_interrupt(*argvs, labels=[c[1] for c in commands], seconds=seconds, env=env)


class _KernelNodes:
    """Keeps the kernel's own nodes running, their log lines in order, while processes run.

    On wall-clock time they run anyway; on simulated time their clock is moved on with the
    wall clock, so that they and the processes (which run on the wall clock) meet.
    """

    def __init__(self) -> None:
        from . import runtime
        rt = runtime._runtime
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
    :param seconds: wall-clock seconds before SIGINT.
    :param env: the processes' environment; default the kernel's, with unbuffered output
        and the course's console format.
    :return: the exit codes, in order (0 is a clean exit; negative is a signal number).
    """
    if env is None:
        env = node_process_env(os.environ)
    labels = list(labels) if labels is not None else [Path(a[0]).name for a in argvs]
    lines: queue.Queue = queue.Queue()
    procs = []
    try:
        for number, (label, argv) in enumerate(zip(labels, argvs), start=1):
            proc = subprocess.Popen(list(argv), env=env, text=True, stdout=subprocess.PIPE,
                                    stderr=subprocess.STDOUT, start_new_session=True)
            procs.append(proc)
            prefix = f'[{label}-{number}] ' if len(argvs) > 1 else ''
            threading.Thread(target=_stream, args=(proc, prefix, lines), daemon=True).start()
        open_streams = len(procs)
        deadline = time.monotonic() + seconds
        interrupted = False
        kernel_nodes = _KernelNodes()
        while open_streams:
            kernel_nodes.tick()
            if not interrupted and time.monotonic() >= deadline:
                interrupted = True
                print(f'^C  (ros2nb sent SIGINT after {seconds:g} s, as Ctrl+C does)')
                for proc in procs:
                    if proc.poll() is None:
                        signal_group(proc, signal.SIGINT)
            try:
                line = lines.get(timeout=0.1)
            except queue.Empty:
                if interrupted and time.monotonic() > deadline + STOP_GRACE_S:
                    break
                continue
            if line is None:
                open_streams -= 1
            else:
                print(line, flush=True)
    except KeyboardInterrupt:
        print('Interrupted: stopping the processes.')
    finally:
        for proc in procs:
            stop_process_group(proc)
    codes = [proc.wait() for proc in procs]
    for label, code in zip(labels, codes):
        print(f'{label} exited with code {code}')
    return codes
