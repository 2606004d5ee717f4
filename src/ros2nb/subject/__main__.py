"""``python -P -m ros2nb.subject IN_FD OUT_FD``: the process that runs the learner's code for
a judge.

Started by the judge (:mod:`ros2nb.judge.subjects`), sandboxed while grading, in a folder of
its own that it alone may write and that no later process reads.  Its working folder is not
on ``sys.path`` (``-P``; taken off here first thing where Python has no ``-P``), so no module
the learner's code or a file of theirs left there stands in for the standard library's.
The first command loads the learner's code (:func:`ros2nb.subject.commands.load`) before the
command loop exists, with the course's answers out of its reach (:mod:`.out_of_reach`) and
what it reaches for noted as it runs (:mod:`.seen`, a detector only); the loop answers the
rest.  Nothing this process holds awards a point: the judge observes what its nodes do.
"""

from __future__ import annotations

import os
import sys


def _working_folder_off_the_path() -> None:
    """What ``-P`` does where Python has no ``-P`` (3.10): ``python -m`` put the working
    folder first on ``sys.path``; take it off before anything else is imported."""
    here = os.getcwd()
    sys.path[:] = [entry for entry in sys.path
                   if entry not in ('', '.') and os.path.abspath(entry) != here]


_working_folder_off_the_path()

import json  # noqa: E402 - only once the working folder is off the path
import signal  # noqa: E402

from ..explain.blocking import guard_sleep  # noqa: E402
from ..explain.plots import guard_pyplot  # noqa: E402
from ..processes import die_with_parent, end_this_process  # noqa: E402
from ..subject_interface import LOADERS, command_of, wire  # noqa: E402
from ..typed_json import Unreadable  # noqa: E402
from . import judge_time, out_of_reach, seen  # noqa: E402
from .commands import PROTOCOL_ERROR, load, serve  # noqa: E402


def main(argv: list[str]) -> int:
    """Entry point: ``python -P -m ros2nb.subject IN_FD OUT_FD``."""
    die_with_parent(signal.SIGTERM)  # a judge (or its server) that ended takes it along
    judge_time.install()  # the judge's pipe and time: this process's alone, never a child's
    noted = seen.install(judge_time.JudgeTime.pipe())  # before anything of the learner's runs
    guard_pyplot()  # plt.pause / plt.show in a callback: the learner's one line
    guard_sleep()  # time.sleep in a callback: at once, not after minutes of the grader's clock
    if len(argv) != 2:
        print('Usage: python -P -m ros2nb.subject IN_FD OUT_FD (started by ros2nb.judge).',
              file=sys.stderr)
        return PROTOCOL_ERROR
    with os.fdopen(int(argv[0]), 'r') as commands, os.fdopen(int(argv[1]), 'w') as replies:
        first = commands.readline()
        if not first:
            return 0
        try:
            command = command_of(json.loads(first), LOADERS)
        except (ValueError, Unreadable):
            return PROTOCOL_ERROR
        out_of_reach.shut()  # no answer module importable: the judge sends what stands in
        namespace, reply = load(command)
        replies.write(json.dumps(wire(reply)) + '\n')
        replies.flush()
        serve(commands, replies, namespace, noted)
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
