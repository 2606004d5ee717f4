"""The nbgrader course under ``grading/nbgrader``: set up from the course's kept copy, and a
platform's zip collected into it.

Runs on the instructor's host.  nbgrader runs here as a command of the course's own venv, in
the course folder, with the course's own Jupyter settings; it executes nothing of the
learners' (the Execute step is off for the scoring run, :mod:`.scoring`).
"""

from __future__ import annotations

import datetime
import fcntl
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
from importlib import metadata
from pathlib import Path
from typing import Any, Optional

from ...paths import ASSIGNMENT, ROOT, SOLUTIONS, gradebook_url
from ..intake.zips import screen_zip

#: nbgrader's command, from the course's venv (or conda environment).
NBGRADER = str(Path(sys.executable).with_name('nbgrader'))
#: Where the course's set-up is kept per version of the solutions (git-ignored).
SET_UP_CACHE = ROOT / '.cache' / 'grading-courses'
#: nbgrader settings of the course under grading/: feedback shows learners' content as text.
COURSE_CONFIG = 'c = get_config()  # noqa: F821\n'


def nbgrader(course: Path, *args: str, log: Path) -> int:
    """Run ``nbgrader ARGS`` for the course folder (trusted: it executes nothing of learners')."""
    argv = [NBGRADER, *args, f'--CourseDirectory.root={course}',
            f'--CourseDirectory.db_url={gradebook_url(course)}', '--log-level=INFO']
    return _run_logged(course, argv, log)


def _run_logged(course: Path, argv: list[str], log: Path) -> int:
    """Run ``argv`` (nbgrader, or the course's code that drives it) in the course folder, with
    the course's own Jupyter settings and the course's Python first on PATH; its output is
    appended to ``log``.  Return its exit code."""
    with open(log, 'a') as out:
        return subprocess.run(argv, cwd=course, env=course_env(course), stdout=out,
                              stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL).returncode


def course_env(course: Path) -> dict[str, str]:
    """The environment nbgrader runs in for ``course``: its own Jupyter settings, the
    course's Python first on PATH (nbgrader runs ``alembic`` by name)."""
    return dict(os.environ, JUPYTER_CONFIG_DIR=str(course / '.jupyter'),
                PATH=os.pathsep.join([str(Path(sys.executable).parent), os.environ['PATH']]))


def kept_course() -> Path:
    """The nbgrader course of the current solutions (source with hidden tests, release,
    gradebook), made by nbgrader's ``generate_assignment`` once per version of the
    solutions and kept in ``.cache/grading-courses/<digest>/``; return its folder.

    ``make test`` makes it before the tests start (the Makefile's ``grading-course``).  One
    grading makes it at a time: another that asks meanwhile (tests run without make, two
    classes graded at once) waits for that one (a lock beside it) rather than making a
    second copy.

    :raises SystemExit: when ``generate_assignment`` failed (the message names its log).
    """
    kept = SET_UP_CACHE / _solutions_digest()
    if not (kept / 'gradebook.db').is_file():
        kept.parent.mkdir(parents=True, exist_ok=True)
        with open(kept.parent / f'{kept.name}.lock', 'a') as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
            if not (kept / 'gradebook.db').is_file():
                _generate_course(kept)
    return kept


def set_up_course(course: Path) -> list[str]:
    """Create the nbgrader course in ``course``: a copy of :func:`kept_course` (its
    gradebook holds the assignment and its cells, and no learner yet).

    :return: the notebooks' names (``NN-title``), in course order.
    :raises SystemExit: when ``generate_assignment`` failed (the message names its log).
    """
    shutil.copytree(kept_course(), course, dirs_exist_ok=True)
    return sorted(p.stem for p in (course / 'source' / ASSIGNMENT).glob('*.ipynb'))


def _solutions_digest() -> str:
    """A digest of what the course's set-up depends on: the solutions and nbgrader's version."""
    parts = [f'nbgrader {metadata.version("nbgrader")}', COURSE_CONFIG]
    for notebook in sorted(SOLUTIONS.glob('*.ipynb')):
        parts += [notebook.name, hashlib.sha256(notebook.read_bytes()).hexdigest()]
    return hashlib.sha256('\n'.join(parts).encode()).hexdigest()[:16]


def _generate_course(kept: Path) -> None:
    """nbgrader's ``generate_assignment`` in a fresh folder, then in place at ``kept``."""
    fresh = Path(tempfile.mkdtemp(prefix='.making-', dir=kept.parent))
    source = fresh / 'source' / ASSIGNMENT
    source.mkdir(parents=True)
    for notebook in sorted(SOLUTIONS.glob('*.ipynb')):
        shutil.copy2(notebook, source / notebook.name)
    (fresh / 'nbgrader_config.py').write_text(COURSE_CONFIG)
    if nbgrader(fresh, 'generate_assignment', ASSIGNMENT, '--force',
                log=fresh / 'grading.log') != 0:
        sys.exit(f'nbgrader generate_assignment failed: see {fresh / "grading.log"}')
    (fresh / 'grading.log').unlink()
    try:
        fresh.rename(kept)  # another grading may have made it meanwhile: then keep that one
    except OSError:
        shutil.rmtree(fresh, ignore_errors=True)


def collect_zip(archive: Path, course: Path,
                times: Optional[dict[tuple[str, str], tuple[datetime.datetime, str]]] = None,
                zone: Any = None, canvas_learners: Optional[dict[str, str]] = None
                ) -> tuple[Path, list[str]]:
    """nbgrader's ``zip_collect`` on a screened copy of a platform download.

    :param times: filled with the hand-in times the archive says (:func:`.zips.screen_zip`),
        a zone-less entry time taken in ``zone`` (default UTC).
    :param canvas_learners: Canvas user id -> learner (the roster's), for Canvas's zip.
    :return: the folder of learner folders, and one line per member refused.
    :raises .hand_in_times.TimeProblem: for a time in the archive the grader does not read.
    """
    downloaded = course / 'downloaded' / ASSIGNMENT / 'archive'
    downloaded.mkdir(parents=True)
    refused = screen_zip(archive, downloaded / archive.name, times,
                         zone if zone is not None else datetime.timezone.utc, canvas_learners)
    regexp = r'.*/extracted/(?:.*/)?(?P<student_id>[^/]+)/(?P<file_id>[^/]+\.ipynb)$'
    code = nbgrader(course, 'zip_collect', ASSIGNMENT, '--force',
                    f'--FileNameCollectorPlugin.named_regexp={regexp}', log=course / 'grading.log')
    collected = course / 'collected'
    collected.mkdir()
    if code != 0:
        refused.append(f'nbgrader zip_collect failed (see {course / "grading.log"}); nothing '
                       'from the archive was graded')
        return collected, refused
    for learner in (course / 'submitted').iterdir() if (course / 'submitted').is_dir() else ():
        target = collected / learner.name
        target.mkdir()
        for notebook in (learner / ASSIGNMENT).glob('*.ipynb'):
            shutil.move(notebook, target / notebook.name)
    shutil.rmtree(course / 'submitted', ignore_errors=True)
    return collected, refused
