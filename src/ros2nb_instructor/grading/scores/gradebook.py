"""The nbgrader course under ``grading/``: its gradebook, scores and feedback, and grades.csv.

Runs on the instructor's host.  nbgrader keeps the gradebook, scores the notebooks and
writes the feedback; it executes nothing of the learners' here (its Execute step is off
for the scoring run: every notebook was run in a sandbox and judged before).
"""

from __future__ import annotations

import contextlib
import datetime
import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from importlib import metadata
from pathlib import Path
from typing import Any, Iterable, Optional

from nbgrader.api import Gradebook, MissingEntry
from ros2nb import graded_parts

from ...paths import ASSIGNMENT, ROOT, SOLUTIONS, gradebook_url
from ..export.spreadsheets import write_csv
from ..intake.deadlines import NO_DEADLINES, CourseSettings, Lateness, assess
from ..intake.extensions import Extensions
from ..intake.extensions import NONE as NO_EXTENSIONS
from ..intake.submissions import Learner
from ..intake.zips import screen_zip
from ..reports import feedback

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
        return subprocess.run(argv, cwd=course, env=_course_env(course), stdout=out,
                              stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL).returncode


def _course_env(course: Path) -> dict[str, str]:
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


def _not_submitted_page(learner: Learner, notebook: str, points: float, standing: str) -> str:
    return feedback.page(notebook, feedback.render('above.html.j2', boxes=[standing]) +
                         feedback.render('not_submitted.html.j2', learner=learner.shown,
                                         notebook=notebook, points=f'{points:g}'))


def standing_table(learner: Learner) -> str:
    """The learner's table of every graded part of the course (:mod:`ros2nb.graded_parts`),
    from this grading's own results (the judge's, never the learner's record of their lab):
    passed, failed, or not handed in, with its points."""
    parts = graded_parts.parts(SOLUTIONS)
    states = {}
    for part in parts:
        result = learner.results.get(part.notebook, {}).get(part.grade_id)
        states[part.grade_id] = (graded_parts.NOT_HANDED_IN if part.notebook not in learner.files
                                 else graded_parts.PASSED if result and result.passed
                                 else graded_parts.FAILED)
    return graded_parts.table_html(graded_parts.rows(parts, states),
                                   'Every notebook, as the grader found it')


#: grades.csv's columns: ``score`` is what the notebook counts (after lateness), ``raw_score``
#: what nbgrader gave it, ``late_penalty`` the difference (:mod:`.deadlines`).
CSV_COLUMNS = ['learner', 'notebook', 'score', 'max_score', 'raw_score', 'late_penalty',
               'handed_in', 'due']


def write_results(course: Path, out: Path, learners: list[Learner], notebooks: list[str],
                  deadlines: CourseSettings = NO_DEADLINES,
                  extensions: Extensions = NO_EXTENSIONS) -> list[list[str]]:
    """grades.csv from nbgrader's gradebook, and the feedback files; return the CSV rows
    (:data:`CSV_COLUMNS`; learner's name as shown, then a TOTAL row per learner).

    A handed-in notebook's lateness (:func:`.deadlines.assess`, with the learner's extension)
    goes into the learner's ``late`` and notes, and into nbgrader's gradebook as its late
    submission penalty (so ``nbgrader export`` and the formgrader show it too)."""
    rows = []
    with Gradebook(gradebook_url(course)) as gb:
        maxima = {nb.name: nb.max_score for nb in gb.find_assignment(ASSIGNMENT).notebooks}
        for learner in learners:
            total = raw_total = 0.0
            standing = feedback.standing_html(standing_table(learner))
            folder = out / 'feedback' / learner.name
            folder.mkdir(parents=True, exist_ok=True)
            for notebook in notebooks:
                try:
                    scored = gb.find_submission_notebook(notebook, ASSIGNMENT, learner.id)
                except MissingEntry:
                    scored = None
                raw = scored.score if scored is not None else 0.0
                late = None
                if notebook in learner.files:
                    late = assess(deadlines, notebook, raw, learner.handed_in.get(notebook),
                                  extensions.of(learner.name, notebook))
                    learner.late[notebook] = late
                    if late.note:
                        learner.note(notebook, late.note)
                    if scored is not None:
                        scored.late_submission_penalty = late.penalty or None
                score = late.final if late else raw
                total, raw_total = total + score, raw_total + raw
                rows.append([learner.shown, notebook, f'{score:g}', f'{maxima[notebook]:g}',
                             f'{raw:g}', f'{raw - score:g}', _time(late, 'handed_in'),
                             _time(late, 'due')])
                _feedback_page(course, folder, learner, notebook, maxima[notebook], standing)
            rows.append([learner.shown, 'TOTAL', f'{total:g}', f'{sum(maxima.values()):g}',
                         f'{raw_total:g}', f'{raw_total - total:g}', '', ''])
        gb.db.commit()
    write_csv(out / 'grades.csv', CSV_COLUMNS, rows)
    return rows


