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
#: The constructor's last lines, then a thread that does ``{work}`` without waiting.
FLOODING_CONSTRUCTOR = STARTED_LINE + '''\
        import threading

        def chatter():
            while True:
                {work}

        threading.Thread(target=chatter, daemon=True).start()
'''
#: What each flooder's thread does: log, or publish readings.
WORK = {'rosout': "self.get_logger().info('still here')",
        'topic': 'self.publisher_.publish(Float32(data=self.temperature))'}
#: The constructor that floods ``kind`` (a key of WORK).
FLOODS = {kind: FLOODING_CONSTRUCTOR.format(work=work) for kind, work in WORK.items()}
READING_LINE = "        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')\n"
#: A slow flood inside the callback: each reading logged with 449 lines more, under the
#: judge's flood limit per second of its clock (500), so that no flood is ever raised: a
#: judge that hears it all for notebook 03's simulated hour (1.6 million lines) once cost
#: 269 CPU-seconds, an honest one about 14; now it is stopped at its CPU limit.
CALLBACK_LINES = 450
SLOW_FLOOD = READING_LINE + f"""\
        for line in range({CALLBACK_LINES - 1}):
            self.get_logger().info(f'and again: line {{line}}')
"""
WHEN = r"(while the grader's clock stood still|in [\d.]+ s of the grader's clock)"
#: The line each flood fails the constructor's check with.
LINES = {'rosout': rf'^Your node temperature_sensor logged over 500 lines to /rosout {WHEN} .*'
                   r'look for a loop that logs without waiting for a timer\.$',
         'topic': rf'^Your code published over 500 messages on /temperature {WHEN} .*'
                  r'look for a loop that publishes without waiting for a timer\.$'}


def flooder_notebook(kind: str) -> dict:
    """Notebook 03 as the solution, its constructor flooding ``kind`` (a key of WORK), or
    with ``'callback'`` its callback logging :data:`CALLBACK_LINES` lines a reading, as a
    learner hands it in (for the grader: ``benchmarks/flood_class.py``,
    ``tests/test_notebook_cpu.py``)."""
    from corpora import Learner, submission
    if kind == 'callback':
        return submission(Learner('flooder', '03', {'sensor-callback': [
            (READING_LINE, SLOW_FLOOD)]}))
    return submission(Learner('flooder', '03', {'sensor-constructor': [
        (STARTED_LINE, FLOODS[kind])]}))


@pytest.mark.parametrize('kind', sorted(WORK))
def test_a_constructor_that_floods(session, kind):
    mutated(session, PUB, STARTED_LINE, FLOODS[kind])
    try:
        fails(session, checks.check_sensor_constructor, LINES[kind])
        # part 4 is the reference's: with the course's constructor it keeps its points
        run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)
    # what the ended flooder still had on its way reaches no later check
    run_check(session, checks.check_sensor_constructor)
