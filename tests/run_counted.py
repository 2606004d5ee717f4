"""Run one step of ``make test`` and count the CPU seconds of every process it started.

``python tests/run_counted.py CPU_FILE COMMAND...`` runs COMMAND, writes the CPU seconds (user
and system) of all the processes it started into CPU_FILE, and exits with COMMAND's code.

A process's CPU is counted once its parent reaps it, but a step's processes do not all have
one: a daemon forks twice (podman's conmon), and a kernel that is killed leaves its children
to whoever adopts them.  This process is their subreaper (``PR_SET_CHILD_SUBREAPER``): every
orphan of the step is adopted here and reaped when it ends, so its CPU counts too.
"""

from __future__ import annotations

import ctypes
import os
import resource
import signal
import subprocess
import sys

PR_SET_CHILD_SUBREAPER = 36  # linux/prctl.h


def adopt_orphans() -> None:
    """Make this process the subreaper of its descendants: an orphan among them is adopted
    here, not by init, so its CPU counts in :func:`reaped_cpu_s`."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)


def reaped_cpu_s() -> float:
    """CPU seconds (user and system) of this process's descendants that ended, the orphans
    that ended reaped first; one still running is not waited for."""
    while True:
        try:
            if os.waitpid(-1, os.WNOHANG)[0] == 0:
                break
        except ChildProcessError:
            break
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def main(argv: list[str]) -> int:
    cpu_file, command = argv[0], argv[1:]
    adopt_orphans()
    # Ctrl+C is the step's to handle (it says where it was); a handler, not SIG_IGN, which
    # the step would inherit.
    signal.signal(signal.SIGINT, lambda *_: None)
    code = subprocess.run(command).returncode
    with open(cpu_file, 'w') as out:
        out.write(f'{reaped_cpu_s():.0f}\n')
    return code

if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
