"""What the processes of a ``make test`` left behind, swept: ``python tests/left_behind.py``.

``make test`` runs it first and last (``tests/run_steps.sh``).  A kernel that nbval or a test
stopped, a judge or grader that was killed, or an earlier ``make test`` that was killed, may
leave temporary folders (in the temporary folder and in ``/dev/shm``) and sandbox cgroups;
the next of their kind removes them (:mod:`ros2nb.temporary`, the grader's cgroups), and this
removes those no later one did.  Only what belonged to processes that no longer run: a test
run beside this one keeps its own.  It prints one line of what it removed, if anything.
"""

from __future__ import annotations

import sys
from pathlib import Path

from ros2nb.temporary import sweep_all
from ros2nb_instructor.grading.sandbox import cgroups


def main() -> int:
    shm = Path('/dev/shm')
    swept = [*sweep_all(), *(sweep_all(shm) if shm.is_dir() else []),
             *cgroups.sweep_left_behind()]
    if swept:
        names = ', '.join(path.name for path in swept[:8])
        more = f' and {len(swept) - 8} more' if len(swept) > 8 else ''
        print(f'=== make test: removed what ended processes left behind: {names}{more}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