def _time(late: Optional[Lateness], which: str) -> str:
    when = getattr(late, which, None) if late else None
    return when.isoformat() if when else ''


def _feedback_page(course: Path, folder: Path, learner: Learner, notebook: str,
                   points: float, standing: str) -> None:
    """The learner's feedback page of ``notebook`` (nbgrader's, made safe, headed by the
    learner's ``standing`` in every notebook, its lateness and the judge's flags), or one
    saying it was not submitted (headed by ``standing`` too)."""
    made = course / 'feedback' / learner.id / ASSIGNMENT / f'{notebook}.html'
    page = folder / f'{notebook}.html'
    try:
        if notebook in learner.files and made.is_file():
            page.write_text(feedback.safe_feedback(made.read_text(), notebook,
                                                   learner.flags.get(notebook, ()),
                                                   learner.late.get(notebook), standing))
        else:
            page.write_text(_not_submitted_page(learner, notebook, points, standing))
    except Exception as error:  # noqa: BLE001 - that page's problem, in a note
        why = (f'its feedback page could not be written ({type(error).__name__}: '
               f'{str(error)[:200]}); the score stands')
        learner.note(notebook, why)
        page.write_text(feedback.page(notebook, feedback.render('paragraph.html.j2', text=why)))


class Scoring:
    """nbgrader scoring a class batch by batch, in one process (:mod:`.scoring`), its log
    appended to ``course/grading.log``.  A context manager: the process ends with the block.

    Introduced for ``ros2nb-grade`` (:mod:`.cli`), which scores learners as they are done.
    """

    def __init__(self, course: Path) -> None:
        self._course = course
        self._process: Optional[subprocess.Popen[str]] = None

    def __enter__(self) -> 'Scoring':
        return self

    def __exit__(self, *_: object) -> None:
        self._end()

    def score(self, exclude: Iterable[str]) -> bool:
        """nbgrader scores what was filed for every learner but ``exclude`` (executing
        nothing), then writes their feedback; True when both worked.

        :param exclude: nbgrader ids of learners left out (not yet graded, or scored before).
        """
        for _attempt in range(2):  # a process that ended meanwhile: once more, in a new one
            process = self._started()
            try:
                assert process.stdin is not None and process.stdout is not None
                process.stdin.write(json.dumps(sorted(exclude)) + '\n')
                process.stdin.flush()
                answer = process.stdout.readline()
            except OSError:
                answer = ''
            if answer:
                with contextlib.suppress(ValueError, AttributeError):
                    return bool(json.loads(answer).get('ok'))
                return False
            self._end()
        return False

    def _started(self) -> subprocess.Popen[str]:
        if self._process is None:
            with open(self._course / 'grading.log', 'a') as log:
                self._process = subprocess.Popen(
                    [sys.executable, '-m', 'ros2nb_instructor.grading.scores.scoring',
                     str(self._course)], cwd=self._course, env=_course_env(self._course),
                    stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log, text=True)
        return self._process

    def _end(self) -> None:
        process, self._process = self._process, None
        if process is not None:
            with contextlib.suppress(OSError):
                process.stdin.close()  # type: ignore[union-attr]  # started with a pipe
            process.wait()
            process.stdout.close()  # type: ignore[union-attr]  # started with a pipe
