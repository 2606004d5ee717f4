"""``python -m ros2nb.judge check NAME`` or ``grade SOURCE SUBMISSION [--seed N]``.

The judge's command line (see :mod:`ros2nb.judge`): it opens a :class:`Session`, runs the
body of each check asked for with it (:func:`ros2nb.checks.run_check`) and prints one JSON
line with the outcome; while grading, also one line per graded cell as soon as it is decided
(``{"cell": ID, "result": ...}``), which is what a judge stopped at its limits leaves.  A
check draws its inputs from a seed the judge draws itself; only the grader gives one
(``--seed``, :mod:`ros2nb.checks.drawn`), the learner's kernel never.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any, Optional

from .. import checks
from ..checks.drawn import SEED_OPTION, parse_seed
from ..errors import Ros2nbError
from ..processes import end_this_process
from ..subject.forked import serve_from_here
from ..terminal.workspace import default_workspace
from .graded_cells import grade
from ..judge_interface import captured
from .session import Session
from .subjects import subject_prefix


USAGE = f'Usage: python -m ros2nb.judge check NAME | grade SOURCE SUBMISSION [{SEED_OPTION} N]'


def arguments(argv: list[str]) -> tuple[list[str], Optional[int]]:
    """The command (``check NAME`` or ``grade SOURCE SUBMISSION``) and the grader's seed of
    the drawn inputs (None: the judge draws one).  Only ``grade`` takes a seed: a check in
    the lab is asked for by the learner's kernel, which must not choose its inputs.

    :raises Ros2nbError: with the usage, or with what is wrong with the seed.
    """
    seed = None
    if argv[:1] == ['grade'] and len(argv) == 5 and argv[3] == SEED_OPTION:
        argv, seed = argv[:3], parse_seed(argv[4])
    if (argv[:1], len(argv)) not in ((['check'], 2), (['grade'], 3)):
        raise Ros2nbError(USAGE)
    return argv, seed


def main(argv: list[str]) -> int:
    """Run one check, or grade one notebook; print the outcome as one JSON line."""
    try:
        argv, seed = arguments(argv)
    except Ros2nbError as problem:
        print(problem, file=sys.stderr)
        return 2
    if not subject_prefix():  # subjects not sandboxed: forked from here, before ROS starts
        serve_from_here()
    session = Session(default_workspace(), seed)
    try:
        if argv[0] == 'check':
            result: Any = captured(lambda: checks.run_check(argv[1], session))
        else:
            # Only grading flags code (the flags parse cells with IPython, whose imports
            # every check of a learner's kernel would pay).
            from .flags import notebook_flags
            source, submission = (json.loads(Path(p).read_text()) for p in argv[1:])
            def checked(grade_id: str, outcome: dict) -> None:
                print(json.dumps({'cell': grade_id, 'result': outcome}), flush=True)

            result = {'results': grade(source, submission, session, checked),
                      'flags': notebook_flags(submission, session.workspace)}
    finally:
        session.close()
    print(json.dumps(result))
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
