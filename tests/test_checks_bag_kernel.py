"""The checks of notebook 10 as the kernel runs them: the learner's function called here.

ROS is up in this process on simulated time, as in the lesson's kernel, and no judge is
(the judge's half is ``test_checks_bag_judge.py``; the cases are ``bag_cases.py``'s). Each
check records or replays with a real rclpy runtime and reads a real bag with rosbags. Also:
a bag written the lesson's way opens with readers the course does not own, and bad input to
the bag verbs gets one line.
"""

import re
import sys

import pytest

pytestmark = [pytest.mark.ros,
              pytest.mark.timeout(600),
              pytest.mark.skipif(sys.version_info < (3, 11),
                                 reason='bags need Python 3.11 or newer (rosbags needs apsw)')]

import ros2nb  # noqa: E402
from ros2nb.errors import CheckFailed, Ros2nbError, UsageError  # noqa: E402
from ros2nb.terminal.bag import metadata  # noqa: E402
from ros2nb.terminal.workspace import WORKSPACE_ENV  # noqa: E402

from bag_cases import (ANSWERS, CHECKS, CONTEXT_WITHOUT_START, LEARNER, MISTAKE_IDS,  # noqa: E402
                       MISTAKES, edited, recording_length, with_hour)
from judging import answer_cells  # noqa: E402


@pytest.fixture(scope='module')
def kernel(tmp_path_factory):
    """A workspace caught up to notebook 10 (its sensor and monitor), and ROS up in this
    process on simulated time, as the lesson's kernel has them; no judge."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv(WORKSPACE_ENV, str(tmp_path_factory.mktemp('checks10') / 'ws'))
        ros2nb.course.catch_up(10)
        ros2nb.start(sim_time=True)
        yield
        ros2nb.shutdown()


def defined(answer: str, context: str = CONTEXT_WITHOUT_START) -> dict:
    """The names an answer cell defines, run after the grading context as the kernel runs it."""
    namespace: dict = {}
    exec(context + '\n' + answer, namespace)
    return namespace


def test_the_solutions_pass(kernel, capsys):
    for name, answer in ANSWERS.items():
        CHECKS[name](defined(answer)[name])
    assert capsys.readouterr().out.count('Check passed:') == 3


@pytest.mark.parametrize('name, label, old, new, pattern', MISTAKES, ids=MISTAKE_IDS)
def test_a_mistake_gets_one_line(kernel, name, label, old, new, pattern, monkeypatch):
    seconds = recording_length(name, old)
    if seconds is not None:
        monkeypatch.setattr(ros2nb.course, 'RECORD_S', float(seconds))
    context = with_hour(CONTEXT_WITHOUT_START, seconds)
    with pytest.raises(CheckFailed) as caught:
        CHECKS[name](defined(edited(name, old, new), context)[name])
    message = str(caught.value)
    assert '\n' not in message and re.search(pattern, message), message


def test_an_untouched_cell_gets_one_line(kernel):
    untouched = answer_cells(LEARNER)[1]
    for name in CHECKS:
        assert 'raise NotImplementedError()' in untouched[name]
        with pytest.raises(CheckFailed) as caught:
            CHECKS[name](defined(untouched[name])[name])
        assert str(caught.value).startswith(f'{name}() still raises NotImplementedError')


def test_a_bag_opens_with_readers_the_course_does_not_own(kernel, tmp_path):
    """mcap's own reader (with mcap-ros2-support's decoder) and rosbags' AnyReader."""
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory
    from rosbags.highlevel import AnyReader

    bag = tmp_path / 'hour'
    defined(ANSWERS['record_hour'])['record_hour'](bag)
    recorded = ros2nb.bag_info(bag)
    assert recorded['/temperature'] == 3600 and recorded['/rosout'] == 7200
    expected = {'/temperature': 'std_msgs/msg/Float32', '/rosout': 'rcl_interfaces/msg/Log'}

    counts, types, first = {}, {}, None
    with open(next(bag.glob('*.mcap')), 'rb') as stream:
        reader = make_reader(stream, decoder_factories=[DecoderFactory()])
        for schema, channel, _message, decoded in reader.iter_decoded_messages():
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            types[channel.topic] = schema.name
            if channel.topic == '/temperature' and first is None:
                first = decoded.data
    assert counts == recorded
    assert types == expected
    assert 18.0 <= first <= 28.0

    with AnyReader([bag]) as reader:
        assert {c.topic: c.msgcount for c in reader.connections} == recorded
        assert {c.topic: c.msgtype for c in reader.connections} == expected
        logs = [reader.deserialize(raw, c.msgtype) for c, _t, raw in
                reader.messages([c for c in reader.connections if c.topic == '/rosout'])]
    assert sum('Status: ' in log.msg for log in logs) == 3600


def test_a_recording_of_rosout_may_start_before_the_node_that_logs(kernel, tmp_path):
    """/rosout's type is ROS's own: the notebook records a replay's statuses before its
    replay() adds the monitor.  A topic of the course's still needs its publisher first (the
    nodes added inside the with block: the check and the next cell both refuse it)."""
    nodes = defined('')
    ros2nb.stop()  # no node of an earlier test publishes anything
    with pytest.raises(UsageError, match=r'^/temperature has no publisher in the ROS graph yet'):
        ros2nb.bag_record(tmp_path / 'early', '/temperature', '/rosout')
    with ros2nb.bag_record(tmp_path / 'statuses', '/rosout'):
        ros2nb.add(nodes['pub'].TemperatureSensor())
        ros2nb.add(nodes['sub'].TemperatureMonitor())
        ros2nb.spin(5, show_logs=False)
    ros2nb.stop()
    recorded = metadata(tmp_path / 'statuses')['topics_with_message_count']
    topics = {t['topic_metadata']['name']: t['topic_metadata']['type'] for t in recorded}
    assert topics == {'/rosout': 'rcl_interfaces/msg/Log'}
    assert ros2nb.bag_info(tmp_path / 'statuses')['/rosout'] >= 5  # a status per reading


@pytest.mark.parametrize('call, pattern', [
    (lambda d: ros2nb.bag_info(d / 'none'), r'is not a bag: a bag is a folder with a metadata'),
    (lambda d: ros2nb.bag_play(d / 'none'), r'is not a bag'),
    (lambda d: ros2nb.bag_record(d, '/temperature').__enter__(), r'already exists: choose'),
    (lambda d: ros2nb.bag_record(d / 'x', 5).__enter__(), r"Topics are names in quotes.*got 5"),
    (lambda d: ros2nb.bag_record(d / 'x').__enter__(), r'Name the topics to record'),
], ids=['info of no bag', 'play of no bag', 'record into an existing folder',
        'a topic that is not a name', 'no topic'])
def test_bad_input_to_the_bag_verbs_gets_one_line(kernel, tmp_path, call, pattern):
    with pytest.raises((Ros2nbError, UsageError)) as caught:
        call(tmp_path)
    assert re.search(pattern, str(caught.value)) and '\n' not in str(caught.value)
