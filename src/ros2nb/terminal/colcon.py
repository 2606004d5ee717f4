"""``colcon build`` (always the real colcon) and ``source install/setup.bash``, from a notebook.

Introduced in ``02-create-a-package.ipynb``.  No ROS import.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Optional

from ..errors import ColconBuildError, Ros2nbError
from .workspace import PathLike, shown, workspace_or_current


def venv_tool(name: str) -> Optional[str]:
    """The program ``name`` beside this Python (the course's venv), else the one on PATH."""
    beside = Path(sys.executable).with_name(name)
    return str(beside) if beside.is_file() else shutil.which(name)


_PY_ERROR = re.compile(r'^\s*(\w+(Error|Exception)): ')
_PY_FILE = re.compile(r'^\s*File "([^"]+)", line (\d+)')


def build_cause(output: list[str]) -> str:
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
    ws = workspace_or_current(workspace_path)
    colcon = venv_tool('colcon')
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
        raise ColconBuildError(f'colcon build failed (exit code {code}): {build_cause(output)}')
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
    ws = workspace_or_current(workspace_path)
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
