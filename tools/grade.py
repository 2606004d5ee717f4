#!/usr/bin/env python3
"""Grade learners' notebooks with nbgrader: ``make grade SUBMISSIONS=DIR`` (or a .zip).

A thin wrapper around nbgrader (generate_assignment, zip_collect, autograde,
generate_feedback and its Gradebook); it grades nothing itself.

DIR/<learner-id>/ holds a learner's copies of notebooks/NN-*.ipynb (any subset).  A .zip
from a learning platform is collected with ``nbgrader zip_collect``; inside it each file
must sit in a folder named after the learner (``<learner-id>/NN-title.ipynb``).

Isolation, per notebook: its own ``nbgrader autograde`` process and kernel, its own
``ROS_DOMAIN_ID``, a time limit per cell and per notebook, and a scratch copy of the
course outside this repository (one scratch workspace per learner, so notebook 05 builds
the package that learner wrote in 03 and 04).  The kernel runs as the same user as you:
for an untrusted class run this inside a container or a VM.  This repository is written
to only under ``grading/``.

Output (``grading/``): ``grades.csv`` (learner,notebook,score,max_score, then a TOTAL row
per learner), ``feedback/<learner>/<notebook>.html`` and ``nbgrader/``, an nbgrader course
folder with its gradebook (``cd grading/nbgrader && nbgrader export`` and the formgrader
work there).  Exit code 0 when grading itself worked, whatever the learners scored.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import csv
import html
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
SOLUTIONS = ROOT / 'solutions'
ASSIGNMENT = 'ros2-pubsub'
LEARNER_ID = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]*$')
#: Seconds one cell may run before nbgrader interrupts it (a hang scores 0 for that part).
CELL_TIMEOUT_S = 120
#: Seconds one notebook may take in all before its process group is killed.
NOTEBOOK_TIMEOUT_S = 600
#: Notebooks graded at the same time (one kernel each).
JOBS = 2

SCORE_ONLY_CONFIG = '''\
# Score notebooks that were already executed in isolation: no execution, keep outputs.
from nbgrader.converters.autograde import Autograde
from nbgrader.preprocessors import ClearOutput, Execute

defaults = Autograde.class_traits()
c.Autograde.sanitize_preprocessors = [
    p for p in defaults['sanitize_preprocessors'].default() if p is not ClearOutput]
c.Autograde.autograde_preprocessors = [
    p for p in defaults['autograde_preprocessors'].default() if p is not Execute]
'''


@dataclass
class Learner:
    """One learner's submission and what happened to it."""

    name: str
    files: dict[str, Path]
    notes: dict[str, str] = field(default_factory=dict)


