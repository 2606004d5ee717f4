"""A subject's audit hook sees the learner's code reach into the course as it runs.

The hook (``ros2nb.subject.seen``) runs here in a Python process of its own, as a subject
installs it before the learner's code loads, writing its lines to a pipe; the "learner's
code" is a file of the test's (no file of ros2nb's or of the Python installation is the
learner's).  Each kind of reaching is told once, with the learner's line; what a library or
the course's own code does on the learner's behalf (rclpy's logger, a namedtuple, the
runtime looking for nodes) is not; and code that replaces names after the hook was installed
(the answers' list, builtins) changes nothing it sees.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from ros2nb.judge.reaching import KINDS, parse_seen

#: Runs LEARNER (a file) with the hook installed first, writing to a pipe it then prints.
RUNNER = '''
import os, runpy, sys
from ros2nb.subject.seen import install
read, write = os.pipe()
install(write)
try:
    runpy.run_path(sys.argv[1], run_name='__main__')
except BaseException as error:
    print('RAISED', type(error).__name__, error)
os.close(write)
sys.stdout.write(os.read(read, 1 << 20).decode())
'''


def seen(tmp_path, code: str) -> list:
    """What the hook saw while the learner's ``code`` ran: ``(kind, what, line)`` each."""
    learner = tmp_path / 'learner.py'
    learner.write_text(code)
    done = subprocess.run([sys.executable, '-c', RUNNER, str(learner)], capture_output=True,
                          text=True, timeout=60, env={**os.environ, 'PYTHONPATH': ''})
    assert done.returncode == 0 and 'RAISED' not in done.stdout, done.stdout + done.stderr
    found = [parse_seen(line.encode()) for line in done.stdout.splitlines()
             if line.startswith('SEEN\t')]
    return [(r.kind, r.what, r.where.rpartition(' line ')[2]) for r in found if r]


@pytest.mark.parametrize('code, kind, what', [
    ('import gc\ngc.get_objects()', 'objects', 'gc.get_objects'),
    ('import gc\ngc.get_referrers(gc)', 'objects', 'gc.get_referrers'),
    ('import sys\nsys._getframe(0)', 'frames', 'sys._getframe'),
    ('import inspect\ninspect.stack()', 'frames', 'sys._getframe'),
    ('import logging\nlogging.currentframe()', 'frames', 'sys._getframe'),
    ('import sys\nsys._current_frames()', 'frames', 'sys._current_frames'),
    ('def f():\n    pass\nf.__code__', 'code', '.__code__'),
    ('try:\n    1 / 0\nexcept ZeroDivisionError as e:\n    e.__traceback__.tb_frame',
     'code', '.tb_frame'),
    ("import ros2nb.rules", 'answer_module', 'ros2nb.rules'),
    ("import importlib\nimportlib.import_module('ros2nb.judge.' + 'stand_ins')",
     'answer_file', 'stand_ins'),  # importlib raises no import event: its files are seen
    ("import ros2nb, pathlib\n(pathlib.Path(ros2nb.__file__).parent / 'rules.py').read_text()",
     'answer_file', 'rules.py'),
    ("import ros2nb, os\nos.listdir(os.path.dirname(ros2nb.__file__) + '/judge')",
     'answer_file', 'judge'),
    ("eval('1 + 1')", 'compiled', 'compile'),
    ("import marshal\nmarshal.loads(marshal.dumps(1))", 'compiled', 'marshal.loads'),
    ("import types\ntypes.FunctionType((lambda: 0).__code__, {})", 'compiled', 'function.__new__'),
    ('import ctypes\nctypes.string_at(id(1), 1)', 'memory', 'ctypes.string_at'),
    ("import subprocess\nsubprocess.run(['true'])", 'processes', 'subprocess.Popen'),
])
def test_each_kind_is_seen_with_the_learners_line(tmp_path, code, kind, what):
    found = seen(tmp_path, code)
    assert any(k == kind and what in w and line == str(code.count('\n') + 1)
               for k, w, line in found), found
    assert all(k in KINDS for k, _w, _line in found), found


def test_what_a_library_or_the_course_does_for_the_learner_is_not_seen(tmp_path):
    """rclpy's logger and Python's read their caller's frame, a namedtuple and a dataclass
    compile code, a traceback is printed, the runtime lists the nodes it knows, a library
    imports ctypes: none of it is the learner's reaching in."""
    found = seen(tmp_path, '''
import collections, dataclasses, logging, traceback, enum
P = collections.namedtuple('P', 'a b')
@dataclasses.dataclass
class D:
    x: int = 1
E = enum.Enum('E', 'A B')
logging.getLogger('x').warning('a line of Python logging')
try:
    1 / 0
except ZeroDivisionError:
    traceback.format_exc()
from ros2nb.runtime import nodes
list(nodes._live_nodes())
import rclpy.impl.rcutils_logger as logger
logger.RcutilsLogger('learner').info('a line of rclpy')
''')
    assert found == [], found


def test_an_error_python_cannot_raise_is_not_the_learners_compile(tmp_path):
    """rclpy's Executor.__del__ raises on the executor a learner's call left half made
    (a keyword one letter off); CPython's own report of that error compiles rclpy's source
    line from C with the learner's frame on top, which the hook told as the learner's
    compile: the subject reports it through Python's traceback module instead."""
    found = seen(tmp_path, '''
from rclpy.executors import MultiThreadedExecutor
try:
    MultiThreadedExecutor(num_thrads=2)
except TypeError:
    pass
''')
    assert found == [], found


def test_what_the_code_replaces_afterwards_changes_nothing_it_sees(tmp_path):
    """The hook's lists and helpers were bound before the learner's code ran: emptying the
    answers' list, replacing a builtin and os.write leave it seeing the import."""
    found = seen(tmp_path, '''
import builtins, os
from ros2nb.subject import out_of_reach, seen
out_of_reach.ANSWERS = ()
seen.ANSWERS = seen.WATCHED = ()
builtins.any = lambda *a: False
os.write = lambda *a: 0
import ros2nb.rules
''')
    assert ('answer_module', 'ros2nb.rules', '8') in found, found


def test_a_flood_of_one_kind_mutes_no_other(tmp_path):
    """64 audit hooks of the learner's own, then an import of the course's rule: the hooks
    are counted past their places shown, and the import is still seen.  Before, the hook's
    64 lines in all went to the hooks and the import was never told."""
    found = seen(tmp_path, '''
import sys
for _ in range(64):
    sys.addaudithook(lambda event, args: None)
import ros2nb.rules
''')
    assert ('answer_module', 'ros2nb.rules', '5') in found, found
    assert sum(kind == 'hooks' for kind, _what, _line in found) == 1, found  # one place
