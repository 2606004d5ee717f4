"""Check of notebook 06's concurrency promise: a worker whose slow callback no longer holds
up its heartbeat.

Part of :mod:`ros2nb.checks` (the other promises are :mod:`.lesson06`).  The learner's
``responsive_worker()`` returns a node and the executor to spin it.  In a subject, the
Worker's two timers stop and the course's slow work and heartbeat take their places, as two
services in the same callback groups (:func:`ros2nb.subject.shown.worker_services`), and the
learner's executor spins them.  The judge calls them from a node of its own and times the
answers itself: the slow work lasts until the judge lets it end, and a heartbeat counts when
its answer left the subject before the slow work's did (the answers' own DDS timestamps).
An answer reaches the judge only through the executor that took the request, so nothing
else in the learner's process answers for it; the graph must show one server of each
service.  The executor and groups the subject reports only name the cause of
what the judge saw.
"""

from __future__ import annotations

from typing import Any, Optional

from rcl_interfaces.srv import GetParameters

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, Subject, learner_error
from ..subject_interface import Worker, WorkerRelease, WorkerStop
from ..subject_replies import WorkerSpun
from .base import judged
from .witnessed import WITNESS_TOPIC, new_nonce, started, told_to

#: The course's services on the learner's Worker: the slow work, the heartbeat.
SERVICES = ('/ros2nb_worker/slow_work', '/ros2nb_worker/heartbeat')
#: The nonce of the first calls, which only show that both ways are matched
#: (:data:`ros2nb.subject.shown.WARM_UP`).
WARM_UP = 'warm-up'
#: Seconds the subject may sit idle (or work, in CPU seconds) with the heartbeat asked for
#: while the slow work runs before the judge lets the slow work end: a heartbeat the
#: learner's executor can run takes it a moment of work, never a wait.
BEAT_PATIENCE_S = 5.0


class _Calls:
    """The judge's client of one of the worker's services, on a node of the judge's that no
    thread spins: it sends requests and takes the answers itself, with their headers."""

    def __init__(self, judge: Judge, name: str) -> None:
        self.name = name
        self.client = judge.observer.quiet_node().create_client(GetParameters, name)
        #: Answers taken so far: sequence number -> (source timestamp in ns, response).
        self.answers: dict[int, tuple[int, Any]] = {}

    def send(self, nonce: str) -> int:
        """Send a request carrying ``nonce``; its sequence number."""
        return self.client.handle.send_request(GetParameters.Request(names=[nonce]))

    def answered(self, sequence: int) -> bool:
        """Take what came, and whether the answer to ``sequence`` is among it."""
        with self.client.handle:
            while True:
                header, response = self.client.handle.take_response(GetParameters.Response)
                if header is None:
                    break
                # the first answer to a request is its answer (a second server's comes later)
                self.answers.setdefault(header.request_id.sequence_number,
                                        (header.source_timestamp, response))
        return sequence in self.answers

    def close(self) -> None:
        self.client.destroy()


def _beat_first(slow: tuple[int, Any], beat: tuple[int, Any]) -> bool:
    """Whether the heartbeat's answer (``(source timestamp, response)``) left the subject
    before the slow work's, and the learner's executor ran it (the course's heartbeat says so
    only from a thread of that executor)."""
    return beat[0] < slow[0] and bool(beat[1].values)


def _servers(judge: Judge, calls: list[_Calls]) -> Optional[bool]:
    """What the judge's graph shows of the services: None while the judge's clients have not
    matched a server of each yet, True when one server serves each, False when more do.

    Read from the endpoints DDS discovery reports (``service_is_ready``, ``count_services``),
    never from the graph's list of nodes: there a subject that left can stay for good under
    its node's name (rmw_fastrtps's graph takes a node list the subject sent before it left
    after it saw the subject leave, and adds it again), and the services of a node looked up
    by name are the first such node's, in a judge that ran an earlier Worker those of the
    one that left (docs/decisions.md)."""
    node = judge.observer.quiet_node()
    if not all(c.client.service_is_ready() for c in calls):
        return None
    return all(node.count_services(c.name) == 1 for c in calls)


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


