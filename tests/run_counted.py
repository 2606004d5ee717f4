"""Run one step of ``make test`` and count the CPU seconds of every process it started.

``python tests/run_counted.py CPU_FILE COMMAND...`` runs COMMAND, writes the CPU seconds (user
and system) of all the processes it started into CPU_FILE, and exits with COMMAND's code.

A process's CPU is counted once its parent reaps it, but a step's processes do not all have
one: a daemon forks twice (podman's conmon), and a kernel that is killed leaves its children
to whoever adopts them.  This process is their subreaper (``PR_SET_CHILD_SUBREAPER``): every
orphan of the step is adopted here and reaped when it ends, so its CPU counts too.  What is
still running when the step's command ended, the step left behind: it is ended, and named.
"""

from __future__ import annotations

import ctypes
import os
import resource
import signal
import subprocess
import sys
from pathlib import Path

import psutil

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


def end_left_running(step: str) -> None:
    """End the processes the step left running (orphans adopted here: the step's command
    has ended), each with what it started, and say which they were."""
    left = [process for process in psutil.Process().children() if _running(process)]
    if not left:
        return
    shown = []
    for process in left:
        try:
            shown.append(' '.join(process.cmdline())[:100])
        except psutil.Error:
            continue
    everything = [p for process in left for p in _with_children(process)]
    for process in everything:
        try:
            process.terminate()
        except psutil.Error:
            pass
    _gone, alive = psutil.wait_procs(everything, timeout=5)
    for process in alive:
        try:
            process.kill()
        except psutil.Error:
            pass
    print(f'=== make test: {step} left {len(left)} process(es) running, ended now: '
          + '; '.join(shown), flush=True)


def _running(process: psutil.Process) -> bool:
    """False for a process that ended and waits only to be reaped (a zombie: it runs nothing
    and has no command line to name)."""
    try:
        return process.status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


def _with_children(process: psutil.Process) -> list[psutil.Process]:
    try:
        return [process, *process.children(recursive=True)]
    except psutil.Error:
        return [process]


def main(argv: list[str]) -> int:
    cpu_file, command = argv[0], argv[1:]
    adopt_orphans()
    # Ctrl+C is the step's to handle (it says where it was); a handler, not SIG_IGN, which
    # the step would inherit.
    signal.signal(signal.SIGINT, lambda *_: None)
    code = subprocess.run(command).returncode
    end_left_running(f'the step {Path(cpu_file).stem}')
    with open(cpu_file, 'w') as out:
        out.write(f'{reaped_cpu_s():.0f}\n')
    return code

if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
