"""The checks of notebook 09 (QoS) against the mistakes learners make: one line each.

Every check runs a real publisher and subscription over DDS with the learner's profile.
Each mistake runs twice: as the kernel runs it (the learner's function called here) and as
the grader runs it (this process is the judge; the answer cell runs in a real subject, which
sends back only the profile's policies).  The answer cells are the solution notebook's, so
they never go stale; they pass all three checks, so every failure below is the planted
mistake's.
"""

import os
import re

import pytest

from ros2nb import checks
from ros2nb.judge_interface import AnswerRef
from ros2nb.errors import CheckFailed
from ros2nb.judge.session import Session

pytestmark = [pytest.mark.judge, pytest.mark.ros, pytest.mark.timeout(300)]

from judging import answer_cells  # noqa: E402

HERE = os.path.dirname(__file__)
SOLUTION = os.path.join(HERE, '..', 'solutions', '09-qos.ipynb')
LEARNER = os.path.join(HERE, '..', 'notebooks', '09-qos.ipynb')


CONTEXT, ANSWERS = answer_cells(SOLUTION)
UNTOUCHED = answer_cells(LEARNER)[1]  # the learner's copy: '# YOUR CODE HERE', NotImplementedError
CHECKS = {'newest_only_profile': 'check_newest_only',
          'sensor_subscription_profile': 'check_sensor_subscription',
          'latched_thresholds_profile': 'check_latched_thresholds'}


@pytest.fixture(scope='module')
def session(tmp_path_factory):
    """A judge session (this process is the judge) with a workspace of its own."""
    root = tmp_path_factory.mktemp('checks09')
    (root / 'ws').mkdir()
    session = Session(root / 'ws')
    yield session
    session.close()


def run_check(session, path: str, name: str, answer: str) -> None:
    """Run the check of ``name`` on ``answer``: in this process, or from source in a subject."""
    if path == 'kernel':
        namespace: dict = {}
        exec(CONTEXT + '\n' + answer, namespace)
        getattr(checks, CHECKS[name])(namespace[name])
    else:
        ref = AnswerRef(name, (CONTEXT, answer))
        try:
            checks.run_check(CHECKS[name], session, ref)
        finally:
            session.drop(('cells', ref.sources))  # one subject at a time


@pytest.mark.parametrize('path', ['kernel', 'judge'])
def test_the_solutions_pass(session, capsys, path):
    for name, answer in ANSWERS.items():
        run_check(session, path, name, answer)
    assert capsys.readouterr().out.count('Check passed:') == 3


NEWEST = 'QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1)'
SENSOR = 'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)'
LATCHED = 'durability=DurabilityPolicy.TRANSIENT_LOCAL)'
MISTAKES = [
    ('newest_only_profile', 'a number', NEWEST, '1',
     r'newest_only_profile\(\) returned int 1; return a QoSProfile\(...\)\.'),
    ('newest_only_profile', 'depth 10', 'depth=1)', 'depth=10)',
     r'After a burst of 30 your subscription got 10 messages \[20, 21, \.\.\., 29\]: its '
     r'history keeps that many; a display of the newest reading keeps depth=1\.'),
    # passes by the vendor's default depth (1 in Fast DDS), with rclpy's warning under it
    ('newest_only_profile', 'depth 0', 'depth=1)', 'depth=0)',
     r"raised: depth=0 with KEEP_LAST does not mean 'keep none'.*e\.g\. depth=1 for the newest "
     r'only\. \(.*line \d+'),
    ('newest_only_profile', 'keep all', 'history=HistoryPolicy.KEEP_LAST',
     'history=HistoryPolicy.KEEP_ALL',
     r'got all 30: KEEP_ALL \(or a depth of 30 or more\) keeps every message; use KEEP_LAST '
     r'with depth=1\.'),
    ('newest_only_profile', 'best effort', 'depth=1)',
     'depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)',
     r"^Your subscription is BEST_EFFORT, (KEEP_LAST \(1\), )?VOLATILE: the display's "
     r'subscription is reliable, as the task says \(the default\): leave reliability out, or '
     r'give ReliabilityPolicy\.RELIABLE\.$'),
    ('newest_only_profile', 'transient local', 'depth=1)',
     'depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)',
     r'never matched the reliable, volatile publisher: rclpy says: Volatile publisher and '
     r'transient local subscription; make the subscription ask for no more than the publisher '
     r'offers\.$'),
    ('sensor_subscription_profile', 'reliable', 'ReliabilityPolicy.BEST_EFFORT',
     'ReliabilityPolicy.RELIABLE',
     r'^Incompatible QoS: the sensor publishes with BEST_EFFORT, KEEP_LAST \(5\), VOLATILE, your '
     r'subscription asks for RELIABLE, (KEEP_LAST \(5\), )?VOLATILE; rclpy says: Best effort '
     r'publisher and reliable subscription; a best-effort publisher never resends'),
    ('sensor_subscription_profile', 'depth 10', 'depth=5', 'depth=10',
     r'^After a burst of 30 while its callback was busy, your subscription kept 10 '
     r'\[20, 21, \.\.\., 29\]: the task keeps the last 5 readings \[25, 26, \.\.\., 29\]: '
     r'KEEP_LAST with depth=5\.$'),
    ('sensor_subscription_profile', 'transient local', 'BEST_EFFORT)',
     'BEST_EFFORT, durability=DurabilityPolicy.TRANSIENT_LOCAL)',
     r'rclpy says: Volatile publisher and transient local subscription'),
    ('latched_thresholds_profile', 'volatile', LATCHED, 'durability=DurabilityPolicy.VOLATILE)',
     r'joined after 20 thresholds were published \(0 to 19\) got none: make durability '
     r'TRANSIENT_LOCAL'),
    ('latched_thresholds_profile', 'best effort', 'ReliabilityPolicy.RELIABLE',
     'ReliabilityPolicy.BEST_EFFORT',
     r'got none: a best-effort subscription is not sent what was published before it joined: '
     r'make it RELIABLE\.'),
    ('latched_thresholds_profile', 'depth 1', 'depth=5', 'depth=1',
     r'got 1 \[19\], expected the last 5 \[15, 16, \.\.\., 19\]: depth=5\.'),
    ('latched_thresholds_profile', 'keep all', 'depth=5,', 'history=HistoryPolicy.KEEP_ALL,',
     r'got all 20: KEEP_ALL \(or a depth of 20 or more\) keeps every message; keep the last 5'),
]


