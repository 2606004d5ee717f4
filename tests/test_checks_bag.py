"""The checks of notebook 10 (record and replay) against the mistakes learners make: one line each.

Each check reads a real bag with rosbags, or listens to a real replay over DDS. Each mistake
runs twice: as the kernel runs it (the learner's function called here, with ROS up in this
process on simulated time) and as the grader runs it (this process is the judge; the answer
cell runs in a real subject). The answer cells are the solution notebook's, so they never go
stale. Also: a bag written the lesson's way opens with readers the course does not own.
"""

import os
import re
import sys
import tempfile
from pathlib import Path

import pytest

pytestmark = [pytest.mark.timeout(600),
              pytest.mark.skipif(sys.version_info < (3, 11),
                                 reason='bags need Python 3.11 or newer (rosbags needs apsw)')]

import ros2nb  # noqa: E402
from ros2nb import checks  # noqa: E402
from ros2nb.checks.base import AnswerRef, bind_judge  # noqa: E402
from ros2nb.checks.dispatch import IN_JUDGE_ENV  # noqa: E402
from ros2nb.errors import CheckFailed, Ros2nbError, UsageError  # noqa: E402
from ros2nb.judge.session import Session  # noqa: E402
from ros2nb.terminal.workspace import WORKSPACE_ENV  # noqa: E402

from judging import answer_cells  # noqa: E402

HERE = os.path.dirname(__file__)
SOLUTION = os.path.join(HERE, '..', 'solutions', '10-record-and-replay.ipynb')
LEARNER = os.path.join(HERE, '..', 'notebooks', '10-record-and-replay.ipynb')
CHECKS = {'record_hour': checks.check_recording, 'replay': checks.check_replay,
          'read_temperatures': checks.check_readings}


CONTEXT, ANSWERS = answer_cells(SOLUTION)


@pytest.fixture(scope='module')
def workspace(tmp_path_factory):
    """A workspace with the course's sensor and monitor, as catch_up(10) writes them."""
    saved = os.environ.get(WORKSPACE_ENV)
    root = tmp_path_factory.mktemp('checks10')
    os.environ[WORKSPACE_ENV] = str(root / 'ws')
    ros2nb.course.catch_up(10)
    yield root / 'ws'
    if saved is None:
        os.environ.pop(WORKSPACE_ENV, None)
    else:
        os.environ[WORKSPACE_ENV] = saved


@pytest.fixture(scope='module')
def session(workspace):
    """A judge session (this process is the judge), and ROS up here for the kernel's path."""
    saved = os.environ.get(IN_JUDGE_ENV)
    session = Session(workspace)
    ros2nb.start(sim_time=True)
    yield session
    bind_judge(None)
    session.close()
    ros2nb.shutdown()
    if saved is None:
        os.environ.pop(IN_JUDGE_ENV, None)
    else:
        os.environ[IN_JUDGE_ENV] = saved


def run_check(session, path: str, name: str, answer: str) -> None:
    """Run the check of ``name`` on ``answer``: in this process, or from source in a subject."""
    if path == 'kernel':
        os.environ.pop(IN_JUDGE_ENV, None)
        bind_judge(None)
        namespace: dict = {}
        exec(CONTEXT.replace('_ = ros2nb.start', '# ') + '\n' + answer, namespace)
        CHECKS[name](namespace[name])
        return
    os.environ[IN_JUDGE_ENV] = '1'
    bind_judge(session)
    ref = AnswerRef(name, (CONTEXT, answer))
    try:
        CHECKS[name](ref)
    finally:
        session.drop(('cells', ref.sources))  # one subject at a time


@pytest.mark.parametrize('path', ['kernel', 'judge'])
def test_the_solutions_pass(session, capsys, path):
    for name, answer in ANSWERS.items():
        run_check(session, path, name, answer)
    assert capsys.readouterr().out.count('Check passed:') == 3


