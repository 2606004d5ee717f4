"""The grader's stand-in nodes of notebook 05 stop with exit code 0 even when rclpy's own
Ctrl+C race strikes: a learner never loses notebook 05's points to it.

The race, made to happen every time with real rclpy: a timer's callback shuts rclpy down (what
rclpy's signal thread does at Ctrl+C) and then publishes, the call that failed in the runs the
clause's comment counts (``RCLError: Failed to publish: publisher's context is invalid``).
"""

import os
import subprocess
import sys

import pytest

from ros2nb import domains
from ros2nb.checks.package_stand_ins import RCLPY_SHUTDOWN_RACE, STAND_IN
from waiting import run_to_end

pytestmark = pytest.mark.ros

#: A stand-in whose timer meets the race at its first tick.
RACING = dict(name='racing_sensor', does='meets the race at its first tick',
              setup="publisher = node.create_publisher(Float32, 'temperature', 10)\n"
                    "    def tick():\n"
                    "        rclpy.shutdown()  # rclpy's signal thread, at Ctrl+C\n"
                    "        publisher.publish(Float32(data=1.0))  # the callback, a moment later\n"
                    "    node.create_timer(0.05, tick)")


def run(race: str, tmp_path) -> subprocess.CompletedProcess:
    script = tmp_path / 'stand_in.py'
    script.write_text(STAND_IN.format(race=race, **RACING) + '\nmain()\n')
    env = {**os.environ, 'ROS_DOMAIN_ID': str(domains.domain_id())}
    return run_to_end([sys.executable, str(script)], 'the stand-in', env=env)


def test_a_stand_in_meeting_rclpys_race_exits_0(tmp_path):
    done = run(RCLPY_SHUTDOWN_RACE, tmp_path)
    assert done.returncode == 0, done.stderr


def test_without_the_clause_the_race_fails_the_stand_in(tmp_path):
    """The failure the clause prevents: the stand-in ends with the race's RCLError."""
    done = run('', tmp_path)
    assert done.returncode == 1
    assert "publisher's context is invalid" in done.stderr.splitlines()[-1]
