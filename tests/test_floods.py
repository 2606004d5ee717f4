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

from ros2nb import checks, course
from ros2nb.judge.floods import CHECK_FLOOD_LIMIT
from ros2nb_instructor.grading.sandbox import bubblewrap

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
#: The line of a logger that sends more in one check than the course's nodes in any.
CHECK_LINE = ('Your node temperature_sensor logged over {limit:,} lines to /rosout in one check (a '
              'node of the course logs one line per reading or tick, 3,600 in an hour): look for '
              'a loop that logs many lines for each reading.')
#: The constructor that floods ``kind`` (a key of WORK).
FLOODS = {kind: FLOODING_CONSTRUCTOR.format(work=work) for kind, work in WORK.items()}
WHEN = r"(while the grader's clock stood still|in [\d.]+ s of the grader's clock)"
#: The line each flood fails the constructor's check with.
LINES = {'rosout': rf'^Your node temperature_sensor logged over 500 lines to /rosout {WHEN} .*'
                   r'look for a loop that logs without waiting for a timer\.$',
         'topic': rf'^Your code published over 500 messages on /temperature {WHEN} .*'
                  r'look for a loop that publishes without waiting for a timer\.$'}


def flooder_notebook(kind: str) -> dict:
    """Notebook 03 as the solution, its constructor flooding ``kind`` (a key of WORK), or
    with ``'callback'`` its callback logging 450 lines a reading (``corpus_floods.py``), as a
    learner hands it in (for the grader: ``benchmarks/flood_class.py``,
    ``tests/test_notebook_cpu.py``)."""
    from corpora import Learner, submission
    from corpus_floods import READING_LINE, SLOW_FLOOD
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


def test_a_flood_while_the_judge_waits_for_the_node_ends_the_wait(session):
    """The constructor starts its flood, then blocks: the judge, still waiting for the node,
    ends it as a flood, and part 4 runs in the course's constructor.  Before, the flood's
    CPU-seconds ran out the subject's patience first, and part 4 failed with "did not finish
    within 30 s": on a busy machine, so did a constructor that floods and returns at once."""
    blocks = FLOODS['topic'] + '        import time\n        time.sleep(600)\n'
    mutated(session, PUB, STARTED_LINE, blocks)
    try:
        fails(session, checks.check_sensor_constructor, LINES['topic'])
        run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)


def test_what_one_run_of_main_logs_counts_in_that_run_alone(session):
    """main() runs four times in its check, on the machine's clock while the judge's stands
    still: every line of the check fell in one window of the judge's clock.  A main() that
    logs 200 lines before it spins (under the window's 500) failed as a flood in its third
    run on any machine, and a slow flood's late lines from one run, arriving as the next
    began, failed main() on a busy one.  Counted per run, it keeps its point."""
    chatty = ('    node = TemperatureSensor()\n'
              "    for line in range(200):\n"
              "        node.get_logger().info(f'starting, step {line}')\n")
    mutated(session, PUB, '    node = TemperatureSensor()\n', chatty)
    try:
        run_check(session, checks.check_sensor_main)
    finally:
        restore(session, PUB)


@pytest.mark.sandbox
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
@pytest.mark.timeout(900)
def test_a_slow_flood_is_found_by_what_one_check_hears(tmp_path, monkeypatch):
    """A callback that logs 450 lines a reading never floods a window of the judge's clock,
    but its hour sends 1.6 million lines: its judge once worked on for 269 CPU-seconds, until
    the 600-s limit; later its CPU limit stopped it, in whichever check the limit met, which
    depended on the machine's load (main()'s point did).  Graded as the grader does (the
    judge in its sandbox, its subjects sandboxed inside), each check that runs the callback
    for many readings hears more lines than any node of the course sends in one check and
    fails with the flood's line; the constructor and main() keep their points; no limit of
    the grader's is met.  Counted in lines, the verdict is the same on any machine."""
    import nbformat
    from corpora import Learner as CorpusLearner, submission, write_parts
    from corpus_floods import READING_LINE, SLOW_FLOOD
    from ros2nb_instructor.grading.judging.judges import judge_notebook
    from ros2nb_instructor.grading.sandbox.scratch import Scratch
    from ros2nb_instructor.grading.judging.settings import Settings
    from ros2nb_instructor.grading.intake.submissions import Learner
    from ros2nb.terminal import workspace as ws_module
    nb = submission(CorpusLearner('flooder', '03', {'sensor-callback': [
        (READING_LINE, SLOW_FLOOD)]}))
    scratch = Scratch(tmp_path, Learner('flooder', 'flooder'))
    monkeypatch.setenv('ROS2NB_WORKSPACE', str(scratch.workspace))
    monkeypatch.setattr(ws_module, '_current', None)
    try:
        course.catch_up(3)  # the workspace as notebook 02 leaves it
        write_parts(nb)
        notebook = '03-write-the-publisher'
        results, problem, _flags = judge_notebook(
            scratch, notebook, nbformat.from_dict(nb), Settings(120, 600, True),
            scratch.snapshot(notebook))
    finally:
        scratch.remove()
    assert problem is None, problem
    assert [gid for gid, result in results.items() if result.passed] == [
        '03-sensor-constructor', '03-sensor-main'], results
    line = CHECK_LINE.format(limit=CHECK_FLOOD_LIMIT)
    assert results['03-sensor-callback'].message == line, results
    assert results['03-sensor-hour'].message == line, results
