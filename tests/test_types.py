"""The seams are typed, and the type checker holds them (``make check`` runs mypy first).

What a check may use of the judge is declared once (``ros2nb.judge_interface``), and so is
every command a subject serves, with its request and reply (``ros2nb.subject_interface``,
``ros2nb.subject_replies``).  mypy, configured in ``pyproject.toml`` ([tool.mypy]), reads the
checks, the judge, the subjects and the grader against them.  Each protection is shown failing
on a planted mistake, beside its honest twin passing, with the same settings and cache as
``make check``.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import typing
from pathlib import Path

import pytest

from ros2nb import subject_interface
from ros2nb.subject_interface import COMMANDS, LOADERS, Serves, reply_type

ROOT = Path(__file__).resolve().parent.parent
#: mypy's cache, as make check leaves it (pyproject.toml: [tool.mypy] cache_dir).
CACHE = ROOT / '.cache' / 'mypy'

#: A check's body that reads a field no reply of that command has, and its honest twin.
WRONG_REPLY_FIELD = '''
from ros2nb.judge_interface import Judge
from ros2nb.subject_interface import WaitMatched


def body(judge: Judge) -> bool:
    subject = judge.file_subject('temperature_publisher.py')
    return subject.request(WaitMatched(topic='/temperature', seconds=1.0)).{field}
'''
#: A check's body that calls the observer wrongly (no ``expected``), and its honest twin.
WRONG_OBSERVER_CALL = '''
from ros2nb.judge_interface import Judge


def body(judge: Judge) -> list[tuple[str, str, str]]:
    return judge.observer.endpoints('temperature_sensor', '/'{expected})
'''
#: A subject's method that answers its command with another reply, and its honest twin.
WRONG_SERVED_REPLY = '''
from ros2nb.subject.commands import Subject
from ros2nb.subject_interface import GetCounts, Serves
from ros2nb.subject_replies import {reply}


class Counting(Subject):
    def counts(self, command: GetCounts) -> {reply}:
        return {reply}(ok=True)


def served(subject: Counting) -> Serves:
    return subject
'''
#: A check's body of the wrong kind for its decorator, and its honest twin.
WRONG_CHECK_BODY = '''
from ros2nb.checks.base import judged
from ros2nb.judge_interface import Judge


@judged
def check_planted(judge: Judge) -> {returns}:
    return {value}
'''
#: A direct check's notebook function called without an argument its body takes, and its
#: honest twin: the body's signature, less the judge, is the function's.
WRONG_CHECK_CALL = '''
from typing import Any, Optional

from ros2nb.checks.base import direct
from ros2nb.judge_interface import Judge


@direct
def check_planted(judge: Optional[Judge], make_path: Any, *, ends_with: str) -> str:
    return 'Check passed: planted'


check_planted(print{ends_with})
'''

PLANTED = {
    'a reply field that does not exist': (
        WRONG_REPLY_FIELD.format(field='matched'), r'"Reply" has no attribute "matched"'),
    'its honest twin (the field that exists)': (WRONG_REPLY_FIELD.format(field='ok'), None),
    'a wrong call of the observer': (
        WRONG_OBSERVER_CALL.format(expected=''),
        r'Missing positional argument "expected" in call to "endpoints" of "Observer"'),
    'its honest twin (what the subject made)': (
        WRONG_OBSERVER_CALL.format(expected=', []'), None),
    "a subject's method answering with another reply": (
        WRONG_SERVED_REPLY.format(reply='Reply'),
        r'Return type "Reply" of "counts" incompatible with return type "Counts" in supertype'),
    'its honest twin (the reply the command declares)': (
        WRONG_SERVED_REPLY.format(reply='Counts'), None),
    "a judged check's body that returns no sentence": (
        WRONG_CHECK_BODY.format(returns='bool', value='True'),
        r'Argument 1 to "judged" has incompatible type "Callable\[\[Judge\], bool\]"'),
    'its honest twin (the passed sentence)': (
        WRONG_CHECK_BODY.format(returns='str', value="'Check passed: planted'"), None),
    "a direct check called without an argument of its body's": (
        WRONG_CHECK_CALL.format(ends_with=''),
        r'Missing named argument "ends_with" for "check_planted"'),
    'its honest twin (every argument)': (
        WRONG_CHECK_CALL.format(ends_with=", ends_with='x'"), None),
}


@pytest.fixture(scope='module')
def checked(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """mypy run once over every planted module, as ``make check`` runs it: its lines by module."""
    folder = tmp_path_factory.mktemp('planted')
    # A copy of make check's cache: the course's modules are read from it, and the planted
    # ones never enter the course's (it would answer for an unchanged one from there).
    cache = folder / 'cache'
    if CACHE.is_dir():
        shutil.copytree(CACHE, cache)
    files = {}
    for number, (label, (source, _)) in enumerate(PLANTED.items()):
        files[label] = folder / f'planted_{number}.py'
        files[label].write_text(source)
    done = subprocess.run([sys.executable, '-m', 'mypy', '--config-file',
                           str(ROOT / 'pyproject.toml'), '--cache-dir', str(cache),
                           *map(str, files.values())],
                          capture_output=True, text=True, cwd=ROOT, timeout=600)
    assert done.returncode in (0, 1), done.stdout + done.stderr  # 2: mypy itself failed
    return {label: '\n'.join(line for line in done.stdout.splitlines()
                             if line.split(':')[0].endswith(f'/{file.name}'))
            for label, file in files.items()}


@pytest.mark.parametrize('label', PLANTED)
def test_the_type_checker_fails_on_a_planted_mistake_only(checked, label):
    _source, error = PLANTED[label]
    if error is None:
        assert checked[label] == '', checked[label]
    else:
        assert re.search(error, checked[label]), checked[label]


def test_every_command_is_served_by_the_method_its_op_names():
    """The subject's loop calls the method named by a command's ``op``
    (:class:`~ros2nb.subject_interface.Serves`, which the type checker holds the subject to):
    a command with no method, or one whose method takes or answers another type, fails here."""
    served = {name for name, member in vars(Serves).items()
              if callable(member) and not name.startswith('_')}
    assert served == set(COMMANDS), served ^ set(COMMANDS)
    for op, command in COMMANDS.items():
        hints = typing.get_type_hints(getattr(Serves, op), vars(subject_interface))
        assert command.op == op
        assert (hints['command'], hints['return']) == (command, reply_type(command)), op
    assert not set(LOADERS) & set(COMMANDS)  # the first command is never served again


#: ``# type: ignore[code]  # why``: a silenced check says what it silences and why.
IGNORE = re.compile(r'#\s*type:\s*ignore(?P<rest>.*)$')
REASONED = re.compile(r'^\[[\w-]+(, *[\w-]+)*\]\s+#\s*\S')


def test_every_type_ignore_names_its_code_and_its_reason():
    unreasoned = []
    for path in sorted(ROOT.glob('*.py')) + sorted(
            p for folder in ('src', 'tests', 'benchmarks', 'docs') for p in
            (ROOT / folder).rglob('*.py')):
        for number, line in enumerate(path.read_text().splitlines(), 1):
            found = IGNORE.search(line)
            if found and not REASONED.match(found['rest'].strip()):
                unreasoned.append(f'{path.relative_to(ROOT)}:{number}: {line.strip()}')
    assert not unreasoned, '\n'.join(unreasoned)
