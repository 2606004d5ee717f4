"""A learner whose code floods slowly: the CPU limit of one check, not a flood limit, ends it,
and the parts checked before it keep their points.

The attack is a denial of service on the class, not a forged point: notebook 03's callback
logs each reading and 449 lines more, under the judge's flood limit of 500 lines in a second
of its clock (``ros2nb.judge.floods``), so that the judge hears 1.6 million lines in the
hour it checks last.  It once cost its judge 269 CPU-seconds (an honest one about 14) and
held a class until the judge's 600-s limit; now the judge is stopped at the CPU limit of the
hour's check (``grading.judging.settings.JUDGE_CPU_S``), the hour is not checked and scores nothing,
and the constructor, the callback and ``main()`` keep their points, as a callback that stops
publishing would.  ``tests/test_floods.py`` grades it in the grader's sandbox;
``benchmarks/flood_class.py --kind callback`` measures what it costs a class.
"""

READING_LINE = "        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')\n"
#: Lines the callback logs for each reading.
CALLBACK_LINES = 450
SLOW_FLOOD = READING_LINE + f"""\
        for line in range({CALLBACK_LINES - 1}):
            self.get_logger().info(f'and again: line {{line}}')
"""
