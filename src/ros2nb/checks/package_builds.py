"""A copy of the learner's package, built with colcon in the judge and sourced (notebook 05).

Part of :mod:`ros2nb.checks`, for :mod:`.lesson05`: the copy carries the grader's stand-in
nodes in place of the learner's, and the course's ``setup.py`` or ``setup.cfg`` where the
other one is graded.  A build is kept by what went into it; the environment that ``source
install/setup.bash`` gives is worked out in a subject and read as data.
"""

from __future__ import annotations

import ast
import json
import os
import re
import shutil
import sys
from hashlib import sha256
from importlib.metadata import EntryPoint
from pathlib import Path
from typing import Any, Optional

from .. import course
from ..errors import CheckFailed, Ros2nbError
from ..judge_interface import Judge
from ..terminal.colcon import build_cause, venv_tool
from ..terminal.pkg_templates import SETUP_CFG, render_setup_py
from .mains import last_line
from .package_stand_ins import EXECUTABLES
from .source import TEXT

PLACEHOLDER = 'raise NotImplementedError'
#: setuptools' warning for a setup.cfg key spelt with a dash (``script-dir``), in a build's
#: output: deprecated, refused by 78.0.0, read again with the warning from 78.0.2
#: (pypa/setuptools#4911), and to be refused by a later release.
DASHED_KEY = re.compile(r"Usage of dash-separated '([\w-]+)' will not be supported")
#: The dash-spelt keys each successful build warned about, by its workspace.
DASHED: dict[Path, list[str]] = {}


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


def package_source(judge: Judge) -> Path:
    source = judge.workspace / 'src' / course.PACKAGE
    if not (source / 'package.xml').is_file():
        raise CheckFailed(f'The package {course.PACKAGE} does not exist in your workspace: create '
                          'it (notebook 02, or run the catch_up cell at the top).')
    return source


def console_scripts(setup_py: Path) -> Optional[list[Any]]:
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


def entry_point_syntax_cause(setup_py: Path) -> Optional[str]:
    """What is wrong with the way a console_scripts string is written (read to word a
    failure the judge saw), or None."""
    for element in console_scripts(setup_py) or []:
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


def build_copy(judge: Judge, *, setup_py: Optional[str] = None,
               setup_cfg: Optional[str] = None, symlink: bool = False) -> Path:
    """Build a copy of the learner's package with the grader's stand-in nodes (and the
    course's setup.py or setup.cfg, when given); cached by what went in.  With ``symlink``,
    as ``colcon build --symlink-install`` (a development install, which reads setup.cfg's
    ``[develop]``, where a normal one reads ``[install]``).

    :return: the copy's workspace (with ``install/``).
    :raises CheckFailed: with the build's cause in one line.
    """
    source = package_source(judge)
    # Links are copied as links, never followed: a link to a file only the judge may read
    # would otherwise put that file's text in the build, where the learner's setup.py runs.
    files = sorted(p for p in source.rglob('*') if '__pycache__' not in p.parts
                   and (p.is_symlink() or p.is_file()))
    digest = sha256(b''.join(p.relative_to(source).as_posix().encode()
                             + (os.readlink(p).encode() if p.is_symlink() else p.read_bytes())
                             for p in files) + repr((setup_py, setup_cfg, symlink)).encode()
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
    command = [colcon, 'build', *(['--symlink-install'] if symlink else [])]
    code, output = judge.run(command, seconds=300, cwd=ws, what=' '.join(['colcon', *command[1:]]),
                             writable=[ws])
    if code != 0:  # a console_scripts string setuptools cannot read says more than its error
        held = [n for n, given in (('setup.py', setup_py), ('setup.cfg', setup_cfg))
                if given is None and PLACEHOLDER in (TEXT.read(source / n) or '')]
        if held:
            raise CheckFailed(f'{held[0]} still holds the placeholder "raise NotImplementedError()"'
                              ': replace it with your lines and run that cell again.')
        syntax = entry_point_syntax_cause(source / 'setup.py') if setup_py is None else None
        raise CheckFailed(f'colcon build of your package failed: '
                          f'{syntax or build_cause(output.splitlines())}')
    judge.builds[digest] = ws
    DASHED[ws] = DASHED_KEY.findall(output)
    return ws


#: What a subject runs in a built workspace: the environment ``source install/setup.bash``
#: gives, printed as one JSON line.
SOURCED_ENV = ('source install/setup.bash >/dev/null 2>&1 || exit 3; exec "$0" -c '
               '"import json, os; print(json.dumps(dict(os.environ)))"')


def sourced(judge: Judge, ws: Path) -> dict[str, str]:
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
