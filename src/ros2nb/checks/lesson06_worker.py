"""Check of notebook 06's concurrency promise: a worker whose slow work no longer holds up its
heartbeat.

Part of :mod:`ros2nb.checks` (the other promises are :mod:`.lesson06`).  The learner's
``responsive_worker()`` returns a node and the executor to spin it; a subject spins them as
they are, on the wall clock.  The Worker's slow work (part 3, given) calls the slow job, a
service, and waits for its answer: here the judge hosts that service, takes the request and
holds it open.  Meanwhile it listens on ``/rosout`` for the Worker's heartbeat.  A heartbeat
that keeps coming while the judge holds the slow job (two lines, sent by the worker after the
request and apart in time) is the behaviour the part asks for, whatever produced it: a
MultiThreadedExecutor with callback groups, a slow work written as a coroutine that awaits
the call on a SingleThreadedExecutor, or a thread of the learner's own.  Nothing in the
learner's process is the course's: no callback, no service, no witness.  The graph must show
the judge as the only server of the slow job (a server of the learner's would answer at
once).  The executor, groups and coroutines the subject reports only word a failure.
"""

from __future__ import annotations

import threading
from typing import Any, Optional

from rcl_interfaces.msg import Log
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_srvs.srv import Trigger

from .. import course
from ..errors import CheckFailed
from ..judge_interface import ARRIVAL_TIMEOUT_S, Judge, learner_error
from ..subject_interface import Worker, WorkerStop
from ..subject_replies import WorkerSpun
from .base import judged

#: The slow job, as the graph names it (the Worker's client asks for ``course.SLOW_SERVICE``
#: relative to its namespace, the root).
SLOW_SERVICE = '/' + course.SLOW_SERVICE
#: The Worker's heartbeat line (part 3).
BEAT = 'heartbeat'
#: Heartbeats the judge must hear, sent after the slow job was asked for, the last at least
#: :data:`BEAT_SPREAD_S` after the first (by the worker's own stamps): what a heartbeat that
#: keeps running looks like, and what a few lines logged at once before it waits do not.
BEATS, BEAT_SPREAD_S = 2, course.HEARTBEAT_PERIOD_S / 2
#: Seconds the subject may sit idle (or work, in CPU seconds) with the slow job held and no
#: heartbeat heard before the judge gives it up: a heartbeat the learner's executor can run
#: takes it a moment of work, never a wait, so the wait ends on a state (idle with the
#: heartbeat due), never on how busy the machine is.
BEAT_PATIENCE_S = 5.0
#: The same for the first call of the slow job, which a Worker's slow timer makes every
#: ``SLOW_PERIOD_S`` of its running: a Worker that sat idle this long without asking never
#: will (and meanwhile its heartbeat fills /rosout on a clock that stands still).
ASK_PATIENCE_S = 5.0
#: /rosout as the judge taps it here: reliable, and what the Worker logged shortly before
#: the judge's subscription matched it (rcl keeps each node's last lines).
ROSOUT_QOS = QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                        durability=DurabilityPolicy.TRANSIENT_LOCAL)
#: Seconds between two looks of the judge's answering thread once the slow job is released.
ANSWER_EVERY_S = 0.02


def _never_called(request: Any, response: Any) -> Any:
    return response  # the judge's node is never spun: it takes each request itself


def _never_heard(line: Any) -> None:
    pass  # the judge's node is never spun: it takes each line itself


class _SlowJob:
    """The judge's server of the slow job, on its node that no thread spins: each request is
    taken and held, with its header, until :meth:`release`."""

    def __init__(self, judge: Judge) -> None:
        self._node = judge.observer.quiet_node()
        self.service = self._node.create_service(Trigger, SLOW_SERVICE, _never_called)
        self._held: list[Any] = []
        #: When the first request was sent (the worker's DDS stamp, ns), once one came.
        self.asked_ns: Optional[int] = None
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None

    def take(self) -> bool:
        """Take every request that came and hold it; whether one ever came."""
        with self.service.handle:
            while True:
                _request, header = self.service.handle.service_take_request(Trigger.Request)
                if header is None:
                    break
                self._held.append(header)
                if self.asked_ns is None:
                    self.asked_ns = header.source_timestamp
        return self.asked_ns is not None

    def servers(self) -> int:
        """Servers of the slow job the judge's graph shows (its own among them)."""
        return self._node.count_services(SLOW_SERVICE)

    def _answer(self) -> None:
        self.take()
        for header in self._held:
            self.service.send_response(Trigger.Response(success=True, message='done'), header)
        self._held.clear()

    def release(self) -> None:
        """Answer what is held, and from now on every request as it comes (in a thread of
        the judge's, until :meth:`close`): the worker's slow work ends, and its next ones
        never wait for long, so that it stops when asked."""
        def answering() -> None:
            while not self._stop.wait(ANSWER_EVERY_S):
                self._answer()

        self._answer()
        self._thread = threading.Thread(target=answering, name='ros2nb-slow-job', daemon=True)
        self._thread.start()

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        self._node.destroy_service(self.service)


