"""``python -m ros2nb.subject.program FILE [CLASS]``: the learner's ``main()``, as
``ros2 run`` starts it.

Introduced in ``03-write-the-publisher.ipynb``.  An entry point (``console_scripts``) imports
the module and calls its ``main()``; this does the same with a file of the learner's, for
the judge's checks of ``main()`` (:mod:`ros2nb.checks.mains`), which watch the process from
outside: its node in the ROS graph, its answers, its exit code after Ctrl+C.  With CLASS,
the node class of that name is first replaced by the course's stand-in
(:func:`ros2nb.subject.stand_ins.stand_in_node`, handed in once the file ran: the file
itself cannot import it, :mod:`.out_of_reach`), so that ``main()`` is graded on its own.
Nothing of this process is believed: it is the learner's program.
"""

from __future__ import annotations

import runpy
import sys

from ..explain.programs import explained_line
from . import out_of_reach

#: Exit code when the file has no ``main()`` to call.
NO_MAIN = 4


def main(argv: list[str]) -> int:
    """Run ``FILE``'s ``main()`` (with its node class replaced when CLASS is given)."""
    if len(argv) not in (1, 2):
        print('Usage: python -m ros2nb.subject.program FILE [CLASS]', file=sys.stderr)
        return 2
    sys.argv = [argv[0]]
    refusing = out_of_reach.shut()  # the stand-in node is handed in only once the file ran
    try:
        module = runpy.run_path(argv[0], run_name='__ros2nb_program__')
        entry = module.get('main')
        if not callable(entry):
            print(f'{argv[0]} has no main() function.', file=sys.stderr)
            return NO_MAIN
        if len(argv) == 2:  # what main() looks up when it runs: its module's globals
            getattr(entry, '__globals__', module)[argv[1]] = \
                refusing.hand_in(out_of_reach.STAND_INS).stand_in_node(argv[1])
        result = entry()
    except Exception as error:  # its line for the check, then Python's traceback as usual
        print(explained_line(error), file=sys.stderr, flush=True)
        raise
    return result if isinstance(result, int) else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
