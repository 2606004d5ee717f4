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
import json
import os
import re
import shutil
import sys
from hashlib import sha256
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any, Optional

from std_msgs.msg import Float32

from .. import course
from ..errors import CheckFailed, Ros2nbError
from ..processes import interrupt, kill_process_group, until_waiting, wait_patiently
from ..terminal.colcon import build_cause, venv_tool
from ..terminal.files import saved_parts
from ..terminal.pkg_templates import SETUP_CFG, render_setup_py
from ..terminal.run import find_executable
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge
from .base import judged
from .drawn import chooser
from .mains import EXIT_AFTER_CTRL_C_S, last_line
from .package_stand_ins import EXECUTABLES
from .source import TEXT

# ------------------------------------------------------------------ the package
PLACEHOLDER = 'raise NotImplementedError'
#: setuptools' warning for a setup.cfg key spelt with a dash (``script-dir``), in a build's
#: output: deprecated, refused by 78.0.0, read again with the warning from 78.0.2
#: (pypa/setuptools#4911), and to be refused by a later release.
DASHED_KEY = re.compile(r"Usage of dash-separated '([\w-]+)' will not be supported")
#: The dash-spelt keys each successful build warned about, by its workspace.
_DASHED: dict[Path, list[str]] = {}


def course_setup_py() -> str:
    """The course's setup.py: what ``pkg_create`` writes, with notebook 05's two entry points."""
    text = render_setup_py(course.PACKAGE, 'TODO: Package description',
                           course.MAINTAINER_NAME, course.MAINTAINER_EMAIL,
                           'TODO: License declaration', None)
    entries = ''.join(f"            '{name} = {course.PACKAGE}.{name}:main',\n"
                      for name, _text in EXECUTABLES)
    return text.replace("'console_scripts': [\n", "'console_scripts': [\n" + entries, 1)


def course_setup_cfg() -> str:
    """The course's setup.cfg: scripts into ``lib/<package>``, where ``ros2 run`` looks."""
    return SETUP_CFG.format(name=course.PACKAGE)


def _package_source(judge: Judge) -> Path:
    source = judge.workspace / 'src' / course.PACKAGE
    if not (source / 'package.xml').is_file():
        raise CheckFailed(f'The package {course.PACKAGE} does not exist in your workspace: create '
                          'it (notebook 02, or run the catch_up cell at the top).')
    return source


def _console_scripts(setup_py: Path) -> Optional[list[Any]]:
    """The ``console_scripts`` list of ``setup(entry_points=...)`` as written, or None."""
    text = TEXT.read(setup_py)
    try:
        tree = ast.parse(text) if text is not None else None
    except (SyntaxError, ValueError):
        return None  # the build says where
    if tree is None:
        return None
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts' \
                        and isinstance(value, ast.List):
                    return value.elts
    return None


def _entry_point_syntax_cause(setup_py: Path) -> Optional[str]:
    """What is wrong with the way a console_scripts string is written (read to word a
    failure the judge saw), or None."""
    for element in _console_scripts(setup_py) or []:
        if not (isinstance(element, ast.Constant) and isinstance(element.value, str)):
            continue
        entry = element.value
        if entry.count('=') > 1:
            return (f'"{entry[:70]}..." is two entries run together: end each string in the '
                    'console_scripts list with a comma.')
        name, _, target = entry.partition('=')
        match = EntryPoint.pattern.match(target.strip()) if name.strip() else None
        if match is None or not match.group('attr'):
            return (f'"{entry}" is not written NAME = package.module:function: the module is '
                    'written with dots, like an import, without .py, and the function follows '
                    'a colon.')
    return None