class _Heartbeats:
    """The Worker's heartbeat lines on /rosout, as the judge's node hears them: each one's
    stamp from the worker's DDS writer (ns)."""

    def __init__(self, judge: Judge, logger: str) -> None:
        self._node = judge.observer.quiet_node()
        self._logger = logger
        self.subscription = self._node.create_subscription(Log, '/rosout', _never_heard,
                                                           ROSOUT_QOS)
        self.sent_ns: list[int] = []

    def take(self) -> None:
        """Take every line that came."""
        with self.subscription.handle:
            while True:
                taken = self.subscription.handle.take_message(Log, False)
                if taken is None:
                    break
                line, info = taken
                if line.name == self._logger and line.msg == BEAT:
                    self.sent_ns.append(int(info['source_timestamp']))

    def kept_beating(self, since_ns: Optional[int]) -> bool:
        """Whether :data:`BEATS` heartbeats were sent after ``since_ns``, spread over at least
        :data:`BEAT_SPREAD_S`."""
        after = sorted(t for t in self.sent_ns if since_ns is not None and t > since_ns)
        return len(after) >= BEATS and after[-1] - after[0] >= BEAT_SPREAD_S * 1e9

    def close(self) -> None:
        self._node.destroy_subscription(self.subscription)


def _worker_cause(reply: WorkerSpun) -> str:
    """Why no heartbeat came while the slow job was held, from the executor, groups and
    coroutines the subject says it was given (only to word what the judge saw)."""
    groups = {name: (kind, number) for name, kind, number in reply.groups}
    shared = groups.get('slow_work') == groups.get('heartbeat') and \
        groups.get('heartbeat', ('', 0))[0] == 'MutuallyExclusiveCallbackGroup'
    if shared and (reply.executor != 'SingleThreadedExecutor' or reply.coroutines):
        return ("both timers are in one MutuallyExclusiveCallbackGroup (the node's default), "
                'which runs one of its callbacks at a time, even while a coroutine waits; '
                'give each timer a group of its own')
    if reply.executor == 'SingleThreadedExecutor':
        return ('a SingleThreadedExecutor runs one callback at a time, and slow_work holds it '
                'while it waits for its answer; return a MultiThreadedExecutor (or make '
                'slow_work a coroutine that awaits self.slow_client.call_async(...))')
    if reply.threads == 1:
        return ('a MultiThreadedExecutor with num_threads=1 runs one callback at a time: give '
                'it num_threads=2')
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
        raise CheckFailed(f"The Worker's service client never found the grader's "
                          f'{course.SLOW_SERVICE} service: is the machine very busy? Run this '
                          'check again.')


def _held(judge: Judge, job: _SlowJob, heard: _Heartbeats) -> tuple[str, bool]:
    """Wait for the worker's slow job and hold it while listening for the heartbeat: what
    went wrong ('never': no slow job asked for; 'servers': another server of it), and
    whether the heartbeat kept coming meanwhile."""
    observer = judge.observer
    if not observer.wait_until(job.take, ASK_PATIENCE_S):
        return 'never', False

    def beating() -> bool:
        job.take()
        heard.take()
        return heard.kept_beating(job.asked_ns)

    beat = observer.wait_until(beating, BEAT_PATIENCE_S)
    return ('servers' if job.servers() > 1 else ''), beat


def _responsive_worker(judge: Judge) -> str:
    observer, name = judge.observer, course.WORKER_NODE
    # The slow job's server and the judge's ear exist before the subject looks for them.
    job, heard = _SlowJob(judge), _Heartbeats(judge, name)
    try:
        subject = judge.file_subject(course.PROMISES_FILE)
        reply = subject.request(Worker(name=course.WORKER_FUNCTION, seconds=ARRIVAL_TIMEOUT_S),
                                timeout=ARRIVAL_TIMEOUT_S + 30)
        if not reply.ok:
            judge.drop(('file', course.PROMISES_FILE))
            _worker_refused(reply)
        try:
            problem, beat = _held(judge, job, heard)
            # the name as the graph shows it, while the node runs (the reply only words a
            # failure)
            named = reply.name == name and \
                observer.wait_until(lambda: observer.has_node(name), ARRIVAL_TIMEOUT_S)
        finally:
            job.release()
            stopped = subject.request(WorkerStop(), timeout=60)
            judge.drop(('file', course.PROMISES_FILE))
    finally:
        job.close()
        heard.close()
    if stopped.failure is not None:
        raise learner_error(stopped.failure.callback, stopped.failure)
    if not named:
        raise CheckFailed(f"{course.WORKER_FUNCTION}() returned a Worker called "
                          f"{reply.name}; name it '{name}'.")
    if problem == 'servers':
        raise CheckFailed('Something in your code answers the slow job: the grader answers it '
                          'itself, once it has heard the heartbeat; return the Worker and its '
                          'executor, and add no node or service of your own.')
    if problem == 'never':
        raise CheckFailed(f'slow_work never asked for the slow job while the Worker ran: keep '
                          f'the Worker of part 3 as given (its slow_work calls the '
                          f'{course.SLOW_SERVICE} service), add it to no other executor, and keep '
                          'both its timers.')
    if beat:
        how = ('slow_work, a coroutine, hands the executor back while it waits'
               if 'slow_work' in reply.coroutines else 'the two timers run side by side')
        return (f'the heartbeat kept coming while slow_work waited for the slow job, on a '
                f'{reply.executor}: {how}.')
    raise CheckFailed(f'No heartbeat came while slow_work waited for the slow job: '
                      f'{_worker_cause(reply)}.')


@judged
def check_responsive_worker(judge: Judge) -> str:
    """Check part 4 of ``promises.py``: a slow callback no longer holds up the heartbeat.

    Calls your ``responsive_worker()`` for its node and executor and spins them on the wall
    clock, as they are.  The grader answers the Worker's slow job itself: it holds the
    request open and listens for the heartbeat meanwhile, which must keep coming.  A
    ``MultiThreadedExecutor`` with callback groups passes, and so does a slow work written as
    a coroutine on a ``SingleThreadedExecutor``.  When no heartbeat comes, the line says why,
    from the executor and the timers' callback groups.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the cause.
    """
    return _responsive_worker(judge)
