"""The graph verbs, on real nodes, compared with what the ros2 CLI prints."""

import math
import random

import pytest

import ros2nb

from nodes import Monitor, Sensor
from waiting import wait_for

pytestmark = pytest.mark.ros


def test_node_list_hides_internal_node(ros, capsys):
    ros2nb.add(Sensor())
    ros2nb.add(Monitor())
    assert ros2nb.node_list() == ['/temperature_monitor', '/temperature_sensor']
    assert '/_ros2nb' in ros2nb.node_list(all=True)


def test_topic_list_with_types_and_typo_note(ros, capsys):
    ros2nb.add(Sensor())
    ros2nb.add(Monitor(topic='temprature'))
    topics = ros2nb.topic_list(show_types=True)
    out = capsys.readouterr().out
    assert {'/temperature', '/temprature', '/rosout', '/parameter_events'} <= set(topics)
    assert '/temperature [std_msgs/msg/Float32]' in out
    assert ('Note: /temperature has 1 publisher(s) but no subscription: '
            'is it a typo of /temprature?') in out
    assert 'Note: /temprature has 1 subscription(s) but no publisher' in out


def test_matched_topics_give_no_note(ros, capsys):
    ros2nb.add(Sensor())
    ros2nb.add(Monitor())
    assert ros2nb.unmatched_topics() == []


def test_topic_info_counts_and_qos(ros, capsys):
    ros2nb.add(Sensor())
    ros2nb.add(Monitor())
    assert ros2nb.topic_info('temperature') == {'publishers': 1, 'subscriptions': 1}
    ros2nb.topic_info('/temperature', verbose=True)
    out = capsys.readouterr().out
    assert 'Type: std_msgs/msg/Float32' in out
    assert 'Node name: temperature_sensor' in out and 'Endpoint type: PUBLISHER' in out
    assert 'Reliability: RELIABLE' in out and 'Durability: VOLATILE' in out


def test_topic_info_unknown_topic_suggests(ros):
    ros2nb.add(Sensor())
    with pytest.raises(ros2nb.Ros2nbError, match=r"Unknown topic '/temprature'. "
                                                 r"Did you mean /temperature\?"):
        ros2nb.topic_info('temprature')


def test_topic_echo_prints_yaml(ros, capsys):
    random.seed(3)
    sensor = ros2nb.add(Sensor())
    messages = ros2nb.topic_echo('temperature', count=2)
    out = capsys.readouterr().out
    assert messages[-1].data == pytest.approx(sensor.value, abs=1e-5)  # float32 of the last walk
    assert abs(messages[1].data - messages[0].data) <= 0.5 + 1e-5
    assert out.count('---') == 2
    assert f'data: {messages[0].data!r}\n---' in out


def test_topic_echo_unknown_type(ros):
    with pytest.raises(ros2nb.Ros2nbError, match='does not appear to be published yet'):
        ros2nb.topic_echo('nothing_here')


def test_topic_echo_times_out_with_advice(ros, capsys):
    ros2nb.add(Monitor())
    got = ros2nb.topic_echo('temperature', 'std_msgs/msg/Float32', count=1, timeout=3)
    assert got == []
    assert 'Received 0 of 1 messages in 3 s' in capsys.readouterr().out


def test_topic_hz_on_sim_time(ros, capsys):
    ros2nb.add(Sensor())
    rate = ros2nb.topic_hz('temperature', window=5)
    assert rate == pytest.approx(1.0)
    assert 'average rate: 1.000' in capsys.readouterr().out


def test_topic_hz_without_messages(ros, capsys):
    ros2nb.add(Monitor())
    assert math.isnan(ros2nb.topic_hz('temperature', 'std_msgs/msg/Float32', timeout=2))


def test_record_an_hour(ros, capsys):
    random.seed(4)
    ros2nb.add(Sensor())
    times, values = ros2nb.record('temperature', 3600)
    assert len(times) == len(values) == 3600
    assert times[0] == pytest.approx(1.0) and times[-1] == pytest.approx(3600.0)
    assert 'Publishing' not in capsys.readouterr().out


def test_message_type_errors():
    with pytest.raises(ros2nb.Ros2nbError, match='package/msg/Type'):
        ros2nb.message_type('Float32')
    with pytest.raises(ros2nb.Ros2nbError, match='not installed'):
        ros2nb.message_type('nope_msgs/msg/Nope')


def test_record_wrong_field_fails_at_once(ros):
    ros2nb.add(Sensor())
    with pytest.raises(ros2nb.Ros2nbError, match=r"Float32 has no field 'temp'; "
                                                 r"its fields are data"):
        ros2nb.record('temperature', 600, field='temp')
    assert ros2nb.current_runtime().sim_now_ns == 0  # nothing ran


def test_record_unknown_topic_suggests(ros):
    ros2nb.add(Sensor())
    with pytest.raises(ros2nb.Ros2nbError, match=r'does not appear to be published yet.*'
                                                 r'Did you mean /temperature\?'):
        ros2nb.record('temprature', 10)


def test_two_message_types_on_one_topic_are_noted(ros, capsys):
    """Across processes a Float64 subscription just never hears a Float32 publisher."""
    import subprocess
    import sys
    code = ('import rclpy\nfrom std_msgs.msg import Float64\nrclpy.init()\n'
            'node = rclpy.create_node("float64_monitor")\n'
            'node.create_subscription(Float64, "temperature", print, 10)\n'
            'print("up", flush=True)\nrclpy.spin(node)\n')
    monitor = subprocess.Popen([sys.executable, '-c', code], stdout=subprocess.PIPE, text=True)
    try:
        assert monitor.stdout.readline().strip() == 'up'
        ros2nb.add(Sensor())
        graph = ros2nb.current_runtime().node
        wait_for(lambda: 'float64_monitor' in [
            info.node_name for info in graph.get_subscriptions_info_by_topic('/temperature')],
            'float64_monitor in the graph',
            seen=lambda: graph.get_node_names_and_namespaces())
        capsys.readouterr()
        ros2nb.topic_list()
        assert ('Note: /temperature is used with 2 message types: std_msgs/msg/Float32 '
                '(temperature_sensor), std_msgs/msg/Float64 (float64_monitor); both sides must '
                'use the same type') in capsys.readouterr().out
    finally:
        monitor.kill()
        monitor.wait()
