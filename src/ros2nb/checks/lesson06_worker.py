"""Check of notebook 06's concurrency promise: a worker whose slow callback no longer holds
up its heartbeat.

Part of :mod:`ros2nb.checks` (the other promises are :mod:`.lesson06`).  The learner's
``responsive_worker()`` returns a node and the executor to spin it; the judge puts the
course's own callbacks on the worker's two timers and decides from what those callbacks
tell it over ROS while the learner's executor spins them (:mod:`.witnessed`).  The
executor and groups the subject reports only name the cause of what the judge saw.
"""

from __future__ import annotations

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, learner_error
from ..subject_interface import Worker, WorkerStop
from ..subject_replies import WorkerSpun
from .base import judged
from .witnessed import WITNESS_TOPIC, events, new_token, told_to

#: How long the course's slow_work works (s, wall clock): as part 3's, within its 0.5 s period.
SLOW_WORK_S = 0.45
#: slow_work runs the judge waits for, at most, before it says no heartbeat came meanwhile.
SLOW_RUNS_WATCHED = 3


def _overlapped(events: list[str]) -> tuple[bool, int]:
    """Whether a heartbeat came while slow_work worked (between one of its starts and the
    done after it), and how many slow_work runs were done, from the course's callbacks'
    events in the order they were published (one publisher keeps it)."""
    working, done = 0, 0
    for event in events:
        if event == 'start':
            working += 1
        elif event == 'done' and working:
            working, done = working - 1, done + 1
        elif event == 'beat' and working:
            return True, done
    return False, done


def _worker_cause(reply: WorkerSpun) -> str:
    """Why no heartbeat came during slow_work, from the executor and groups the subject
    says it was given (only to name the cause of what the judge saw)."""
    groups = {name: (kind, number) for name, kind, number in reply.groups}
    if reply.executor == 'SingleThreadedExecutor':
        return ('a SingleThreadedExecutor runs one callback at a time, so slow_work holds up '
                'heartbeat; return a MultiThreadedExecutor')
    if reply.threads == 1:
        return ('a MultiThreadedExecutor with num_threads=1 runs one callback at a time: give '
                'it num_threads=2')
    if groups.get('slow_work') == groups.get('heartbeat') and \
            groups.get('heartbeat', ('', 0))[0] == 'MutuallyExclusiveCallbackGroup':
        return ("both timers are in one MutuallyExclusiveCallbackGroup (the node's default), "
                'which runs one of its callbacks at a time; give each timer a group of its own')
    return ('let the timers overlap: a MultiThreadedExecutor(num_threads=2), and a callback '
            'group of its own for each timer')


def _worker_refused(reply: WorkerSpun) -> None:
    """Raise for a worker the subject could not spin (its reply names what it found)."""
    if reply.undefined:
        raise CheckFailed(f'promises.py defines no function {course.WORKER_FUNCTION}: write '
                          'part 4 (and run its cell).')
    if reply.error is not None:
        raise learner_error(f'{course.WORKER_FUNCTION}()', reply.error)
    if reply.returned is not None:
        raise CheckFailed(f'{course.WORKER_FUNCTION}() returned {reply.returned.value}; '
                          'return two things, the Worker node and the executor to spin it: '
                          'return node, executor.')
    if reply.timers is not None:
        raise CheckFailed(f'{course.WORKER_FUNCTION}() returned a node with {reply.timers} '
                          'timer(s): return a Worker (part 3), whose two timers run slow_work '
                          'and heartbeat.')
    if reply.unmatched:
        raise CheckFailed("The worker's witness never reached the grader: is the machine very "
                          'busy? Run this check again.')


def _responsive_worker(judge: Judge) -> str:
    subject = judge.file_subject(course.PROMISES_FILE)
    observer = judge.observer
    told = told_to(judge)
    mark, token, name = len(told), new_token(), 'responsive_worker'
    reply = subject.request(Worker(name=course.WORKER_FUNCTION, topic=WITNESS_TOPIC,
                                   token=token, work_s=SLOW_WORK_S, seconds=ARRIVAL_TIMEOUT_S),
                            timeout=ARRIVAL_TIMEOUT_S + 30)
    if not reply.ok:
        judge.drop(('file', course.PROMISES_FILE))
        _worker_refused(reply)

    def seen() -> bool:
        overlap, done = _overlapped(events(told, mark, token))
        return overlap or done >= SLOW_RUNS_WATCHED

    try:
        observer.wait_until(seen, ARRIVAL_TIMEOUT_S)
        # the name as the graph shows it, while the node runs (the reply only words a failure)
        named = reply.name == name and \
            observer.wait_until(lambda: observer.has_node(name), ARRIVAL_TIMEOUT_S)
    finally:
        stopped = subject.request(WorkerStop(), timeout=60)
        judge.drop(('file', course.PROMISES_FILE))
    overlap, done = _overlapped(events(told, mark, token))
    if stopped.failure is not None:
        raise learner_error(stopped.failure.callback, stopped.failure)
    if not named:
        raise CheckFailed(f"{course.WORKER_FUNCTION}() returned a Worker called "
                          f"{reply.name}; name it '{name}'.")
    if overlap:
        return (f'a heartbeat came while slow_work was busy, on a {reply.executor}: the two '
                'timers run side by side.')
    if done == 0:
        raise CheckFailed(f'slow_work never finished in {ARRIVAL_TIMEOUT_S:g} s: keep both timers '
                          'of the Worker running.')
    raise CheckFailed(f'No heartbeat came while slow_work was busy ({done} runs of slow_work '
                      f'watched): {_worker_cause(reply)}.')


@judged
def check_responsive_worker(judge: Judge) -> str:
    """Check part 4 of ``promises.py``: a slow callback no longer holds up the heartbeat.

    Calls your ``responsive_worker()`` for its node and executor, puts the course's own
    callbacks on the Worker's two timers (in the callback groups you chose: a slow one that
    works 0.45 s, a quick one) and spins your executor on the wall clock.  The course's
    callbacks tell the grader when each runs: a heartbeat must run while ``slow_work`` is
    busy.  When none does, the line says why, from the executor and the timers' callback
    groups.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the cause.
    """
    return _responsive_worker(judge)
