"""Waiting in tests: poll for the state a test needs, never sleep for a guessed time.

Every wait in ``tests/`` ends as soon as its state is there.  When the state never comes, the
test fails and says what it last saw, once the processes the test started had
:data:`PATIENCE_S` as the judge counts it (:func:`ros2nb.patience.wait_for_work`): seconds
of their work while they work or stand in the queue for a CPU, of the wall clock while they
sit idle.  So a busy machine makes a test slower, never wrong; and a slow machine needs one
knob, not thirty.
"""

from __future__ import annotations

import contextlib
import os
import subprocess
import time
from pathlib import Path
from typing import Any, Callable, Iterator, Optional, Sequence

from ros2nb.patience import child_pids, wait_for_work

from ros2nb.processes import kill_process_group

#: The longest a test waits for a state that should come (s): of the work of the processes
#: the test started, or of their idle waiting.  Generous: a bound matters only when the
#: state never comes.
PATIENCE_S = float(os.environ.get('ROS2NB_TEST_PATIENCE_S', '180'))
#: Seconds between two looks at a condition.
LOOK_S = 0.02


def wait_until(condition: Callable[[], Any], seconds: float = PATIENCE_S,
               interval: float = LOOK_S) -> bool:
    """Poll ``condition()`` until it is true; return False once this test's processes had
    ``seconds`` (with none, seconds of the wall clock)."""
    return wait_for_work(condition, child_pids(os.getpid()), seconds,
                         look=lambda check, s: _poll(check, s, interval))


def wait_for(condition: Callable[[], Any], what: str, *, seconds: float = PATIENCE_S,
             seen: Optional[Callable[[], Any]] = None, interval: float = 0.05) -> Any:
    """Poll ``condition()`` until it returns something true, and return that.

    :param what: the state waited for, e.g. ``"ada's server ready"``.
    :param seen: describes what was there instead, for the failure message.
    :raises AssertionError: ``what: not within N s ...; last seen: ...`` when this test's
        processes had their patience.
    """
    value: Any = None

    def held() -> bool:
        nonlocal value
        value = condition()
        return bool(value)

    if wait_until(held, seconds, interval):
        return value
    last = seen() if seen is not None else value
    raise AssertionError(f'{what}: not within {seconds:g} s of the work or idle waiting of the '
                         f'processes this test started; last seen: {last!r}')


def run_to_end(argv: Sequence[str], what: str, *, seconds: float = PATIENCE_S,
               **popen: Any) -> subprocess.CompletedProcess:
    """``subprocess.run(argv, capture_output=True, text=True, **popen)``, given ``seconds`` as
    the judge gives a program (of its work, or of its idle waiting), not of the wall clock.

    :raises AssertionError: ``what`` and its output so far, when it had them and still runs.
    """
    proc = subprocess.Popen(list(argv), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, **popen)
    out: list[str] = []

    def ended() -> bool:
        try:
            out[:] = proc.communicate(timeout=LOOK_S)  # no output is lost on a retry
        except subprocess.TimeoutExpired:
            return False
        return True

    if not wait_for_work(ended, [proc.pid], seconds, look=lambda check, _s: check()):
        kill_process_group(proc)
        stdout, stderr = proc.communicate()
        raise AssertionError(f'{what} still ran after {seconds:g} s of its work or idle '
                             f'waiting: {(stdout + stderr)[-2000:]}')
    return subprocess.CompletedProcess(proc.args, proc.returncode, *out)


def _poll(condition: Callable[[], Any], seconds: float, interval: float) -> bool:
    deadline = time.monotonic() + seconds
    while not condition():
        if time.monotonic() >= deadline:
            return False
        time.sleep(interval)
    return True


@contextlib.contextmanager
def starved(share: float) -> Iterator[Callable[[int], None]]:
    """A CPU quota of ``share`` CPUs while the block runs (the grader's own cgroups,
    :func:`ros2nb_instructor.grading.sandbox.cgroups.make_cgroups`): ``admit(tid)`` puts a process
    (by its pid, with the children it starts later) or one thread of this process (by its
    thread id: cgroup v1 moves a thread alone) under it.  A program there gets at most that
    share however idle the machine is: slow for certain, not by luck.  Skips the test where
    no quota can be set (not root, no cpu controller)."""
    import pytest
    from ros2nb_instructor.grading.sandbox import cgroups
    made, enforced = cgroups.make_cgroups(64, 1 << 30, share)
    quota = [c for c in made if (c / 'cpu.cfs_quota_us').exists() or (c / 'cpu.max').exists()]
    if 'cpu(cgroup)' not in enforced or not quota:
        cgroups.remove(made)
        pytest.skip('no CPU quota can be set here (needs root and a cpu cgroup controller)')

    def admit(tid: int) -> None:
        for cgroup in quota:
            Path(cgroup / ('tasks' if (cgroup / 'tasks').exists() else 'cgroup.threads')
                 ).write_text(str(tid))

    try:
        yield admit
    finally:
        for cgroup in quota:  # whatever is left goes back where it came from: the root
            root = cgroup.parent / ('tasks' if (cgroup / 'tasks').exists() else 'cgroup.procs')
            for tid in (cgroup / ('tasks' if (cgroup / 'tasks').exists() else
                                  'cgroup.threads')).read_text().split():
                with contextlib.suppress(OSError):
                    root.write_text(tid)
        cgroups.remove(made)