def _overlapped(judge: Judge, subject: Subject, reply: WorkerSpun) -> tuple[bool, str]:
    """Call the slow work, then the heartbeat while it runs; whether the heartbeat's answer
    left the subject first, and what went wrong otherwise (empty when nothing did)."""
    observer, told = judge.observer, told_to(judge)
    slow, beat = calls = [_Calls(judge, name) for name in SERVICES]
    try:
        if not observer.wait_until(lambda: _servers(judge, calls) is not None, ARRIVAL_TIMEOUT_S):
            return False, 'never'
        if not _servers(judge, calls):
            return False, 'servers'
        warm = (slow.send(WARM_UP), beat.send(WARM_UP))
        if not observer.wait_until(lambda: slow.answered(warm[0]) and beat.answered(warm[1]),
                                   ARRIVAL_TIMEOUT_S):
            return False, 'never'
        nonce, mark = new_nonce(), len(told)
        working = slow.send(nonce)
        if not observer.wait_until(lambda: started(told, mark, nonce), ARRIVAL_TIMEOUT_S):
            return False, 'never'
        beating = beat.send(WARM_UP)
        observer.wait_until(lambda: beat.answered(beating), BEAT_PATIENCE_S)
        one_server = _servers(judge, calls)
        subject.request(WorkerRelease())
        observer.wait_until(lambda: slow.answered(working) and beat.answered(beating),
                            ARRIVAL_TIMEOUT_S)
        if one_server is False:
            return False, 'servers'
        if not (slow.answered(working) and beat.answered(beating)):
            return False, 'never'
        return _beat_first(slow.answers[working], beat.answers[beating]), ''
    finally:
        for call in calls:
            call.close()


def _responsive_worker(judge: Judge) -> str:
    subject = judge.file_subject(course.PROMISES_FILE)
    observer, name = judge.observer, 'responsive_worker'
    told_to(judge)  # the judge's subscription exists before the subject looks for it
    reply = subject.request(Worker(name=course.WORKER_FUNCTION, topic=WITNESS_TOPIC,
                                   services=list(SERVICES), seconds=ARRIVAL_TIMEOUT_S),
                            timeout=ARRIVAL_TIMEOUT_S + 30)
    if not reply.ok:
        judge.drop(('file', course.PROMISES_FILE))
        _worker_refused(reply)
    try:
        overlap, problem = _overlapped(judge, subject, reply)
        # the name as the graph shows it, while the node runs (the reply only words a failure)
        named = reply.name == name and \
            observer.wait_until(lambda: observer.has_node(name), ARRIVAL_TIMEOUT_S)
    finally:
        stopped = subject.request(WorkerStop(), timeout=60)
        judge.drop(('file', course.PROMISES_FILE))
    if stopped.failure is not None:
        raise learner_error(stopped.failure.callback, stopped.failure)
    if not named:
        raise CheckFailed(f"{course.WORKER_FUNCTION}() returned a Worker called "
                          f"{reply.name}; name it '{name}'.")
    if problem == 'servers':
        raise CheckFailed('Something in your code answers for the Worker: the grader calls '
                          "the Worker's own callbacks, which only your executor runs; return "
                          'the Worker and its executor, and add no node or service of your own.')
    if problem == 'never':
        raise CheckFailed(f'slow_work never ran within {ARRIVAL_TIMEOUT_S:g} s: add the Worker '
                          'to no other executor, and keep both its callback groups.')
    if overlap:
        return (f'a heartbeat came while slow_work was busy, on a {reply.executor}: the two '
                'timers run side by side.')
    raise CheckFailed(f'No heartbeat came while slow_work was busy: {_worker_cause(reply)}.')


@judged
def check_responsive_worker(judge: Judge) -> str:
    """Check part 4 of ``promises.py``: a slow callback no longer holds up the heartbeat.

    Calls your ``responsive_worker()`` for its node and executor, puts the course's own
    slow work and heartbeat in place of the Worker's two timers (as services, in the
    callback groups you chose) and spins your executor on the wall clock.  The grader calls
    them and times the answers itself: a heartbeat must be answered while ``slow_work`` is
    busy.  When none does, the line says why, from the executor and the timers' callback
    groups.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the cause.
    """
    return _responsive_worker(judge)