def nbgrader(course: Path, *args: str, env: dict[str, str] | None = None,
             timeout: float | None = None, log: Path | None = None) -> int:
    """Run ``nbgrader ARGS`` for the course folder; return its exit code (-9 on timeout)."""
    argv = [sys.executable, '-m', 'nbgrader', *args, f'--CourseDirectory.root={course}',
            f'--CourseDirectory.db_url=sqlite:///{course / "gradebook.db"}', '--log-level=INFO']
    env = dict(env or os.environ)
    # nbgrader runs `alembic` by name: the venv's bin/ must come first on PATH.
    env['PATH'] = os.pathsep.join([str(Path(sys.executable).parent), env.get('PATH', '')])
    env.setdefault('JUPYTER_CONFIG_DIR', str(course / '.jupyter'))
    out = open(log, 'a') if log else subprocess.DEVNULL
    try:
        proc = subprocess.Popen(argv, cwd=course, env=env, stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
        try:
            return proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
            return -9
    finally:
        if log:
            out.close()


def set_up_course(course: Path) -> list[str]:
    """Create the nbgrader course (source with hidden tests, release, gradebook)."""
    source = course / 'source' / ASSIGNMENT
    source.mkdir(parents=True)
    for notebook in sorted(SOLUTIONS.glob('*.ipynb')):
        shutil.copy2(notebook, source / notebook.name)
    (course / 'nbgrader_config.py').write_text(
        'c = get_config()  # noqa: F821\n')
    if nbgrader(course, 'generate_assignment', ASSIGNMENT, '--force',
                log=course / 'grading.log') != 0:
        sys.exit(f'nbgrader generate_assignment failed: see {course / "grading.log"}')
    return sorted(p.stem for p in source.glob('*.ipynb'))


def collect_zip(archive: Path, course: Path) -> Path:
    """``nbgrader zip_collect`` a platform download; return the folder of learner folders."""
    downloaded = course / 'downloaded' / ASSIGNMENT / 'archive'
    downloaded.mkdir(parents=True)
    shutil.copy2(archive, downloaded / archive.name)
    regexp = (r'.*/extracted/(?:.*/)?(?P<student_id>[A-Za-z0-9][A-Za-z0-9_.-]*)/'
              r'(?P<file_id>[^/]+\.ipynb)$')
    code = nbgrader(course, 'zip_collect', ASSIGNMENT, '--force',
                    f'--FileNameCollectorPlugin.named_regexp={regexp}',
                    log=course / 'grading.log')
    if code != 0:
        sys.exit(f'nbgrader zip_collect failed: see {course / "grading.log"}')
    collected = course / 'collected'
    if not (course / 'submitted').is_dir():
        sys.exit(f'{archive.name} holds no <learner-id>/NN-title.ipynb files: each notebook must '
                 'sit in a folder named after its learner.')
    shutil.move(course / 'submitted', collected)
    for learner in collected.iterdir():  # <learner>/<assignment>/NB -> <learner>/NB
        for notebook in (learner / ASSIGNMENT).glob('*.ipynb'):
            shutil.move(notebook, learner / notebook.name)
        shutil.rmtree(learner / ASSIGNMENT, ignore_errors=True)
    return collected


def find_learners(folder: Path, notebooks: list[str]) -> list[Learner]:
    """One Learner per sub-folder; files named like a course notebook are kept."""
    learners = []
    for entry in sorted(folder.iterdir()):
        if not entry.is_dir():
            continue
        if not LEARNER_ID.match(entry.name):
            print(f'skipped {entry.name!r}: a learner id uses letters, digits, _ . - only')
            continue
        files = {p.stem: p for p in entry.glob('*.ipynb') if p.stem in notebooks}
        learner = Learner(entry.name, files)
        for other in sorted(entry.iterdir()):
            if other.is_file() and other.stem not in files:
                learner.notes.setdefault('_other', '')
                learner.notes['_other'] += f'{other.name} is not a course notebook; '
        learners.append(learner)
    return learners


def readable(path: Path) -> str | None:
    """Return why a submitted file cannot be graded, or None when it is a valid notebook."""
    if path.stat().st_size == 0:
        return 'the file is empty'
    try:
        nbformat.validate(nbformat.read(path, as_version=4))
    except Exception as error:  # json, schema or encoding errors alike
        return f'the file is not a valid notebook ({type(error).__name__})'
    return None


def note_notebook(course: Path, notebook: str, message: str) -> nbformat.NotebookNode:
    """The released notebook with ``message`` as the error output of every graded cell.

    Scored by nbgrader like any run notebook: each graded cell is 0 and shows why.
    """
    nb = nbformat.read(course / 'release' / ASSIGNMENT / f'{notebook}.ipynb', as_version=4)
    nb.cells.insert(0, nbformat.v4.new_markdown_cell(f'**Grading note:** {message}'))
    for cell in nb.cells:
        if cell.cell_type == 'code' and cell.metadata.get('nbgrader', {}).get('grade'):
            cell.execution_count = 1
            cell.outputs = [nbformat.v4.new_output(
                'error', ename='GradingError', evalue=message,
                traceback=[f'GradingError: {message}'])]
    return nb


def run_one(course: Path, scratch: Path, learner: Learner, notebook: str, domain: int,
            cell_timeout: int, notebook_timeout: int) -> nbformat.NotebookNode:
    """Autograde one notebook in a scratch course of its own; return the executed notebook."""
    problem = readable(learner.files[notebook])
    if problem:
        learner.notes[notebook] = problem
        return note_notebook(course, notebook, f'{problem}; 0 points.')
    # A fresh nbgrader course per notebook; the workspace is the learner's, across notebooks.
    grader = scratch / f'course-{notebook}'
    shutil.copytree(course / 'source', grader / 'source')
    shutil.copy2(course / 'gradebook.db', grader / 'gradebook.db')
    shutil.copy2(course / 'nbgrader_config.py', grader / 'nbgrader_config.py')
    submitted = grader / 'submitted' / learner.name / ASSIGNMENT
    submitted.mkdir(parents=True)
    shutil.copy2(learner.files[notebook], submitted / f'{notebook}.ipynb')
    home = scratch / 'home'
    # Every place a kernel, IPython, matplotlib or ROS writes to is inside the scratch
    # folder (make exports some of them into this repository for `make lab`).
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
               ROS2NB_WORKSPACE=str(scratch / 'workspace' / 'ROS2_and_RL_Tutorials'),
               HOME=str(home), IPYTHONDIR=str(home / '.ipython'),
               MPLCONFIGDIR=str(home / '.matplotlib'), ROS_HOME=str(home / '.ros'),
               ROS_LOG_DIR=str(home / '.ros' / 'log'), JUPYTER_CONFIG_DIR=str(home / '.jupyter'),
               JUPYTER_DATA_DIR=str(home / '.local'), JUPYTER_RUNTIME_DIR=str(home / '.runtime'),
               PYTHONUNBUFFERED='1')
    env.pop('PIP_CACHE_DIR', None)
    log = scratch / f'{notebook}.log'
    code = nbgrader(grader, 'autograde', ASSIGNMENT, f'--student={learner.name}',
                    f'--CourseDirectory.notebook_id={notebook}', '--force',
                    f'--Execute.timeout={cell_timeout}', env=env, timeout=notebook_timeout,
                    log=log)
    executed = grader / 'autograded' / learner.name / ASSIGNMENT / f'{notebook}.ipynb'
    if code == 0 and executed.is_file():
        nb = nbformat.read(executed, as_version=4)
        timed_out = [c for c in nb.cells for o in c.get('outputs', [])
                     if o.get('output_type') == 'error' and o.get('ename') == 'CellTimeoutError']
        if timed_out:
            learner.notes[notebook] = (f'{len(timed_out)} cell(s) ran longer than '
                                       f'{cell_timeout} s and were interrupted')
        return nb
    text = log.read_text(errors='replace') if log.is_file() else ''
    if not (grader / 'gradebook.db').is_file() or not (grader / 'source').is_dir():
        reason = ('it deleted the grading files around it (outside its own folder), so it '
                  'could not be graded')
    elif code == -9:
        reason = f'it ran longer than the {notebook_timeout} s limit for a notebook and was stopped'
    elif 'DeadKernelError' in text or 'Kernel died' in text or 'kernel died' in text.lower():
        reason = 'its kernel died while it ran (e.g. the process was killed or exited)'
    else:
        errors = [line for line in text.splitlines() if 'Error' in line]
        reason = 'nbgrader could not run it' + (f': {errors[-1].strip()[:200]}' if errors else '')
    learner.notes[notebook] = reason
    return note_notebook(course, notebook, f'{reason}; 0 points.')


