"""What a Dask worker does for ``ros2nb-grade --scheduler``: check its course, grade one learner.

Runs on a worker host where the course is installed (the course's image, or a clone with
``make setup``), as root while grading, like the grader on one machine.  A learner is graded by
:func:`.learners.grade_learner`, the function a local grading runs, in the same sandboxes; what
goes back to the instructor is only what grading made of them (:class:`.learners.Graded`, whole:
the notebooks filed for nbgrader, the notes, the judge's results and flags), and the worker's
address.  Nothing here decides a point.
"""

from __future__ import annotations

import hashlib
import os
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from ...paths import ASSIGNMENT, ROOT
from ..intake.submissions import Learner
from ..judging.judges import Judges
from ..judging.learners import Graded, grade_learner
from ..judging.settings import Settings
from ..sandbox import bubblewrap
from ..sandbox.scratch import grading_folder

#: The folders whose files make a course version: the code that runs and judges learners
#: (ros2nb, ros2nb_instructor), the solutions (the hidden tests) and the pinned packages.
VERSIONED = ('src/ros2nb', 'src/ros2nb_instructor', 'solutions', 'environment/requirements.txt')


def course_version(root: Path = ROOT) -> str:
    """A digest of the installed course: every file under :data:`VERSIONED` (bytecode caches
    aside), by path and content, and the Python version; 16 hex digits.

    Two hosts with the same digest run the same judge and sandbox code on the same hidden
    tests with the same pinned packages (installed from the same requirements), so they grade
    a notebook alike.  Introduced for ``ros2nb-grade --scheduler`` (docs/classroom-server.md).
    """
    digest = hashlib.sha256(f'python {sys.version_info[0]}.{sys.version_info[1]}\n'.encode())
    for part in VERSIONED:
        top = root / part
        files = [top] if top.is_file() else sorted(
            p for p in top.rglob('*') if p.is_file() and '__pycache__' not in p.parts)
        for path in files:
            digest.update(f'{path.relative_to(root)}\n'.encode())
            digest.update(hashlib.sha256(path.read_bytes()).digest())
    return digest.hexdigest()[:16]


def resource_name(version: str) -> str:
    """The Dask worker resource a worker of course ``version`` is given once it is checked."""
    return f'ros2nb-course-{version}'


async def accept(version: str, sandboxed: bool, dask_worker: Any = None) -> Optional[str]:
    """Run on each worker (``Client.run``): None when it may grade for an instructor whose
    course is ``version`` (it then holds :func:`resource_name`, which every learner's task
    needs, one per thread, and the scheduler knows it), else why not, in words that end the
    instructor's line."""
    mine = course_version()
    if mine != version:
        return (f'its course is version {mine}, the instructor\'s {version} (update it: git pull '
                '&& make setup, or the course image of the instructor\'s commit)')
    why = bubblewrap.problem() if sandboxed else None
    if why:
        return (f'no sandbox can be made there ({why}); grading runs learners\' code '
                '(NO_SANDBOX=1 grades trusted work unsandboxed)')
    if dask_worker is not None:
        await dask_worker.set_resources(**{resource_name(version): dask_worker.state.nthreads})
    return None


class WrongCourse(RuntimeError):
    """A learner's task reached a worker whose course is not the instructor's (it changed
    since the worker was checked): nothing of the learner's ran there."""


@dataclass(frozen=True)
class Job:
    """One learner's task: what a worker needs to grade them (all of it travels to it).

    :ivar id: the learner's nbgrader id.
    :ivar files: notebook -> the bytes handed in (None: the instructor could not read it).
    :ivar release: notebook -> the course's released notebook as the instructor's nbgrader
        made it (the learner's notebooks only).
    """

    id: str
    files: dict[str, Optional[bytes]]
    release: dict[str, str]
    notebooks: tuple[str, ...]
    settings: Settings
    version: str


@dataclass(frozen=True)
class FromWorker:
    """What travels back from a worker: what it made of one learner, and its address."""

    graded: Graded
    worker: str


def grade_job(job: Job) -> FromWorker:
    """Grade one learner on this worker, as :func:`.learners.grade_learner` grades on one
    machine, in a folder of its own that is gone when it returns.

    :raises WrongCourse: when this worker's course is not ``job.version``.
    """
    mine = course_version()
    if mine != job.version:
        raise WrongCourse(f'the worker\'s course is version {mine}, not {job.version}')
    with grading_folder('ros2nb-worker-') as top:
        release = top / 'course' / 'release' / ASSIGNMENT
        release.mkdir(parents=True)
        for notebook, text in job.release.items():
            (release / f'{notebook}.ipynb').write_text(text)
        handed_in = top / 'handed-in'
        handed_in.mkdir()
        for notebook, data in job.files.items():
            if data is not None:  # a file the instructor could not read stays missing here
                (handed_in / f'{notebook}.ipynb').write_bytes(data)
        learner = Learner(job.id, job.id, {n: handed_in / f'{n}.ipynb' for n in job.files})
        scratch = top / 'scratch'
        scratch.mkdir()
        scratch.chmod(0o711)
        judges = Judges(1)  # a notebook's judge beside the learner's next notebook
        try:
            graded = grade_learner(top / 'course', scratch, learner, list(job.notebooks),
                                   job.settings, judges)
        finally:
            judges.close()
        return FromWorker(graded, _worker_address())


def _worker_address() -> str:
    try:
        from distributed import get_worker
        return get_worker().address
    except (ImportError, ValueError):
        return f'pid {os.getpid()}'
