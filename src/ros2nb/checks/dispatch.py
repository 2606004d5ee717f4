"""From the kernel to a judge: a check asked for by name, its verdict read back.

Part of :mod:`ros2nb.checks`; runs in the kernel.  :func:`ask_judge` starts ``python -m
ros2nb.judge check NAME`` (the judge is named, never imported), which runs the check's
registered body once and prints its outcome as one JSON line
(:func:`ros2nb.judge_interface.captured`); :func:`~ros2nb.judge_interface.show_result` turns
it back into the printed lines or the raised failure.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

from .. import domains
from ..errors import CheckFailed, Ros2nbError
from ..judge_interface import show_result
from ..processes import LOOK_S, Patience, kill_process_group
from ..terminal.workspace import WORKSPACE_ENV, current_workspace

#: Seconds one check may take in all when the kernel runs it: of its judge's work while it
#: works, of the wall clock while it waits (:class:`~ros2nb.processes.Patience`).
CHECK_TIMEOUT_S = 300.0


def ask_judge(check: str) -> None:
    """Run the check named ``check`` in a judge process; print or raise its result.

    Called by the notebook's function of every judged check
    (:func:`ros2nb.checks.base.judged`).  The judge gets a ROS domain of its own (never the
    kernel's, where the learner's nodes may be running) and the kernel's workspace.

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    """
    env = {k: v for k, v in os.environ.items() if k != domains.DOMAIN_ENV}
    env.update({WORKSPACE_ENV: str(current_workspace()), 'PYTHONUNBUFFERED': '1'})
    proc = subprocess.Popen([sys.executable, '-m', 'ros2nb.judge', 'check', check],
                            env=env, text=True,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            start_new_session=True)
    patience = Patience(proc.pid, CHECK_TIMEOUT_S)  # a busy machine slows the judge down
    try:
        while True:
            try:
                out, err = proc.communicate(timeout=LOOK_S)  # no output is lost on a retry
                break
            except subprocess.TimeoutExpired:
                if patience.exhausted():
                    kill_process_group(proc)
                    raise CheckFailed(f'The check did not finish within {CHECK_TIMEOUT_S:g} s: '
                                      'does your code wait for something that never happens?'
                                      ) from None
    except KeyboardInterrupt:
        kill_process_group(proc)
        raise CheckFailed('Check interrupted: run the cell again to check.') from None
    lines = out.strip().splitlines()
    try:
        result = json.loads(lines[-1])
    except (IndexError, json.JSONDecodeError):
        raise Ros2nbError(f'The check could not run (exit code {proc.returncode}): '
                          f'{(err.strip().splitlines() or ["no output"])[-1]}') from None
    show_result(result)