def _built(judge: Judge, *, setup_py: Optional[str] = None,
           setup_cfg: Optional[str] = None) -> Path:
    """Build a copy of the learner's package with the grader's stand-in nodes (and the
    course's setup.py or setup.cfg, when given); cached by what went in.

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
                             for p in files) + repr((setup_py, setup_cfg)).encode()
                    ).hexdigest()[:12]
    if digest in judge.builds:
        return judge.builds[digest]
    ws = judge.scratch / f'build-{digest}'
    package = ws / 'src' / course.PACKAGE
    shutil.copytree(source, package, symlinks=True,
                    ignore=shutil.ignore_patterns('__pycache__', '*.egg-info'))
    for name, given in (('setup.py', setup_py), ('setup.cfg', setup_cfg)):
        if given is not None:
            (package / name).unlink(missing_ok=True)
            (package / name).write_text(given)
    for module, text in EXECUTABLES:
        target = package / course.PACKAGE / f'{module}.py'
        target.unlink(missing_ok=True)
        target.write_text(text)
    colcon = venv_tool('colcon')
    if colcon is None:
        raise Ros2nbError('colcon is not installed: run `make lab` or `make test`.')
    code, output = judge.run([colcon, 'build'], seconds=300, cwd=ws, what='colcon build')
    if code != 0:  # a console_scripts string setuptools cannot read says more than its error
        held = [n for n, given in (('setup.py', setup_py), ('setup.cfg', setup_cfg))
                if given is None and PLACEHOLDER in (TEXT.read(source / n) or '')]
        if held:
            raise CheckFailed(f'{held[0]} still holds the placeholder "raise NotImplementedError()"'
                              ': replace it with your lines and run that cell again.')
        syntax = _entry_point_syntax_cause(source / 'setup.py') if setup_py is None else None
        raise CheckFailed(f'colcon build of your package failed: '
                          f'{syntax or build_cause(output.splitlines())}')
    judge.builds[digest] = ws
    _DASHED[ws] = DASHED_KEY.findall(output)
    return ws


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
    code, output = judge.run(['bash', '-c', SOURCED_ENV, sys.executable], seconds=60,
                             cwd=ws, what='source install/setup.bash')
    try:
        env = json.loads(output.splitlines()[-1]) if code == 0 else None
    except (IndexError, ValueError):
        env = None
    if not isinstance(env, dict) or not all(isinstance(v, str) for v in env.values()):
        raise CheckFailed(f'source install/setup.bash failed in the build of your package '
                          f'(exit code {code}): {last_line(output)}')
    env.update({k: v for k, v in judge.subject_env().items()  # the judge's domain and transports,
                if k.startswith(('ROS_', 'RCUTILS', 'FASTDDS', 'PYTHONUNBUFFERED'))  # the
                or k in ('HOME', 'TMPDIR')})  # subjects' home and temporary folder
    return env


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
    env = _sourced(judge, ws)
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
            if not any(round(h.value, 3) == given for h in readings[first:]):
                name, out = course.PUBLISHER_EXECUTABLE, sensor_out
                would = f'published {given}'
            else:
                name, out = course.SUBSCRIBER_EXECUTABLE, monitor_out
                would = f'logged the reading {given} it heard'
            return (f'ros2 run {course.PACKAGE} {name} did not start main() of '
                    f'{course.PACKAGE}.{name}: the grader\'s stand-in there would have {would} '
                    f'({last_line(out.text())}).')
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
    syntax = _entry_point_syntax_cause(setup_py)
    if syntax is not None:
        return syntax
    written = [e.value for e in _console_scripts(setup_py) or []
               if isinstance(e, ast.Constant) and isinstance(e.value, str)]
    scripts = {name.strip(): target.strip() for name, _, target in
               (entry.partition('=') for entry in written)}
    for executable, _text in EXECUTABLES:
        want = f'{course.PACKAGE}.{executable}:main'
        if executable not in scripts:
            have = ', '.join(f'{k} = {v}' for k, v in sorted(scripts.items())) or 'none'
            return (f'console_scripts has no entry named {executable} (it has: {have}); the name '
                    'left of = is what you pass to ros2 run.')
        if scripts[executable].replace(' ', '') != want:
            return (f'{executable} = {scripts[executable]}: it should start main() in '
                    f'{course.PACKAGE}/{executable}.py, written {want}.')
    return None


def _entry_points(judge: Judge) -> str:
    problem = _runs(judge, _built(judge))
    if problem is not None:  # with the course's setup.cfg, setup.py alone counts
        problem = _runs(judge, _built(judge, setup_cfg=course_setup_cfg()))
    if problem is not None:
        cause = _entries_cause(_package_source(judge) / 'setup.py')
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
    file = _package_source(judge) / 'setup.cfg'
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


def _setup_cfg(judge: Judge) -> str:
    if PLACEHOLDER in (TEXT.read(_package_source(judge) / 'setup.cfg') or '') or \
            saved_parts(judge.workspace, course.SETUP_CFG_FILE) == set():  # its cell: unwritten
        raise CheckFailed('The setup.cfg cell still holds the placeholder "raise '
                          'NotImplementedError()": write the two settings in its place and run it.')
    try:  # the learner's setup.py may be at fault
        problem = _runs(judge, _built(judge))
    except CheckFailed as failure:
        problem = str(failure)
    if problem is not None:  # with the course's setup.py, setup.cfg alone counts
        built = _built(judge, setup_py=course_setup_py())
        problem = _runs(judge, built)
    else:
        built = _built(judge)
    if problem is not None:
        raise CheckFailed(_setup_cfg_cause(judge) or
                          f'{problem} setup.cfg puts the executables where ros2 run looks: '
                          f'$base/lib/{course.PACKAGE}.')
    dashed = _DASHED.get(built)
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
    setup.cfg counts) and starts both executables as ``ros2 run`` does.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the setting and the expected value.
    """
    return _setup_cfg(judge)


def _package_runs(judge: Judge) -> str:
    problem = _runs(judge, _built(judge))
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
