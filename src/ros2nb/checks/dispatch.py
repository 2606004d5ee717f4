"""Between the kernel and the judge: a check asked for by name, its result as one JSON line.

Part of :mod:`ros2nb.checks`.  In the kernel, :func:`run_in_judge` starts ``python -m
ros2nb.judge check NAME {}`` (the judge is named, never imported); the judge runs the same
public check, captures its outcome with :func:`captured` and prints it as one JSON line,
which :func:`show_result` turns back into the printed lines or the raised failure.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
from typing import Any, Callable

from .. import domains
from ..errors import CheckFailed, LearnerCodeError, Ros2nbError
from ..processes import LOOK_S, Patience, kill_process_group
from ..terminal.workspace import WORKSPACE_ENV, current_workspace

#: Set in the judge process: checks then run there instead of starting a judge.
IN_JUDGE_ENV = 'ROS2NB_JUDGE'
#: Seconds one check may take in all when the kernel runs it: of its judge's work while it
#: works, of the wall clock while it waits (:class:`~ros2nb.processes.Patience`).
CHECK_TIMEOUT_S = 300.0


def in_judge() -> bool:
    """True in the judge process."""
    return os.environ.get(IN_JUDGE_ENV) == '1'


def run_in_judge(check: str, arguments: dict[str, Any]) -> None:
    """Run ``ros2nb.checks.<check>(**arguments)`` in a judge process; print or raise its result.

    Called by the checks in a notebook.  The judge gets a ROS domain of its own (never the
    kernel's, where the learner's nodes may be running) and the kernel's workspace.

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    """
    env = {k: v for k, v in os.environ.items() if k != domains.DOMAIN_ENV}
    env.update({IN_JUDGE_ENV: '1', WORKSPACE_ENV: str(current_workspace()),
                'PYTHONUNBUFFERED': '1'})
    proc = subprocess.Popen([sys.executable, '-m', 'ros2nb.judge', 'check', check,
                             json.dumps(arguments)], env=env, text=True,
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


def show_result(result: dict) -> None:
    """Print a passed result's lines, or raise the failure it describes."""
    if result['passed']:
        print('\n'.join(result['lines']))
        return
    if result['type'] == 'LearnerCodeError':
        raise LearnerCodeError(result['message'], result['traceback'])
    raise CheckFailed(result['message'])


#: The line of a check that ended on an error of its own: one check's points, never the
#: notebook's (the others are graded as usual).
UNFINISHED = ('The grader could not finish this check ({error}); the other checks are '
              'graded as usual. If your code changes ros2nb or its processes, undo that; '
              'otherwise tell your instructor.')


def captured(call: Callable[[], Any]) -> dict:
    """Run one check (in the judge); return its outcome as JSON-safe data for the kernel.

    An error the check did not expect (a subject's reply of the wrong shape, say) fails
    that check with one line (:data:`UNFINISHED`), so a notebook's other checks still count.
    """
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            call()
    except LearnerCodeError as error:
        return {'passed': False, 'type': 'LearnerCodeError', 'message': str(error),
                'traceback': error.traceback_lines, 'lines': out.getvalue().splitlines()}
    except CheckFailed as error:
        return {'passed': False, 'type': 'CheckFailed', 'message': str(error),
                'lines': out.getvalue().splitlines()}
    except Ros2nbError as error:
        return {'passed': False, 'type': 'CheckFailed', 'message': str(error),
                'lines': out.getvalue().splitlines()}
    except Exception as error:  # what a process that ran learner code said made no sense
        return {'passed': False, 'type': 'CheckFailed', 'lines': out.getvalue().splitlines(),
                'message': UNFINISHED.format(error=f'{type(error).__name__}: '
                                                   f'{(str(error).splitlines() or [""])[0][:160]}')}
    return {'passed': True, 'lines': out.getvalue().splitlines()}
