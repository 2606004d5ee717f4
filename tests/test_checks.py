"""The challenge checks fail with a helpful message on wrong answers and pass on right ones."""

from pathlib import Path

import pytest

from ros2nb import checks
from ros2nb.checks import CheckFailed


def unsolved(*_args):
    raise NotImplementedError()


def test_unsolved_challenge_says_so():
    with pytest.raises(CheckFailed, match='still raises NotImplementedError'):
        checks.check_classify(unsolved)


def test_classify_boundaries():
    checks.check_classify(checks.reference_status)
    with pytest.raises(CheckFailed, match=r"classify\(20.0\) returned 'Low'"):
        def classify(t):
            return 'High' if t > 26 else 'Low' if t <= 20 else 'Normal'
        checks.check_classify(classify)


def test_clamp():
    checks.check_clamp(lambda v: max(18.0, min(28.0, v)))
    with pytest.raises(CheckFailed, match=r'\(10.2\) returned 10.2'):
        checks.check_clamp(lambda v: max(10.2, min(28.0, v)))  # the tutorial's floor


def test_publisher_samples():
    good = [22.0 + 0.1 * i for i in range(10)]
    checks.check_publisher_samples(good, seconds=10)
    with pytest.raises(CheckFailed, match='one step is at most'):
        checks.check_publisher_samples([22.0, 23.0] + good[2:], seconds=10)
    with pytest.raises(CheckFailed, match='expected one per second'):
        checks.check_publisher_samples(good[:5], seconds=10)


def test_expanded_path():
    checks.check_expanded_path(lambda: Path('~/Documents/W').expanduser(), ends_with='Documents/W')
    with pytest.raises(CheckFailed, match='root of the disk'):
        checks.check_expanded_path(lambda: Path('/Documents/W'), ends_with='Documents/W')
    with pytest.raises(CheckFailed, match='expanduser'):
        checks.check_expanded_path(lambda: Path('~/Documents/W'), ends_with='Documents/W')


def test_dependencies(tmp_path):
    xml = tmp_path / 'package.xml'
    xml.write_text('<package format="3"><depend>rclpy</depend><test_depend>x</test_depend>'
                   '<depend>std_msgs</depend></package>')
    checks.check_dependencies(checks.package_dependencies, xml)
    with pytest.raises(CheckFailed, match='test_depend is not a depend'):
        checks.check_dependencies(lambda p: ['rclpy', 'x', 'std_msgs'], xml)


def test_endpoint():
    import ros2nb
    from rclpy.node import Node
    from std_msgs.msg import String

    class Listener(Node):
        def __init__(self):
            super().__init__('loud_listener')
            self.create_subscription(String, 'chater', lambda m: None, 10)

    ros2nb.start()
    try:
        with pytest.raises(CheckFailed, match='no subscription on /chatter'):
            checks.check_endpoint(Listener, 'subscription', '/chatter', 'std_msgs/msg/String')
        with pytest.raises(CheckFailed, match='uses std_msgs/msg/String, but the topic carries std_msgs/msg/Float32'):
            checks.check_endpoint(Listener, 'subscription', '/chater', 'std_msgs/msg/Float32')
        checks.check_endpoint(Listener, 'subscription', '/chater', 'std_msgs/msg/String')
    finally:
        ros2nb.shutdown()


def test_checks_say_when_ros_was_shut_down():
    from rclpy.node import Node
    with pytest.raises(CheckFailed, match=r'was rclpy.shutdown\(\) called\?'):
        checks.check_endpoint(Node, 'subscription', '/chatter', 'std_msgs/msg/String')