@pytest.mark.parametrize('path', ['kernel', 'judge'])
@pytest.mark.parametrize('name', sorted(CHECKS))
def test_an_untouched_cell_gets_one_line(session, path, name):
    assert 'raise NotImplementedError()' in UNTOUCHED[name]
    with pytest.raises(CheckFailed) as caught:
        run_check(session, path, name, UNTOUCHED[name])
    message = str(caught.value)
    assert '\n' not in message and message.startswith(f'{name}() still raises '
                                                       'NotImplementedError'), message


@pytest.mark.parametrize('path', ['kernel', 'judge'])
@pytest.mark.parametrize('name, label, old, new, pattern', MISTAKES,
                         ids=[f'{m[0]}: {m[1]}' for m in MISTAKES])
def test_a_mistake_gets_one_line(session, path, name, label, old, new, pattern):
    answer = ANSWERS[name]
    assert old in answer, old
    with pytest.raises(CheckFailed) as caught:
        run_check(session, path, name, answer.replace(old, new, 1))
    message = str(caught.value)
    assert '\n' not in message and re.search(pattern, message), message


#: A volatile profile (wrong: a late joiner gets none), and a thread the answer cell starts:
#: it watches the graph for the check's trial topic and, once the late subscription has
#: matched it, publishes the five thresholds the check wants to see.
INJECTOR = '''
import threading as _threading
import time as _time

import rclpy as _rclpy
from rclpy.context import Context as _Context
from std_msgs.msg import Int32 as _Int32


def _inject():
    context = _Context()
    _rclpy.init(context=context)
    node = _rclpy.create_node('helper', context=context)
    done = set()
    while True:
        for topic, _types in node.get_topic_names_and_types():
            if topic.startswith('/ros2nb_qos_trial_') and topic not in done:
                done.add(topic)
                publisher = node.create_publisher(_Int32, topic, QoSProfile(depth=5))
                while publisher.get_subscription_count() == 0:
                    _time.sleep(0.005)
                for number in range(15, 20):
                    publisher.publish(_Int32(data=number))
        _time.sleep(0.005)


_threading.Thread(target=_inject, daemon=True).start()
'''


def test_a_thread_of_the_answer_cell_cannot_feed_the_trial(session):
    """The trials run on the judge's domain: a thread the learner's answer cell started could
    publish on the trial's topic (found in the graph) what the check wants to see. The
    subject lives through the trial (it holds the learner's publisher), so that publisher
    publishes numbers only the judge chose, and counts a second publisher on the
    topic, or a number it never chose, as what it is. Without that, this volatile profile
    passed as latched."""
    answer = ANSWERS['latched_thresholds_profile'].replace(
        LATCHED, 'durability=DurabilityPolicy.VOLATILE)') + INJECTOR
    with pytest.raises(CheckFailed, match=r'Something other than the publisher made with your '
                                          r'profile published|got none: make durability'):
        run_check(session, 'judge', 'latched_thresholds_profile', answer)


#: The sensor's profile, honest, that silences the logger of the subject holding its
#: subscription: a line that subject would log never reaches the judge.  Calls are counted in
#: a file, since each trial runs in a new subject.
SILENCED = '''
import rclpy.logging as _logging

_honest = sensor_subscription_profile


def sensor_subscription_profile():
    with open({calls!r}, 'a') as calls:
        calls.write('.')
    _logging.get_logger('qos_answer').set_level(_logging.LoggingSeverity.ERROR)
    return _honest()
'''


def test_what_the_subscription_keeps_is_seen_by_the_judge_not_told(session, capsys, tmp_path):
    """What a subscription with the learner's history keeps of the burst is what a
    subscription of the judge's own keeps: no line of the subject's plays a part.  When the
    subject logged what it took, this honest depth 5 lost the part ('your subscription kept
    0 []', as once in make test), and later cost a burst sent again."""
    calls = tmp_path / 'calls'
    answer = ANSWERS['sensor_subscription_profile'] + SILENCED.format(calls=str(calls))
    run_check(session, 'judge', 'sensor_subscription_profile', answer)
    assert calls.read_text() == '.'  # one trial: the pairing, whose reply gives the history
    assert 'keeps the last 5 readings' in capsys.readouterr().out
