"""``python -m ros2nb.subject IN_FD OUT_FD``: the process that runs the learner's code for a judge.

Started by the judge (:mod:`ros2nb.judge.subjects`), sandboxed while grading.  The first
command loads the learner's code (:func:`ros2nb.subject.commands.load`) before the command
loop exists, with the course's answers out of its reach (:mod:`.out_of_reach`) and what it
reaches for seen as it runs (:mod:`.seen`); the loop answers the rest.
"""

from __future__ import annotations

import json
import os
import signal
import sys

from ..explain.blocking import guard_sleep
from ..explain.plots import guard_pyplot
from ..processes import die_with_parent, end_this_process
from ..subject_interface import LOADERS, command_of, wire
from ..typed_json import Unreadable
from . import judge_time, out_of_reach, seen
from .commands import PROTOCOL_ERROR, load, serve
from .shown import make_sealer


def main(argv: list[str]) -> int:
    """Entry point: ``python -m ros2nb.subject IN_FD OUT_FD``."""
    die_with_parent(signal.SIGTERM)  # a judge (or its server) that ended takes it along
    judge_time.install()  # the judge's pipe and time: this process's alone, never a child's
    seen.install(judge_time.JudgeTime.pipe())  # before anything of the learner's runs
    guard_pyplot()  # plt.pause / plt.show in a callback: the learner's one line
    guard_sleep()  # time.sleep in a callback: at once, not after minutes of the grader's clock
    if len(argv) != 2:
        print('Usage: python -m ros2nb.subject IN_FD OUT_FD (started by ros2nb.judge).',
              file=sys.stderr)
        return PROTOCOL_ERROR
    with os.fdopen(int(argv[0]), 'r') as commands, os.fdopen(int(argv[1]), 'w') as replies:
        first = commands.readline()
        if not first:
            return 0
        try:
            request = json.loads(first)
            del first
            # notebook 07's seal: its key lives in the sealer's frame alone, taken out of the
            # command before any learner code runs (the command itself keeps none)
            sealer = make_sealer(str(request.pop('seal', '') if isinstance(request, dict) else ''))
            command = command_of(request, LOADERS)
        except (ValueError, Unreadable):
            return PROTOCOL_ERROR
        out_of_reach.shut()  # no answer module importable: the judge sends what stands in
        namespace, reply = load(command)
        replies.write(json.dumps(wire(reply)) + '\n')
        replies.flush()
        serve(commands, replies, namespace, sealer)
    return 0


if __name__ == '__main__':
    end_this_process(main(sys.argv[1:]))
