"""Checks of notebook 05, entry points and run: setup.py, setup.cfg, a build, ``ros2 run``.

Part of :mod:`ros2nb.checks`.  The judge builds a copy of the learner's package with colcon
and its own stand-in nodes in place of the learner's, finds each executable the way ``ros2
run`` does and starts it.  An entry point counts when ``ros2 run`` starts the stand-in: the
sensor publishes a number the judge chose (a parameter on the command line), the monitor
logs a number the judge published, and both stop cleanly on Ctrl+C.  What setuptools wrote
is never evidence; the learner's files, read as text, only word a failure.  The course's
``setup.cfg`` stands in while ``setup.py`` is graded, and the other way round.
"""

from __future__ import annotations

import ast
import configparser
from pathlib import Path
from typing import Any, Optional

from std_msgs.msg import Float32

from .. import course
from ..errors import CheckFailed, Ros2nbError
from ..processes import interrupt, kill_process_group, until_waiting, wait_patiently
from ..terminal.files import saved_parts
from ..terminal.run import find_executable
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge
from .base import judged
from .drawn import chooser
from .mains import EXIT_AFTER_CTRL_C_S, last_line
from .package_builds import (DASHED, PLACEHOLDER, build_copy, console_scripts, course_setup_cfg,
                             course_setup_py, entry_point_syntax_cause, package_source, sourced)
from .package_stand_ins import EXECUTABLES
from .source import TEXT

def _ros2_run(judge: Judge, ws: Path, env: dict[str, str], executable: str,
              *args: str) -> tuple[Any, Any]:
    """``ros2 run sensor_simulator EXECUTABLE ARGS`` in the build ``ws``: started, not waited for.

    :raises CheckFailed: with the CLI's own error (``No executable found``, ...).
    """
    try:
        path = find_executable(course.PACKAGE, executable, env)
    except Ros2nbError as error:
        raise CheckFailed(f'ros2 run {course.PACKAGE} {executable}: {error}') from None
    return judge.start([str(path), *args], cwd=ws, env=env)


def _stop(procs: list[Any]) -> list[Optional[int]]:
    """Ctrl+C for each process, once it sits idle in its spin; their exit codes (None: one
    had to be killed)."""
    for proc in procs:
        until_waiting(proc, EXIT_AFTER_CTRL_C_S)
        interrupt(proc)
    codes = [wait_patiently(proc, EXIT_AFTER_CTRL_C_S) for proc in procs]
    for proc, code in zip(procs, codes):
        if code is None:
            kill_process_group(proc)
    return codes


def _runs(judge: Judge, ws: Path) -> Optional[str]:
    """Start both executables of the build ``ws`` as ``ros2 run`` does and watch them work:
    the sensor publishes the reading the judge gave it on its command line, and the monitor
    logs that reading when it hears it; then Ctrl+C.  Return what went wrong, in one line
    (None: both ran as they should)."""
    env = sourced(judge, ws)
    observer = judge.observer
    readings = observer.watch('/' + course.TOPIC, Float32, lambda m: float(m.data))
    given = round(chooser(judge, '05 package runs').uniform(19.0, 25.0), 3)
    heard = f'heard {given:.3f}'
    first, mark = len(readings), len(observer.logs)
    procs: list[Any] = []
    try:
        try:
            procs.append(_ros2_run(judge, ws, env, course.PUBLISHER_EXECUTABLE,
                                   '--ros-args', '-p', f'reading:={given}'))
            procs.append(_ros2_run(judge, ws, env, course.SUBSCRIBER_EXECUTABLE))
        except CheckFailed as problem:
            return str(problem)
        (sensor, sensor_out), (monitor, monitor_out) = procs
        observer.wait_until(lambda: heard in observer.lines_of(course.MONITOR_NODE, mark)
                            or sensor.poll() is not None or monitor.poll() is not None,
                            ARRIVAL_TIMEOUT_S)
        if heard not in observer.lines_of(course.MONITOR_NODE, mark):
            # the grader's stand-in there would have published the reading, or logged it
            if not any(round(h.value, 3) == given for h in readings[first:]):
                name, out = course.PUBLISHER_EXECUTABLE, sensor_out
            else:
                name, out = course.SUBSCRIBER_EXECUTABLE, monitor_out
            return (f'ros2 run {course.PACKAGE} {name} did not start main() of '
                    f'{course.PACKAGE}.{name} ({last_line(out.text())}).')
        codes = _stop([sensor, monitor])
        procs.clear()
    finally:
        for proc, _out in procs:
            kill_process_group(proc)
    for name, out, code in ((course.PUBLISHER_EXECUTABLE, sensor_out, codes[0]),
                            (course.SUBSCRIBER_EXECUTABLE, monitor_out, codes[1])):
        if code != 0:
            return (f'After Ctrl+C, ros2 run {course.PACKAGE} {name} exited with '
                    f'{"no exit (killed)" if code is None else f"code {code}"}, expected 0 '
                    f'({last_line(out.text())}).')
    return None


