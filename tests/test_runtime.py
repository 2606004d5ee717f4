"""ros2nb's runtime against real rclpy over real DDS (no mocks of ROS)."""

import random
import threading

import pytest
import rclpy

import importlib
import subprocess
import sys

import ros2nb

rt_module = importlib.import_module('ros2nb.runtime')

from nodes import Broken, Monitor, Sensor


@pytest.fixture
def ros():
    rt = ros2nb.start(sim_time=True)
    yield rt
    ros2nb.shutdown()


def test_import_does_nothing():
    probe = ('import threading, rclpy, ros2nb, os; '
             'print(rclpy.ok(), threading.active_count(), "ROS_PYTHON_CHECK_FIELDS" in os.environ)')
    env = {k: v for k, v in __import__('os').environ.items() if k != 'ROS_PYTHON_CHECK_FIELDS'}
    out = subprocess.run([sys.executable, '-c', probe], capture_output=True, text=True,
                         env=env, check=True).stdout.split()
    assert out == ['False', '1', 'False']


def test_start_is_idempotent(ros):
    assert rt_module._runtime is ros
    assert ros2nb.start(sim_time=True) is ros
    assert rclpy.ok()
    threads = [t for t in threading.enumerate() if t.name == 'ros2nb-executor']
    assert len(threads) == 1


def test_start_refuses_other_domain(ros):
    other = (ros.domain_id + 1) % 100
    with pytest.raises(ros2nb.Ros2nbError, match='already up on domain'):
        ros2nb.start(domain_id=other)


def test_start_turns_on_field_checks(ros):
    from std_msgs.msg import Float32
    with pytest.raises(AssertionError, match="'data' field must be of type 'float'"):
        Float32(data='hot')


def test_calls_before_start_say_what_to_do():
    assert rt_module._runtime is None
    with pytest.raises(ros2nb.Ros2nbError, match=r'run ros2nb.start\(\) first'):
        ros2nb.spin(1)


def test_same_name_replaces_old_node(ros, capsys):
    first = ros2nb.add(Sensor())
    second = ros2nb.add(Sensor())
    assert list(ros.nodes) == ['/temperature_sensor']
    assert ros.nodes['/temperature_sensor'] is second
    assert list(first.timers) == [] and list(first.publishers) == []  # nothing stale left
    monitor = ros2nb.add(Monitor())
    capsys.readouterr()
    ros2nb.spin(5)
    assert len(monitor.received) == 5  # one sensor, not two
    out = capsys.readouterr().out  # the new node's logs still reach the cell
    assert out.count('[INFO] [temperature_sensor]: Publishing:') == 5
    assert ros2nb.topic_info('temperature', verbose=True)['publishers'] == 1
    assert '_NODE_NAME_UNKNOWN_' not in capsys.readouterr().out


def test_stop_one_and_all(ros):
    ros2nb.add(Sensor())
    ros2nb.add(Monitor())
    assert ros2nb.stop('temperature_monitor') == ['temperature_monitor']
    assert list(ros.nodes) == ['/temperature_sensor']
    with pytest.raises(ros2nb.Ros2nbError, match='No running node'):
        ros2nb.stop('temperature_monitor')
    assert ros2nb.stop() == ['temperature_sensor']
    assert ros.nodes == {}


def test_spin_prints_logs_in_console_format(ros, capsys):
    random.seed(1)
    ros2nb.add(Sensor())
    ros2nb.spin(2)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == '[INFO] [temperature_sensor]: started'
    assert len(lines) == 3
    assert all(line.startswith('[INFO] [temperature_sensor]: Publishing: ') for line in lines[1:])


def test_callback_exception_reported_and_executor_alive(ros, capsys):
    ros2nb.add(Broken())
    monitor = ros2nb.add(Monitor())
    ros2nb.add(Sensor())
    ros2nb.spin(3)
    captured = capsys.readouterr()
    assert captured.err.count('[ERROR] [broken]') == 1  # reported once, then stopped
    assert '[ERROR] [broken]: callback Broken.explode raised ZeroDivisionError' in captured.err
    assert "raise ZeroDivisionError('division by zero')" in captured.err  # the learner's line
    assert '/broken' not in ros.nodes
    assert len(monitor.received) == 3  # the other nodes kept running


def test_shutdown_joins_thread_and_allows_restart():
    rt = ros2nb.start()
    ros2nb.add(Sensor())
    thread = rt._thread
    ros2nb.shutdown()
    assert not thread.is_alive()
    assert not rclpy.ok()
    ros2nb.shutdown()  # twice is harmless
    ros2nb.start()
    assert rclpy.ok()
    ros2nb.shutdown()


def _sim_run(seed: int) -> str:
    import contextlib
    import io
    out = io.StringIO()
    ros2nb.start(sim_time=True)
    try:
        with contextlib.redirect_stdout(out):
            random.seed(seed)
            ros2nb.add(Sensor())
            ros2nb.add(Monitor())
            ros2nb.spin(30)
    finally:
        ros2nb.shutdown()
    return out.getvalue()


def test_sim_time_is_deterministic():
    first, second = _sim_run(7), _sim_run(7)
    assert first == second
    assert first.count('Publishing:') == 30
    assert first.count('Temperature:') == 30
    assert _sim_run(8) != first


def test_wall_clock_spin_runs_in_real_time(ros):
    import time
    monitor = ros2nb.add(Monitor())
    ros2nb.add(Sensor())
    started = time.monotonic()
    ros2nb.spin(1.5, sim_time=False)
    assert time.monotonic() - started >= 1.5
    assert 1 <= len(monitor.received) <= 2


def test_spin_rejects_negative_seconds(ros):
    with pytest.raises(ValueError, match='zero or more'):
        ros2nb.spin(-1)


def test_fixed_node_readded_after_failure_keeps_its_logs(ros, capsys):
    """Learner flow: a callback raises, they fix the class and re-run the cell."""
    import gc
    broken = ros2nb.add(Broken())
    ros2nb.spin(2)
    assert '[ERROR] [broken]' in capsys.readouterr().err

    class Fixed(Broken):
        def explode(self) -> None:
            self.get_logger().info('fixed')

    broken = ros2nb.add(Fixed())  # drops the learner's last reference to the failed node
    gc.collect()
    ros2nb.spin(3)
    assert capsys.readouterr().out.count('[INFO] [broken]: fixed') == 3
