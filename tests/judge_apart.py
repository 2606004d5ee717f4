"""The judge's own command, ``python -m ros2nb.judge grade SOURCE SUBMISSION``, for the corpora.

``python tests/judge_apart.py [--knows-nothing] [--hour-s S] SOURCE SUBMISSION [--seed N]``
grades one submission as the grader's judge does (a process of its own, started in a
session of its own, the course's reference nodes hidden by ``ROS2NB_GRADING``, with the
grading's seed when given), and prints the judge's JSON lines.  With ``--knows-nothing`` the
judge's reader of the learner's text (:data:`ros2nb.checks.source.TEXT`) finds nothing: no
point may depend on reading the learner's code.  With ``--hour-s S`` notebook 03's hidden
hour, and the hour notebook 10 records, last S simulated seconds: each hour is most of its
grading's CPU time, and a corpus's learner graded for another part needs no more of it
(``corpora.py``: ``SHORT_HOUR_S``, which also shortens the hour of 10's grading context).

The corpora's tests (``corpora.py``) start it rather than judging in the test process: a judge
steps its subject's clock one simulated second at a time, each step a turn of each process,
and in pytest-xdist's worker the judge shared the worker's scheduling group (its session) with
every other worker, and beside CPU burners started from the same shell one hour of notebook
03 took its test many times as long (docs/decisions.md).
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Optional

from ros2nb.subject.forked import serve_from_here


def main(argv: list[str]) -> int:
    """Grade SOURCE's graded cells on SUBMISSION, as ``python -m ros2nb.judge grade``."""
    serve_from_here()  # as the judge's main does, before the checks are imported
    from ros2nb.checks import source

    class KnowsNothing(source.TextReader):
        """A reader of the learner's text that never finds anything."""

        def read(self, path: Path) -> Optional[str]:
            return None

    knows_nothing = '--knows-nothing' in argv
    paths = [arg for arg in argv if arg != '--knows-nothing']
    if knows_nothing:  # the one reader's method: modules hold the reader itself
        source.TEXT.read = KnowsNothing().read  # type: ignore[method-assign]  # reads nothing
    if paths[:1] == ['--hour-s']:
        from ros2nb import course
        from ros2nb.checks import lesson03
        lesson03.HOUR_S = int(paths[1])
        course.RECORD_S = float(paths[1])
        paths = paths[2:]
    from ros2nb.judge.__main__ import main as judge
    return judge(['grade', *paths])  # SOURCE SUBMISSION [--seed N]


if __name__ == '__main__':
    from ros2nb.processes import end_this_process
    end_this_process(main(sys.argv[1:]))