def grade_learner(course: Path, scratch_root: Path, learner: Learner, notebooks: list[str],
                  first_domain: int, cell_timeout: int, notebook_timeout: int) -> None:
    """Run a learner's notebooks in order, each isolated, and file them in the course."""
    # A folder of its own, not a sibling path another learner's code could guess.
    scratch = Path(tempfile.mkdtemp(prefix=f'{learner.name}-', dir=scratch_root))
    target = course / 'submitted' / learner.name / ASSIGNMENT
    target.mkdir(parents=True, exist_ok=True)
    for index, notebook in enumerate(n for n in notebooks if n in learner.files):
        domain = 1 + (first_domain + index) % 100
        nb = run_one(course, scratch, learner, notebook, domain, cell_timeout, notebook_timeout)
        nbformat.write(nb, target / f'{notebook}.ipynb')
    shutil.rmtree(scratch, ignore_errors=True)


def write_results(course: Path, out: Path, learners: list[Learner],
                  notebooks: list[str]) -> list[list[str]]:
    """grades.csv from nbgrader's gradebook, and feedback files; return the CSV rows."""
    from nbgrader.api import Gradebook, MissingEntry
    rows = []
    feedback = out / 'feedback'
    with Gradebook(f'sqlite:///{course / "gradebook.db"}') as gb:
        assignment = gb.find_assignment(ASSIGNMENT)
        maxima = {nb.name: nb.max_score for nb in assignment.notebooks}
        for learner in learners:
            total = 0.0
            (feedback / learner.name).mkdir(parents=True, exist_ok=True)
            for notebook in notebooks:
                try:
                    score = gb.find_submission_notebook(notebook, ASSIGNMENT, learner.name).score
                except MissingEntry:
                    score = 0.0
                total += score
                rows.append([learner.name, notebook, f'{score:g}', f'{maxima[notebook]:g}'])
                made = course / 'feedback' / learner.name / ASSIGNMENT / f'{notebook}.html'
                page = feedback / learner.name / f'{notebook}.html'
                if notebook in learner.files and made.is_file():
                    shutil.copy2(made, page)
                else:
                    page.write_text(
                        f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{notebook}'
                        f'</title></head><body><h1>{html.escape(learner.name)}: {notebook}</h1>'
                        f'<p>Not submitted: 0 of {maxima[notebook]:g} points.</p></body></html>\n')
            rows.append([learner.name, 'TOTAL', f'{total:g}', f'{sum(maxima.values()):g}'])
    with open(out / 'grades.csv', 'w', newline='') as stream:
        writer = csv.writer(stream)
        writer.writerow(['learner', 'notebook', 'score', 'max_score'])
        writer.writerows(rows)
    return rows


