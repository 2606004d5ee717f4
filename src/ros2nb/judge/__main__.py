"""``python -m ros2nb.judge check NAME KWARGS_JSON`` or ``grade SOURCE SUBMISSION``.

The judge's command line (see :mod:`ros2nb.judge`): it binds a :class:`Session` as the
judge of this process's checks, runs them and prints one JSON line with the outcome.
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

from .. import checks
from ..checks.base import bind_judge
from ..checks.dispatch import IN_JUDGE_ENV, captured
from ..processes import end_this_process
from ..subject.forked import serve_from_here
from ..terminal.workspace import default_workspace
from .grading import grade
from .session import Session
from .subjects import subject_prefix


def main(argv: list[str]) -> int:
    """Run one check, or grade one notebook; print the outcome as one JSON line."""
    os.environ[IN_JUDGE_ENV] = '1'
    if len(argv) != 3 or argv[0] not in ('check', 'grade'):
        print('Usage: python -m ros2nb.judge check NAME KWARGS_JSON | grade SOURCE '
              'SUBMISSION', file=sys.stderr)
        return 2
    if not subject_prefix():  # subjects not sandboxed: forked from here, before ROS starts
        serve_from_here()
    session = Session(default_workspace())
    bind_judge(session)
    try:
        if argv[0] == 'check':
            function = getattr(checks, argv[1])
            result: Any = captured(lambda: function(**json.loads(argv[2])))
        else:
            # Only grading flags code (the flags parse cells with IPython: 40 ms of imports
            # that every check of a learner's kernel would pay).
            from .flags import notebook_flags
            source, submission = (json.loads(Path(p).read_text()) for p in argv[1:])
            result = {'results': grade(source, submission),
                      'flags': notebook_flags(submission, session.workspace)}
    finally:
        bind_judge(None)
        session.close()
    print(json.dumps(result))
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
