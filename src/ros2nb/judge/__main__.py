"""``python -m ros2nb.judge check NAME`` or ``grade SOURCE SUBMISSION [--seed N]``.

The judge's command line (see :mod:`ros2nb.judge`): it opens a :class:`Session`, runs the
body of each check asked for with it (:func:`ros2nb.checks.run_check`) and prints one JSON
line with the outcome; while grading, also one line as each graded cell starts
(``{"begin": ID}``: the grader counts each check's CPU time from there) and one as soon as
it is decided (``{"cell": ID, "result": ..., "cpu_s": ...}``, with the CPU seconds it took,
this process's and its subjects'), which is what a judge stopped at its limits leaves.  A
check draws its inputs from a seed the judge draws itself; only the grader gives one
(``--seed``, :mod:`ros2nb.checks.drawn`), the learner's kernel never.
"""

from __future__ import annotations

import dataclasses
import json
import os
import signal
import sys
from pathlib import Path
from typing import Any, Optional

from .. import working
from ..patience import tree_cpu_seconds
from ..processes import die_with_parent, end_this_process
from ..subject.forked import SUBJECT_PREFIX_ENV, serve_from_here

# Nothing of the checks, the judge's session or the course's answers is imported yet: the
# fork server forks every subject from this process as it is now (main()), and a subject
# must hold no answer in its memory (ros2nb.subject.out_of_reach).
USAGE = 'Usage: python -m ros2nb.judge check NAME | grade SOURCE SUBMISSION [--seed N]'


def arguments(argv: list[str]) -> tuple[list[str], Optional[int]]:
    """The command (``check NAME`` or ``grade SOURCE SUBMISSION``) and the grader's seed of
    the drawn inputs (None: the judge draws one).  Only ``grade`` takes a seed: a check in
    the lab is asked for by the learner's kernel, which must not choose its inputs.

    :raises Ros2nbError: with the usage, or with what is wrong with the seed.
    """
    from ..checks.drawn import SEED_OPTION, parse_seed
    from ..errors import Ros2nbError
    seed = None
    if argv[:1] == ['grade'] and len(argv) == 5 and argv[3] == SEED_OPTION:
        argv, seed = argv[:3], parse_seed(argv[4])
    if (argv[:1], len(argv)) not in ((['check'], 2), (['grade'], 3)):
        raise Ros2nbError(USAGE)
    return argv, seed


def _ended(signum: int, _frame: Any) -> None:
    """SIGTERM (its kernel ended it, or ended itself): end here, the session closed on the
    way out (its subjects and programs ended too)."""
    signal.signal(signum, signal.SIG_DFL)  # a second one ends the process at once
    raise SystemExit(128 + signum)


def main(argv: list[str]) -> int:
    """Run one check, or grade one notebook; print the outcome as one JSON line."""
    signal.signal(signal.SIGTERM, _ended)
    die_with_parent(signal.SIGTERM)  # a kernel restarted or killed takes its judge with it
    working.tell_on_stderr()  # what it does, for the kernel that waits (none of its children)
    if not os.environ.get(SUBJECT_PREFIX_ENV):  # subjects not sandboxed: forked from here,
        serve_from_here()  # before ROS starts and before any answer is imported
    from .. import checks
    from ..errors import Ros2nbError
    from ..judge_interface import captured
    from ..outcomes import CellChecked, CheckOutcome, NotebookChecked
    from ..terminal.workspace import default_workspace
    from .graded_cells import grade
    from .session import Session
    try:
        argv, seed = arguments(argv)
    except Ros2nbError as problem:
        print(problem, file=sys.stderr)
        return 2
    session, hurried = Session(default_workspace(), seed), False
    try:
        if argv[0] == 'check':
            result: Any = dataclasses.asdict(
                captured(lambda: checks.run_check(argv[1], session)))
        else:
            # Only grading flags code (the flags parse cells with IPython, whose imports
            # every check of a learner's kernel would pay).
            from .flags import notebook_flags
            from .written import REWRITTEN, as_written
            source, submission = (json.loads(Path(p).read_text()) for p in argv[1:])
            rewritten = as_written(submission, session.workspace)
            flags = notebook_flags(submission, session.workspace, source)
            if rewritten:  # what another cell wrote into the package is never graded
                session.grade_as_written(rewritten)

            began = [0.0]

            def starting(grade_id: str) -> None:
                began[0] = tree_cpu_seconds(os.getpid())
                print(json.dumps({'begin': grade_id}), flush=True)

            def checked(grade_id: str, outcome: CheckOutcome) -> None:
                cpu_s = round(tree_cpu_seconds(os.getpid()) - began[0], 2)
                print(json.dumps(dataclasses.asdict(CellChecked(grade_id, outcome, cpu_s))),
                      flush=True)

            result = dataclasses.asdict(NotebookChecked(
                grade(source, submission, session, checked, starting),
                flags + [REWRITTEN.format(name=Path(r).name) for r in rewritten]
                + session.reaching.flags()))
    except SystemExit:  # ended from outside (_ended): the learner's processes go at once
        hurried = True
        raise
    finally:
        session.close(hurried=hurried)
    print(json.dumps(result))
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
