"""Checks of notebook 05, entry points and run: setup.py, setup.cfg, a build, ``ros2 run``.

Part of :mod:`ros2nb.checks`.  The judge builds a copy of the learner's package with the
real colcon, with its own stand-in nodes in place of the learner's (so only this
notebook's work counts), and reads what setuptools installed.
"""

from __future__ import annotations

import ast
import configparser
import json
import os
import shutil
import subprocess
import sys
from hashlib import sha256
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any, Optional

from .. import course
from ..errors import CheckFailed, Ros2nbError
from ..processes import interrupt, kill_process_group
from ..terminal.colcon import build_cause, venv_tool
from ..terminal.run import find_executable
from .base import ARRIVAL_TIMEOUT_S, Judge, judged
from .mains import EXIT_AFTER_CTRL_C_S, last_line

# ------------------------------------------------------------------ the package
#: The grader's own stand-in nodes, so notebook 05 is graded on its own: they take the
#: place of temperature_publisher.py and temperature_subscriber.py in the judge's build.
#: Each is this program with its node's name and what the node does.
STAND_IN = '''\
"""Grader's stand-in {name}: a node that only {does}."""
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32


def main(args=None):
    rclpy.init(args=args)
    node = Node('{name}')
    {setup}
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''
STAND_IN_PUBLISHER = STAND_IN.format(
    name=course.SENSOR_NODE, does='publishes a constant reading five times a second',
    setup="publisher = node.create_publisher(Float32, 'temperature', 10)\n"
          "    node.create_timer(0.2, lambda: publisher.publish(Float32(data=21.5)))")
STAND_IN_SUBSCRIBER = STAND_IN.format(
    name=course.MONITOR_NODE, does='logs every reading it hears',
    setup="node.create_subscription(Float32, 'temperature',\n"
          "                             lambda m: node.get_logger().info(f'heard {m.data:.2f}'), 10)")
PLACEHOLDER = 'raise NotImplementedError'


def _package_source(judge: Judge) -> Path:
    source = judge.workspace / 'src' / course.PACKAGE
    if not (source / 'package.xml').is_file():
        raise CheckFailed(f'The package {course.PACKAGE} does not exist in your workspace: create '
                          'it (notebook 02, or run the catch_up cell at the top).')
    return source


def _console_scripts(setup_py: Path) -> Optional[list[Any]]:
    """The ``console_scripts`` list of ``setup(entry_points=...)`` as written, or None."""
    try:
        tree = ast.parse(setup_py.read_text())
    except (SyntaxError, OSError):
        return None  # the build says where
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts' \
                        and isinstance(value, ast.List):
                    return value.elts
    return None


def _entry_point_syntax_verdict(setup_py: Path) -> None:
    """Each console_scripts string must read ``NAME = package.module:function``."""
    for element in _console_scripts(setup_py) or []:
        if not (isinstance(element, ast.Constant) and isinstance(element.value, str)):
            continue
        entry = element.value
        if entry.count('=') > 1:
            raise CheckFailed(f'"{entry[:70]}..." is two entries run together: end each string '
                              'in the console_scripts list with a comma.')
        name, _, target = entry.partition('=')
        match = EntryPoint.pattern.match(target.strip()) if name.strip() else None
        if match is None or not match.group('attr'):
            raise CheckFailed(f'"{entry}" is not written NAME = package.module:function: the '
                              'module is written with dots, like an import, without .py, and '
                              'the function follows a colon.')


def _built(judge: Judge) -> Path:
    """Build a copy of the learner's package, with the grader's stand-in nodes; cached.

    :return: the copy's workspace (with ``install/``).
    :raises CheckFailed: with the build's cause in one line.
    """
    source = _package_source(judge)
    # Links are copied as links, never followed: a link to a file only the judge may read
    # would otherwise put that file's text in the build, where the learner's setup.py runs.
    files = sorted(p for p in source.rglob('*') if '__pycache__' not in p.parts
                   and (p.is_symlink() or p.is_file()))
    digest = sha256(b''.join(p.relative_to(source).as_posix().encode()
                             + (os.readlink(p).encode() if p.is_symlink() else p.read_bytes())
                             for p in files)).hexdigest()[:12]
    if digest in judge.builds:
        return judge.builds[digest]
    for name in ('setup.py', 'setup.cfg'):
        if (source / name).is_file() and PLACEHOLDER in (source / name).read_text():
            raise CheckFailed(f'{name} still holds the placeholder "raise NotImplementedError()": '
                              'replace it with your lines and run that cell again.')
    _entry_point_syntax_verdict(source / 'setup.py')
    ws = judge.scratch / f'build-{digest}'
    package = ws / 'src' / course.PACKAGE
    shutil.copytree(source, package, symlinks=True,
                    ignore=shutil.ignore_patterns('__pycache__', '*.egg-info'))
    for module, text in ((course.PUBLISHER_EXECUTABLE, STAND_IN_PUBLISHER),
                         (course.SUBSCRIBER_EXECUTABLE, STAND_IN_SUBSCRIBER)):
        (package / course.PACKAGE / f'{module}.py').write_text(text)
    colcon = venv_tool('colcon')
    if colcon is None:
        raise Ros2nbError('colcon is not installed: run `make lab` or `make test`.')
    code, output = judge.run([colcon, 'build'], seconds=300, cwd=ws)
    if code != 0:
        raise CheckFailed(f'colcon build of your package failed: '
                          f'{build_cause(output.splitlines())}')
    judge.builds[digest] = ws
    return ws


def _entry_points(judge: Judge) -> str:
    ws = _built(judge)
    found = sorted(ws.glob(f'install/{course.PACKAGE}/lib/python*/site-packages/'
                           f'{course.PACKAGE}*-info/entry_points.txt'))
    scripts: dict[str, str] = {}
    if found:
        config = configparser.ConfigParser(interpolation=None)  # data, never %(name)s
        try:
            config.read(found[0])
        except configparser.Error as error:
            raise CheckFailed(f'The entry points setuptools installed cannot be read: '
                              f'{str(error).splitlines()[0][:160]}; write each as '
                              f"'name = {course.PACKAGE}.module:main'.") from None
        if config.has_section('console_scripts'):
            scripts = {k: v.strip() for k, v in config.items('console_scripts')}
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        want = f'{course.PACKAGE}.{executable}:main'
        if executable not in scripts:
            have = ', '.join(f'{k} = {v}' for k, v in sorted(scripts.items())) or 'none'
            raise CheckFailed(f'console_scripts has no entry named {executable} (it has: {have}); '
                              'the name left of = is what you pass to ros2 run.')
        if scripts[executable].replace(' ', '') != want:
            raise CheckFailed(f'{executable} = {scripts[executable]}: it should start main() in '
                              f'{course.PACKAGE}/{executable}.py, written {want}.')
    return (f'console_scripts gives {course.PUBLISHER_EXECUTABLE} and '
            f'{course.SUBSCRIBER_EXECUTABLE}, each starting main() of its module.')


def check_entry_points() -> None:
    """Check the ``console_scripts`` entry points in ``setup.py`` (notebook 05).

    Builds a copy of your package with colcon (the grader's stand-in nodes take the place
    of your two node files, so only this notebook's work counts) and reads the entry
    points setuptools installed.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the missing or wrong entry, or the build's cause.
    """
    judged('check_entry_points', _entry_points)


def _setup_cfg(judge: Judge) -> str:
    file = _package_source(judge) / 'setup.cfg'
    if not file.is_file():
        raise CheckFailed('setup.cfg is missing: without it ros2 run finds no executable; '
                          'write it (the cell above).')
    text = file.read_text()
    if PLACEHOLDER in text:
        raise CheckFailed('setup.cfg still holds the placeholder "raise NotImplementedError()": '
                          'write the two settings in its place.')
    config = configparser.ConfigParser(interpolation=None)  # the two values as written
    try:
        config.read_string(text)
    except configparser.Error as error:
        raise CheckFailed(f'setup.cfg cannot be read: {str(error).splitlines()[0]}') from None
    want = f'$base/lib/{course.PACKAGE}'
    for section, key in (('develop', 'script_dir'), ('install', 'install_scripts')):
        got = config.get(section, key, fallback=None)
        if got is None:
            raise CheckFailed(f'setup.cfg has no {key} in its [{section}] section; ros2 run '
                              f'looks in {want}.')
        if got.strip() != want:
            raise CheckFailed(f'[{section}] {key} is {got.strip()}; ros2 run looks in {want}.')
    ws = _built(judge)
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        if not (ws / 'install' / course.PACKAGE / 'lib' / course.PACKAGE / executable).is_file():
            raise CheckFailed(f'After the build there is no lib/{course.PACKAGE}/{executable}: '
                              'check the entry points in setup.py.')
    return f'setup.cfg installs the executables into lib/{course.PACKAGE}, where ros2 run looks.'


def check_setup_cfg() -> None:
    """Check ``setup.cfg``: executables go to ``lib/sensor_simulator``, where ros2 run looks.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the setting and the expected value.
    """
    judged('check_setup_cfg', _setup_cfg)


#: What a subject runs in a built workspace: the environment ``source install/setup.bash``
#: gives, printed as one JSON line.
SOURCED_ENV = ('source install/setup.bash >/dev/null 2>&1 || exit 3; exec "$0" -c '
               '"import json, os; print(json.dumps(dict(os.environ)))"')


def _sourced(judge: Judge, ws: Path) -> dict[str, str]:
    """The environment ``source install/setup.bash`` gives in ``ws``, worked out in a subject.

    colcon wrote those scripts, and the hooks they source, in a build that ran the
    learner's setup.py (a package may declare hooks of its own): the judge never runs them
    itself, it reads what they gave as data.
    """
    code, output = judge.run(['bash', '-c', SOURCED_ENV, sys.executable], seconds=60, cwd=ws)
    try:
        env = json.loads(output.splitlines()[-1]) if code == 0 else None
    except (IndexError, ValueError):
        env = None
    if not isinstance(env, dict) or not all(isinstance(v, str) for v in env.values()):
        raise CheckFailed(f'source install/setup.bash failed in the build of your package '
                          f'(exit code {code}): {last_line(output)}')
    return env


def _package_runs(judge: Judge) -> str:
    ws = _built(judge)
    env = _sourced(judge, ws)
    argvs = []
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        try:
            argvs.append([str(find_executable(course.PACKAGE, executable, env))])
        except Ros2nbError as error:
            raise CheckFailed(f'ros2 run {course.PACKAGE} {executable}: {error}') from None
    env.update({k: v for k, v in judge.subject_env().items()  # the judge's domain and transports,
                if k.startswith(('ROS_', 'RCUTILS', 'FASTDDS', 'PYTHONUNBUFFERED'))  # the
                or k in ('HOME', 'TMPDIR')})  # subjects' home and temporary folder
    observer = judge.observer
    mark = len(observer.logs)
    started = [judge.start(argv, cwd=ws, env=env) for argv in argvs]
    procs, outputs = [proc for proc, _ in started], [output for _, output in started]
    try:
        heard = observer.wait_until(lambda: observer.lines_of(course.MONITOR_NODE, mark),
                                    ARRIVAL_TIMEOUT_S)
        for proc in procs:
            interrupt(proc)
        codes = []
        for proc in procs:
            try:
                codes.append(proc.wait(EXIT_AFTER_CTRL_C_S))
            except subprocess.TimeoutExpired:
                codes.append(kill_process_group(proc))
    finally:
        for proc in procs:
            kill_process_group(proc)
    if not heard:
        raise CheckFailed('ros2 run started both executables, but the monitor heard no reading: '
                          f'{last_line(outputs[0].text())}')
    if codes != [0, 0]:
        raise CheckFailed(f'After Ctrl+C the executables exited with {codes}, expected [0, 0].')
    return 'ros2 run starts both entry points; they talk over /temperature and stop on Ctrl+C.'


def check_package_runs() -> None:
    """Hidden test of notebook 05: the built package runs with ``ros2 run``.

    Builds your package (with the grader's stand-in nodes), finds both executables the way
    ``ros2 run`` does, starts them, waits until the monitor hears the sensor, then sends
    Ctrl+C and expects exit code 0 from both.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: with the CLI's error or the exit codes.
    """
    judged('check_package_runs', _package_runs)
