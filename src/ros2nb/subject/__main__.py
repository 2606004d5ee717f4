"""``python -m ros2nb.subject IN_FD OUT_FD``: the process that runs the learner's code for a judge.

Started by the judge (:mod:`ros2nb.judge.subjects`), sandboxed while grading.
"""

from __future__ import annotations

import os
import sys

from ..processes import end_this_process
from .process import PROTOCOL_ERROR, serve


def main(argv: list[str]) -> int:
    """Entry point: ``python -m ros2nb.subject IN_FD OUT_FD``."""
    if len(argv) != 2:
        print('Usage: python -m ros2nb.subject IN_FD OUT_FD (started by ros2nb.judge).',
              file=sys.stderr)
        return PROTOCOL_ERROR
    with os.fdopen(int(argv[0]), 'r') as commands, os.fdopen(int(argv[1]), 'w') as replies:
        serve(commands, replies)
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