def _entries_cause(setup_py: Path) -> Optional[str]:
    """What the console_scripts of setup.py, read as text, lack or get wrong (to word a
    failure the judge saw), or None."""
    syntax = entry_point_syntax_cause(setup_py)
    if syntax is not None:
        return syntax
    written = [e.value for e in console_scripts(setup_py) or []
               if isinstance(e, ast.Constant) and isinstance(e.value, str)]
    scripts = {name.strip(): target.strip() for name, _, target in
               (entry.partition('=') for entry in written)}
    for executable, _text in EXECUTABLES:
        want = f'{course.PACKAGE}.{executable}:main'
        if executable not in scripts:
            have = ', '.join(f'{k} = {v}' for k, v in sorted(scripts.items())) or 'none'
            return (f'console_scripts has no entry named {executable} (it has: {have}); the name '
                    'left of = is what you pass to ros2 run.')
        target = scripts[executable].replace(' ', '')
        if target != want:
            if target.partition(':')[0] != f'{course.PACKAGE}.{executable}':
                return (f'{executable} = {scripts[executable]}: it should start main() in '
                        f'{course.PACKAGE}/{executable}.py; left of the colon, name that file '
                        'as a module (package.module: dots, no .py).')
            return (f'{executable} = {scripts[executable]}: right of the colon goes the function '
                    f'that starts the node, main, as {executable}.py defines it.')
    return None


def _entry_points(judge: Judge) -> str:
    problem = _runs(judge, build_copy(judge))
    if problem is not None:  # with the course's setup.cfg, setup.py alone counts
        problem = _runs(judge, build_copy(judge, setup_cfg=course_setup_cfg()))
    if problem is not None:
        cause = _entries_cause(package_source(judge) / 'setup.py')
        raise CheckFailed(f'{problem.rstrip(".")}: {cause}' if cause else problem)
    return (f'ros2 run starts main() of {course.PUBLISHER_EXECUTABLE} and of '
            f'{course.SUBSCRIBER_EXECUTABLE} from your console_scripts.')


@judged
def check_entry_points(judge: Judge) -> str:
    """Check the ``console_scripts`` entry points in ``setup.py`` (notebook 05).

    Builds a copy of your package with colcon (the grader's stand-in nodes take the place
    of your two node files, so only this notebook's work counts) and starts each executable
    as ``ros2 run`` does: each must start its stand-in's ``main()``, which the grader sees at
    work, and stop on Ctrl+C.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the executable that did not start, or the build's cause.
    """
    return _entry_points(judge)


