"""Grading a class on a Dask cluster (``make grade SCHEDULER=tcp://host:8786``): a task a learner.

Runs on the instructor's host.  Each learner is one task of a Dask scheduler, graded on a
worker where the course is installed by :func:`.worker.grade_job` (the local grading's
:func:`.learners.grade_learner`, in the same sandboxes); what comes back is filed in the
instructor's nbgrader course, which scores it as on one machine (:mod:`.cli`).

A worker is checked before any learner runs there (:func:`.worker.accept`): the same
course version (:func:`.worker.course_version`) and a sandbox; a worker refused gets one
line and never the resource the learners' tasks need.  Workers that join later are checked as
they come.  A worker that dies while it holds learners costs nobody: the scheduler runs their
tasks again elsewhere, and each learner's result is taken once, from the one task that finished.
"""

from __future__ import annotations

import os
import time
import uuid
from pathlib import Path
from typing import TYPE_CHECKING, Any, Hashable, Iterator, Optional

from ...paths import ASSIGNMENT
from ..intake.submissions import MAX_SUBMISSION_BYTES, Learner
from ..judging.learners import file_graded
from ..judging.settings import Settings
from .worker import FromWorker, Job, accept, course_version, grade_job, resource_name

if TYPE_CHECKING:  # only the type: a class on a cluster imports distributed when it connects
    from distributed import Future

#: Seconds to wait for a scheduler to answer, and for its first worker to join.
CONNECT_S = 30
WORKERS_S = 120
#: Seconds between looks for workers that joined (they are checked before they grade).
LOOK_S = 5


class ClusterProblem(Exception):
    """Grading on the cluster cannot start; the message is the one line to print."""


