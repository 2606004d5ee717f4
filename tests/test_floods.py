"""A loop that floods /rosout or a topic fails its part at once, with one line that names it.

As tests/test_checks.py: this process is the judge, the learner's code runs in real subject
processes.  Each learner below is the course's reference sensor whose constructor starts a
thread that logs (or publishes) as fast as it can, as a beginner's loop without a timer does.
The judge once waited for every line it was told of: such a sensor kept notebook 03 in the
judge until its 600-s limit (this file's tests then end at their own limit).  Now the judge
counts what it hears on its own clock (``ros2nb.judge.floods``), ends the flooding processes
and fails the part with the flood's line; the parts the course's stand-in grades alone keep
their points.  What a class pays for a flooder is measured by CPU seconds in
``benchmarks/flood_class.py`` (docs/decisions.md), not asserted here.
"""

import pytest

from ros2nb import checks

from judging import run_check
from test_checks import PUB, fails, mutated, restore

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]

STARTED_LINE = "        self.get_logger().info('Temperature Sensor Node Started')\n"
#: The constructor's last lines, then a thread that logs without waiting.
LOG_FLOOD = STARTED_LINE + '''\
        import threading

        def chatter():
            while True:
                self.get_logger().info('still here')

        threading.Thread(target=chatter, daemon=True).start()
'''
#: The constructor's last lines, then a thread that publishes readings without waiting.
TOPIC_FLOOD = STARTED_LINE + '''\
        import threading

        def chatter():
            while True:
                self.publisher_.publish(Float32(data=self.temperature))

        threading.Thread(target=chatter, daemon=True).start()
'''
WHEN = r"(while the grader's clock stood still|in [\d.]+ s of the grader's clock)"


def test_a_constructor_that_floods_rosout(session):
    mutated(session, PUB, STARTED_LINE, LOG_FLOOD)
    try:
        fails(session, checks.check_sensor_constructor,
              rf'^Your node temperature_sensor logged over 500 lines to /rosout {WHEN} .*'
              r'look for a loop that logs without waiting for a timer\.$')
        # part 4 is the reference's: with the course's constructor it keeps its points
        run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)
    # what the ended flooder still had on its way reaches no later check
    run_check(session, checks.check_sensor_constructor)


def test_a_constructor_that_floods_the_topic(session):
    mutated(session, PUB, STARTED_LINE, TOPIC_FLOOD)
    try:
        fails(session, checks.check_sensor_constructor,
              rf'^Your code published over 500 messages on /temperature {WHEN} .*'
              r'look for a loop that publishes without waiting for a timer\.$')
        run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)