def _setup_cfg_cause(judge: Judge) -> Optional[str]:
    """What setup.cfg, read as text, sets differently (to word a failure the judge saw)."""
    file = package_source(judge) / 'setup.cfg'
    if not file.is_file():
        return ('setup.cfg is missing: without it ros2 run finds no executable; write it '
                '(the cell above).')
    config = configparser.ConfigParser(interpolation=None)  # the two values as written
    try:
        config.read_string(TEXT.read(file) or '')
    except configparser.Error as error:
        return f'setup.cfg cannot be read: {str(error).splitlines()[0]}'
    want = f'$base/lib/{course.PACKAGE}'
    for section, key in (('develop', 'script_dir'), ('install', 'install_scripts')):
        got = config.get(section, key, fallback=None)
        if got is None:
            return f'setup.cfg has no {key} in its [{section}] section; ros2 run looks in {want}.'
        if got.strip().rstrip('/') != want:
            return f'[{section}] {key} is {got.strip()}; ros2 run looks in {want}.'
    return None


def _found_in_development_install(judge: Judge, setup_py: Optional[str]) -> Optional[str]:
    """What ``ros2 run`` says of the package built with ``colcon build --symlink-install``
    (setuptools' development install, which reads ``[develop]``), or None when it finds both
    executables, as after a normal build."""
    ws = build_copy(judge, setup_py=setup_py, symlink=True)
    env = sourced(judge, ws)
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        try:
            find_executable(course.PACKAGE, executable, env)
        except Ros2nbError as error:
            return (f'ros2 run {course.PACKAGE} {executable}: {error}, after colcon build '
                    '--symlink-install.')
    return None


def _setup_cfg(judge: Judge) -> str:
    if PLACEHOLDER in (TEXT.read(package_source(judge) / 'setup.cfg') or '') or \
            saved_parts(judge.workspace, course.SETUP_CFG_FILE) == set():  # its cell: unwritten
        raise CheckFailed('The setup.cfg cell still holds the placeholder "raise '
                          'NotImplementedError()": write the two settings in its place and run it.')
    setup_py: Optional[str] = None
    try:  # the learner's setup.py may be at fault
        problem = _runs(judge, build_copy(judge))
    except CheckFailed as failure:
        problem = str(failure)
    if problem is not None:  # with the course's setup.py, setup.cfg alone counts
        setup_py = course_setup_py()
        problem = _runs(judge, build_copy(judge, setup_py=setup_py))
    built = build_copy(judge, setup_py=setup_py)
    if problem is None:  # a development install reads [develop]: ros2 run finds it too
        problem = _found_in_development_install(judge, setup_py)
    if problem is not None:
        raise CheckFailed(_setup_cfg_cause(judge) or
                          f'{problem} setup.cfg puts the executables where ros2 run looks: '
                          f'$base/lib/{course.PACKAGE}.')
    dashed = DASHED.get(built)
    if dashed:
        raise CheckFailed(f'setup.cfg spells {dashed[0]} with a dash: setuptools reads it with a '
                          'deprecation warning in the build, but a coming release refuses it, as '
                          '78.0.0 did until 78.0.2 took that back (then ros2 run finds nothing): '
                          f'write {dashed[0].replace("-", "_")}.')
    return (f'setup.cfg installs the executables into lib/{course.PACKAGE}, where ros2 run '
            'finds them.')


@judged
def check_setup_cfg(judge: Judge) -> str:
    """Check ``setup.cfg``: executables go to ``lib/sensor_simulator``, where ros2 run looks.

    Builds your package (with the course's setup.py when yours is at fault, so that only
    setup.cfg counts) and starts both executables as ``ros2 run`` does; then again built with
    ``colcon build --symlink-install``, a development install, which reads ``[develop]``
    where a normal build reads ``[install]``.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the setting and the expected value.
    """
    return _setup_cfg(judge)


def _package_runs(judge: Judge) -> str:
    problem = _runs(judge, build_copy(judge))
    if problem is not None:
        raise CheckFailed(problem)
    return 'ros2 run starts both entry points; they talk over /temperature and stop on Ctrl+C.'


@judged
def check_package_runs(judge: Judge) -> str:
    """Hidden test of notebook 05: the built package runs with ``ros2 run``.

    Builds your package (with the grader's stand-in nodes), starts both executables the
    way ``ros2 run`` does, checks that each runs its stand-in, then sends Ctrl+C and expects
    exit code 0 from both.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: with the CLI's error or what went wrong.
    """
    return _package_runs(judge)