def main() -> int:
    parser = argparse.ArgumentParser(description='Grade learners\' notebooks with nbgrader.')
    parser.add_argument('submissions', type=Path, help='folder of learner folders, or a .zip')
    parser.add_argument('--out', type=Path, default=ROOT / 'grading')
    parser.add_argument('--cell-timeout', type=int, default=CELL_TIMEOUT_S)
    parser.add_argument('--notebook-timeout', type=int, default=NOTEBOOK_TIMEOUT_S)
    parser.add_argument('--jobs', type=int, default=JOBS)
    parser.add_argument('--force', action='store_true',
                        help='replace an earlier grading/ (and any manual grades in it)')
    args = parser.parse_args()
    submissions, out = args.submissions.resolve(), args.out.resolve()
    if not submissions.exists():
        print(f'{submissions} does not exist: pass SUBMISSIONS=folder-of-learner-folders or a .zip')
        return 2
    if out.exists() and any(out.iterdir()):
        if not args.force:
            print(f'{out} holds an earlier grading (maybe with manual grades): move it away, '
                  'or run again with FORCE=1 to replace it.')
            return 2
        shutil.rmtree(out)
    out.mkdir(parents=True, exist_ok=True)
    course = out / 'nbgrader'
    course.mkdir()
    notebooks = set_up_course(course)
    if submissions.suffix == '.zip':
        if not zipfile.is_zipfile(submissions):
            print(f'{submissions} is not a zip file: download the submissions again.')
            return 2
        submissions = collect_zip(submissions, course)
    learners = find_learners(submissions, notebooks)
    if not learners:
        print(f'{submissions} has no learner folders (<learner-id>/NN-title.ipynb).')
        return 2
    with tempfile.TemporaryDirectory(prefix='ros2nb-grading-') as scratch_root:
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
            # Most notebooks first, so the longest learner does not start last.
            by_size = sorted(learners, key=lambda learner: -len(learner.files))
            jobs = [pool.submit(grade_learner, course, Path(scratch_root), learner, notebooks,
                                os.getpid() + 7 * i, args.cell_timeout, args.notebook_timeout)
                    for i, learner in enumerate(by_size)]
            for job in jobs:
                job.result()
    graded = [l.name for l in learners if l.files]
    log = course / 'grading.log'
    if graded:  # score what ran (nothing executes here), then write feedback, for everyone
        config = course / 'nbgrader_config.py'
        normal = config.read_text()
        # nbgrader reads the course's nbgrader_config.py (its command line has no --config);
        # the score-only settings live there only for this one run.
        config.write_text(normal + SCORE_ONLY_CONFIG)
        try:
            nbgrader(course, 'autograde', ASSIGNMENT, '--force', log=log)
        finally:
            config.write_text(normal)
        nbgrader(course, 'generate_feedback', ASSIGNMENT, '--force', log=log)
    rows = write_results(course, out, learners, notebooks)
    (out / 'notes.json').write_text(json.dumps({l.name: l.notes for l in learners}, indent=1,
                                               sort_keys=True) + '\n')
    totals = {row[0]: f'{row[2]}/{row[3]}' for row in rows if row[1] == 'TOTAL'}
    for learner in learners:
        notes = '; '.join(f'{k}: {v}' for k, v in sorted(learner.notes.items()))
        print(f'{learner.name}: {totals[learner.name]}' + (f'  ({notes})' if notes else ''))
    print(f'wrote {out / "grades.csv"} and {out / "feedback"}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