class Cluster:
    """The instructor's connection to a Dask scheduler, for one class.

    :ivar graded_by: learner id -> the address of the worker whose result was taken.
    :ivar refused: worker address -> why it grades nobody.
    """

    def __init__(self, address: str, settings: Settings) -> None:
        """Connect and check every worker there.

        :raises ClusterProblem: when no scheduler answers, no worker joins within
            :data:`WORKERS_S`, or no worker can grade (each refused worker is printed).
        """
        from distributed import Client  # only a class on a cluster pays for the import
        self.address, self.settings = address, settings
        self.version = course_version()
        self.graded_by: dict[str, str] = {}
        self.refused: dict[str, str] = {}
        self._accepted: set[str] = set()
        try:
            self.client = Client(address, timeout=CONNECT_S, set_as_default=False)
        except (OSError, TimeoutError, ValueError) as error:
            raise ClusterProblem(f'No Dask scheduler answered at {address} ({error}): start '
                                 'one (dask scheduler), or grade here without SCHEDULER.') from None
        try:
            try:
                self.client.wait_for_workers(1, timeout=WORKERS_S)
            except TimeoutError:
                raise ClusterProblem(f'No worker joined the Dask scheduler at {address} within '
                                     f'{WORKERS_S} s: start workers (dask worker {address}) where '
                                     'the course is installed.') from None
            self._check_new_workers()
            if not self._accepted:
                raise ClusterProblem(f'No worker of the Dask scheduler at {address} can grade '
                                     f'this class (course version {self.version}): see the '
                                     'lines above.')
        except BaseException:
            self.client.close()
            raise
        print(f'grading on the Dask scheduler at {address}: {len(self._accepted)} worker(s) of '
              f'course version {self.version}', flush=True)

    def _check_new_workers(self) -> bool:
        """Check the workers not seen before; print one line for each one refused.  True
        when one was accepted."""
        workers = set(self.client.scheduler_info(n_workers=-1)['workers'])
        new = sorted(workers - self._accepted - set(self.refused))
        if not new:
            return False
        before = len(self._accepted)
        try:
            answers = self.client.run(accept, self.version, self.settings.sandboxed,
                                      workers=new, on_error='return')
        except (OSError, ValueError, KeyError):  # one left meanwhile: look again next time
            return False
        for worker in new:
            why = answers.get(worker, 'it left before it was checked')
            if isinstance(why, BaseException):
                why = f'checking it failed ({type(why).__name__}: {str(why)[:200]})'
            if why is None:
                self._accepted.add(worker)
            else:
                self.refused[worker] = why
                print(f'worker {worker} refused, no learner runs there: {why}', flush=True)
        return len(self._accepted) > before

    def graded(self, course: Path, learners: list[Learner], notebooks: list[str]
               ) -> Iterator[list[tuple[Learner, Optional[BaseException]]]]:
        """Grade every learner on the cluster; yield them in batches as they are done, each
        with the error that kept them from being graded (None when graded).

        A learner graded is filed in ``course`` (``submitted/<id>/``, for nbgrader to score)
        and has their notes and the judge's results, as a local grading leaves them.
        """
        release = course / 'release' / ASSIGNMENT
        futures: dict[Future[FromWorker], tuple[Learner, Job]] = {}
        # Most notebooks first (a higher priority), so the longest learner does not start last.
        for learner in sorted(learners, key=lambda lr: -len(lr.files)):
            job = Job(learner.id, {n: _handed_in(p) for n, p in learner.files.items()},
                      {n: (release / f'{n}.ipynb').read_text() for n in learner.files},
                      tuple(notebooks), self.settings, self.version)
            futures[self._submit(job)] = (learner, job)
        try:
            yield from self._gathered(course, futures)
        finally:
            for future in futures:
                future.cancel()

    def _submit(self, job: Job) -> Any:
        """``job`` as a task only a checked worker runs (it needs their resource)."""
        # The key names the learner (an nbgrader id) for the dashboard, and is new each time.
        return self.client.submit(
            grade_job, job, key=f'ros2nb-learner-{uuid.uuid4().hex[:12]}-{job.id}', pure=False,
            resources={resource_name(self.version): 1}, priority=len(job.files))

    def _resubmit_unrunnable(self, futures: dict[Future[FromWorker], tuple[Learner, Job]],
                             pending: set[Future[FromWorker]]) -> None:
        """Submit again the tasks no worker could take when they were placed (every checked
        worker had gone); a worker checked since does not make the scheduler look at them.
        They never ran, so nobody is graded twice."""
        stuck = set(self.client.run_on_scheduler(_unrunnable_keys))
        for future in [f for f in pending if f.key in stuck]:
            learner, job = futures.pop(future)
            pending.discard(future)
            future.cancel()
            again = self._submit(job)
            futures[again] = (learner, job)
            pending.add(again)

    def _gathered(self, course: Path, futures: dict[Future[FromWorker], tuple[Learner, Job]]
                  ) -> Iterator[list[tuple[Learner, Optional[BaseException]]]]:
        """The learners of ``futures`` in batches as their tasks end, each taken once."""
        from distributed import wait
        pending, taken, looked = set(futures), set(), time.monotonic()
        while pending:
            if time.monotonic() - looked >= LOOK_S:  # also while results keep coming
                looked = time.monotonic()
                if self._check_new_workers():
                    self._resubmit_unrunnable(futures, pending)
            try:
                with self.client.as_current():
                    wait(list(pending), timeout=LOOK_S, return_when='FIRST_COMPLETED')
            except TimeoutError:
                continue
            batch: list[tuple[Learner, Optional[BaseException]]] = []
            for future in [f for f in pending if f.done()]:
                pending.discard(future)
                learner = futures[future][0]
                if learner.id in taken:  # one result per learner, whatever ran twice
                    continue
                taken.add(learner.id)
                try:
                    returned: FromWorker = future.result()
                    file_graded(course, learner, returned.graded)
                    self.graded_by[learner.id] = returned.worker
                    error = None
                except Exception as failed:  # noqa: BLE001 - that learner's, in a note
                    error = failed
                future.release()
                batch.append((learner, error))
            yield batch

    def close(self) -> None:
        """Disconnect from the scheduler (the scheduler and its workers go on)."""
        self.client.close()


def _unrunnable_keys(dask_scheduler: Any) -> list[Hashable]:
    """Run on the scheduler: the keys of the tasks no worker can run now."""
    return [task.key for task in dask_scheduler.unrunnable]


def _handed_in(path: Path) -> Optional[bytes]:
    """The bytes of a handed-in file, read without following a link (None when unreadable);
    at most one byte over the largest a worker grades, which it then refuses as too large."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError:
        return None
    with os.fdopen(fd, 'rb') as stream:
        return stream.read(MAX_SUBMISSION_BYTES + 1)

