"""From the kernel to a judge: a check asked for by name, its verdict read back.

Part of :mod:`ros2nb.checks`; runs in the kernel.  :func:`ask_judge` starts ``python -m
ros2nb.judge check NAME`` (the judge is named, never imported), which runs the check's
registered body once and prints its outcome as one JSON line
(:func:`ros2nb.judge_interface.captured`); :func:`~ros2nb.judge_interface.show_result` turns
it back into the printed lines or the raised failure.  While it works the judge says what it
does on its stderr (:mod:`ros2nb.working`), shown in the cell as one line that it replaces.
"""

from __future__ import annotations

import json
import os
import selectors
import subprocess
import sys

from .. import domains, working
from ..errors import CheckFailed, Ros2nbError
from ..judge_interface import show_result
from ..outcomes import CheckOutcome
from ..patience import LOOK_S, Patience
from ..processes import kill_process_group
from ..terminal.workspace import WORKSPACE_ENV, current_workspace
from ..typed_json import decoded

#: Seconds one check may take in all when the kernel runs it: of its judge's work while it
#: works, of the wall clock while it waits (:class:`~ros2nb.patience.Patience`).
CHECK_TIMEOUT_S = 300.0
#: How the line of a check stopped with the Stop button starts.
INTERRUPTED = 'Check interrupted'


def ask_judge(check: str) -> None:
    """Run the check named ``check`` in a judge process; print or raise its result.

    Called by the notebook's function of every judged check
    (:func:`ros2nb.checks.base.judged`).  The judge gets a ROS domain of its own (never the
    kernel's, where the learner's nodes may be running) and the kernel's workspace.  What it
    says it does shows as one line while it works (:func:`ros2nb.working.shown`).

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    """
    env = {k: v for k, v in os.environ.items() if k != domains.DOMAIN_ENV}
    env.update({WORKSPACE_ENV: str(current_workspace()), 'PYTHONUNBUFFERED': '1',
                working.ENV: '1'})
    proc = subprocess.Popen([sys.executable, '-m', 'ros2nb.judge', 'check', check],
                            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    try:
        with working.shown(check) as work:
            work.say('starting the grader')
            out, err = _read_until_done(proc, work)
    except KeyboardInterrupt:
        kill_process_group(proc)
        raise CheckFailed(f'{INTERRUPTED}: run the cell again to check.') from None
    lines = out.strip().splitlines()
    try:
        result = decoded(CheckOutcome, json.loads(lines[-1]))
    except (IndexError, ValueError):  # no line, not JSON, or not an outcome (Unreadable)
        raise Ros2nbError(f'The check could not run (exit code {proc.returncode}): '
                          f'{(err.strip().splitlines() or ["no output"])[-1]}') from None
    show_result(result)


def _read_until_done(proc: subprocess.Popen[bytes], work: working.Working) -> tuple[str, str]:
    """The judge's stdout and its own stderr lines, read as they come until it ends; each
    line of what it does shown on the way.

    :raises CheckFailed: when the judge had its patience (:data:`CHECK_TIMEOUT_S`).
    """
    patience = Patience(proc.pid, CHECK_TIMEOUT_S)  # a busy machine slows the judge down
    if proc.stdout is None or proc.stderr is None:  # pragma: no cover - both are pipes
        raise Ros2nbError('The check could not run: its judge has no output to read.')
    out_fd, err_fd = proc.stdout.fileno(), proc.stderr.fileno()
    out: list[bytes] = []
    err_lines: list[str] = []
    partial = b''
    with selectors.DefaultSelector() as selector:
        for fd in (out_fd, err_fd):
            selector.register(fd, selectors.EVENT_READ)
        while selector.get_map():
            for key, _events in selector.select(LOOK_S):
                data = os.read(key.fd, 65536)
                if not data:
                    selector.unregister(key.fd)
                elif key.fd == out_fd:
                    out.append(data)
                else:
                    *whole, partial = (partial + data).split(b'\n')
                    for raw in whole:
                        line = raw.decode(errors='replace')
                        told = working.said(line)
                        if told is None:
                            err_lines.append(line)
                        else:
                            work.say(told)
            work.tick()
            if selector.get_map() and patience.exhausted():
                kill_process_group(proc)
                raise CheckFailed(f'The check did not finish within {CHECK_TIMEOUT_S:g} s: '
                                  'does your code wait for something that never happens?')
    proc.wait()
    return (b''.join(out).decode(errors='replace'),
            '\n'.join([*err_lines, partial.decode(errors='replace')]))