MISTAKES = [
    ('record_hour', 'no /rosout', "'/temperature', '/rosout')", "'/temperature')",
     r"^The bag holds /temperature but not /rosout \(the monitor's statuses\): record both "
     r'/temperature and /rosout\.$'),
    ('record_hour', 'a minute', 'spin(HOUR_S,', 'spin(60,',
     r'^The bag holds 60 readings on /temperature; one simulated hour of the sensor is 3600'),
    ('record_hour', 'another folder', 'bag_record(bag_path,',
     "bag_record(Path(tempfile.mkdtemp()) / 'elsewhere',",
     r'^record_hour\(bag_path\) wrote no bag at the path it was given: pass bag_path'),
    ('record_hour', 'no monitor', '    ros2nb.add(sub.TemperatureMonitor())\n', '',
     r'^The bag holds 0 status lines of temperature_monitor on /rosout, expected 3600'),
    ('replay', 'no monitor', '    ros2nb.add(sub.TemperatureMonitor())\n', '',
     r'^temperature_monitor logged no status during the replay: add your monitor before '
     r'bag_play'),
    ('replay', 'monitor after play', "    ros2nb.add(sub.TemperatureMonitor())\n    "
     "ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])\n",
     "    ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])\n"
     '    ros2nb.add(sub.TemperatureMonitor())\n',
     r'^temperature_monitor logged no status during the replay'),
    ('read_temperatures', 'absolute times', '(stamp - first) / 1e9', 'stamp / 1e9',
     r'^read_temperatures\(\) returned times \[1\.0, 2\.0, 3\.0\]\.\.\.; expected seconds since '
     r'the first reading'),
    ('read_temperatures', 'one list', 'return times_s, temperatures_c', 'return temperatures_c',
     r'^read_temperatures\(\) returned list; return two lists: \(times_s, temperatures_c\)\.$'),
]


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


def test_an_untouched_cell_gets_one_line(session):
    untouched = answer_cells(LEARNER)[1]
    for name in CHECKS:
        assert 'raise NotImplementedError()' in untouched[name]
        with pytest.raises(CheckFailed) as caught:
            run_check(session, 'kernel', name, untouched[name])
        assert str(caught.value).startswith(f'{name}() still raises NotImplementedError')


def test_a_bag_opens_with_readers_the_course_does_not_own(session):
    """mcap's own reader (with mcap-ros2-support's decoder) and rosbags' AnyReader."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    from rosbags.highlevel import AnyReader

    namespace: dict = {}
    exec(CONTEXT.replace('_ = ros2nb.start', '# ') + '\n' + ANSWERS['record_hour'], namespace)
    bag = Path(tempfile.mkdtemp(prefix='ros2nb-bag-')) / 'hour'
    os.environ.pop(IN_JUDGE_ENV, None)
    namespace['record_hour'](bag)
    recorded = ros2nb.bag_info(bag)
    assert recorded['/temperature'] == 3600 and recorded['/rosout'] == 7200
    expected = {'/temperature': 'std_msgs/msg/Float32', '/rosout': 'rcl_interfaces/msg/Log'}

    counts, types, first = {}, {}, None
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for _schema, channel, _message, decoded in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            types[channel.topic] = _schema.name
            if channel.topic == '/temperature' and first is None:
                first = decoded.data
    assert counts == recorded
    assert {t: n.replace('/msg/', '/msg/') for t, n in types.items()} == expected
    assert 18.0 <= first <= 28.0

    with AnyReader([bag]) as reader:
        assert {c.topic: c.msgcount for c in reader.connections} == recorded
        assert {c.topic: c.msgtype for c in reader.connections} == expected
        logs = [reader.deserialize(raw, c.msgtype) for c, _t, raw in
                reader.messages([c for c in reader.connections if c.topic == '/rosout'])]
    assert sum('Status: ' in log.msg for log in logs) == 3600


@pytest.mark.parametrize('call, pattern', [
    (lambda d: ros2nb.bag_info(d / 'none'), r'is not a bag: a bag is a folder with a metadata'),
    (lambda d: ros2nb.bag_play(d / 'none'), r'is not a bag'),
    (lambda d: ros2nb.bag_record(d, '/temperature').__enter__(), r'already exists: choose'),
    (lambda d: ros2nb.bag_record(d / 'x', 5).__enter__(), r"Topics are names in quotes.*got 5"),
    (lambda d: ros2nb.bag_record(d / 'x').__enter__(), r'Name the topics to record'),
], ids=['info of no bag', 'play of no bag', 'record into an existing folder',
        'a topic that is not a name', 'no topic'])
def test_bad_input_to_the_bag_verbs_gets_one_line(tmp_path, call, pattern):
    ros2nb.start(sim_time=True)
    try:
        with pytest.raises((Ros2nbError, UsageError)) as caught:
            call(tmp_path)
        assert re.search(pattern, str(caught.value)) and '\n' not in str(caught.value)
    finally:
        ros2nb.shutdown()
