"""The course's answers are out of reach of the learner's code in a subject.

A subject runs the learner's code beside the course's stand-ins, its rules
(``monitor_status``) and, forked from a judge, the judge's checks.  Its code can import the
learner's API (rclpy, the messages, ros2nb's verbs and ``ros2nb.course``'s constants) and no
module that holds an answer, by any name (``import``, ``importlib``, ``ros2nb.course``,
``ros2nb.rules``, ``sys.modules``), fresh or forked from a judge that imported them all.
The stand-ins are still handed in to the subject once the code is loaded: the honest
corpora's checks run on them.
"""

import json
import os
import sys

import pytest

from waiting import run_to_end

pytestmark = [pytest.mark.judge, pytest.mark.timeout(120)]

#: Learner code that reaches for the answers in every plain way, and uses what it may.
PROBE = '''
import importlib, json, sys
import rclpy, ros2nb
from std_msgs.msg import Float32
from ros2nb import course
reached = {}
for how, reach in [
        ('import', lambda: __import__('ros2nb.subject.stand_ins').subject.stand_ins),
        ('importlib', lambda: importlib.import_module('ros2nb.subject.stand_ins')),
        ('the rule through ros2nb.course', lambda: course.monitor_status),
        ('the rule itself', lambda: importlib.import_module('ros2nb.rules')),
        ('the rule through ros2nb', lambda: ros2nb.rules.monitor_status),
        ('a check', lambda: importlib.import_module('ros2nb.checks.lesson04')),
        ('the checks through ros2nb', lambda: ros2nb.checks),
        ('the reference', lambda: importlib.import_module('ros2nb.reference.fan_controller')),
        ('the judge', lambda: importlib.import_module('ros2nb.judge.session')),
        ('sys.modules', lambda: [m for m in sys.modules if m.split('.')[:2] in (
            ['ros2nb', 'rules'], ['ros2nb', 'checks'], ['ros2nb', 'judge'],
            ['ros2nb', 'reference'])][0]),
        ('the stand-ins in sys.modules', lambda: sys.modules['ros2nb.subject.stand_ins'])]:
    try:
        reach()
        reached[how] = 'reached'
    except (ImportError, AttributeError, IndexError, KeyError) as error:
        reached[how] = str(error)
print('REACHED', json.dumps({'reached': reached, 'api': [course.TOPIC, Float32.__name__,
                                                         callable(ros2nb.start)]}))
'''
#: A judge that imported its checks, the stand-ins and the rules, then forks its subjects.
JUDGE = '''
import json, sys
from pathlib import Path
import ros2nb.checks.lesson04, ros2nb.judge.session, ros2nb.subject.stand_ins
import ros2nb.rules
ros2nb.rules.monitor_status(27.0)
from ros2nb.subject.forked import serve_from_here
serve_from_here()  # as python -m ros2nb.judge does
from ros2nb.judge.subjects import SubjectProcess
from ros2nb.subject_interface import ExecCells
subject = SubjectProcess(Path(sys.argv[1]))
subject.request(ExecCells(sources=[sys.argv[2]]))
subject.close()
print(subject.output.text())
'''


def _reached(out: str) -> dict:
    line, = (line for line in out.splitlines() if line.startswith('REACHED '))
    return json.loads(line[len('REACHED '):])


@pytest.mark.parametrize('started', ['forked from a judge', 'started afresh'])
def test_no_answer_is_importable(started, tmp_path):
    env = None
    if started == 'started afresh':  # a sandbox prefix: the subject is not forked
        env = {**os.environ, 'ROS2NB_SUBJECT_PREFIX': json.dumps(['env'])}
    done = run_to_end([sys.executable, '-c', JUDGE, str(tmp_path), PROBE], 'a judge',
                      env=env, cwd=tmp_path)
    said = _reached(done.stdout)
    assert said['api'] == ['temperature', 'Float32', True], said
    assert 'reached' not in said['reached'].values(), said['reached']
    assert "holds the course's answer" in said['reached']['importlib'], said['reached']
