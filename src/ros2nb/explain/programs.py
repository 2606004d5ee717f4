"""The line a learner's program prints for the error that ended it, for the check that ran it.

Part of :mod:`ros2nb.explain`.  A check of ``main()`` (:mod:`ros2nb.checks.mains`) runs the
learner's program as ``ros2 run`` would (:mod:`ros2nb.subject.program`) and watches it from
outside; when the program ends on an error, it prints one line for the check first
(:func:`explained_line`), which the check reads back (:func:`read_explained`) to word its
failure at the learner's line.  Nothing in it earns a point: the exit code and the graph do.
Introduced in ``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import json
from typing import Any, Optional

from rclpy.exceptions import NotInitializedException

from .exceptions import describe_error


#: What starts the line a program of the learner's prints for the error that ended it
#: (:func:`explained_line`), read back by the check that ran it (:func:`read_explained`).
EXPLAINED_MARK = 'ros2nb explains: '


def explained_line(error: BaseException, *, in_program: bool = True) -> str:
    """One line for the learner's program to print when ``error`` ends it: the mark, then
    :func:`describe_error`'s facts as JSON (a check words its failure with them; nothing in
    them earns a point).  In a program (``ros2 run``), "not initialised" means that main()
    never called ``rclpy.init()``."""
    facts = describe_error(error)
    if in_program and isinstance(error, NotInitializedException):
        facts['explanation'] = ('rclpy.init() was not called before this: call '
                                'rclpy.init(args=args) first in main(), before the node is '
                                'created.')
    return EXPLAINED_MARK + json.dumps({k: facts[k] for k in ('type', 'message', 'explanation',
                                                              'where')})


def read_explained(text: str) -> Optional[dict[str, Any]]:
    """The facts of the last :func:`explained_line` in a program's output, or None."""
    for line in reversed(text.splitlines()):
        if line.startswith(EXPLAINED_MARK):
            try:
                facts = json.loads(line[len(EXPLAINED_MARK):])
            except ValueError:
                return None
            return facts if isinstance(facts, dict) else None
    return None
