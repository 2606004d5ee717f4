"""A learner whose code floods slowly, beside its twin: the judge's CPU limit, not a flood
limit, ends it, and the parts checked before it keep their points.

The attack is a denial of service on the class, not a forged point: notebook 03's callback
logs each reading and 449 lines more, under the judge's flood limit of 500 lines in a second
of its clock (``ros2nb.judge.floods``), so that the judge hears 1.6 million lines in the
hour it checks last.  It once cost its judge 269 CPU-seconds (an honest one about 14) and
held a class until the judge's 600-s limit; now the judge is stopped at its CPU limit
(``grading.settings.JUDGE_CPU_S``), the hour is not checked and scores nothing, and the
constructor, the callback and ``main()`` keep their points: its twin is a callback that
stops publishing, so that only the hour fails.  ``tests/test_floods.py`` grades it in the
grader's sandbox; ``benchmarks/flood_class.py --kind callback`` measures what it costs a class.
"""

from corpora import Learner

READING_LINE = "        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')\n"
#: Lines the callback logs for each reading.
CALLBACK_LINES = 450
SLOW_FLOOD = READING_LINE + f"""\
        for line in range({CALLBACK_LINES - 1}):
            self.get_logger().info(f'and again: line {{line}}')
"""
STEP_LINE = '        step = random.uniform(-MAX_STEP_C, MAX_STEP_C)\n'
#: The twin's callback publishes 600 readings, then returns at once: more than the callback's
#: check takes, fewer than the hour's 3600.
STOPS = """\
        self.published = getattr(self, 'published', 0) + 1
        if self.published > 600:
            return
""" + STEP_LINE

FLOODERS = [
    Learner('03 twin: a callback that stops publishing after 600 readings', '03',
            {'sensor-callback': [(STEP_LINE, STOPS)]}, loses=('sensor-hour',)),
    Learner('03 attack: a slow flood, 450 lines a reading from the callback', '03',
            {'sensor-callback': [(READING_LINE, SLOW_FLOOD)]},
            twin='03 twin: a callback that stops publishing after 600 readings'),
]
