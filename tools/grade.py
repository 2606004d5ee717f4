#!/usr/bin/env python3
"""Grade learners' notebooks: ``make grade SUBMISSIONS=DIR`` (or a platform's .zip).

DIR/<learner>/ holds a learner's copies of notebooks/NN-*.ipynb (any subset).  nbgrader
keeps the gradebook, scores the notebooks and writes the feedback; this script decides
nothing by itself.  Per notebook, three steps, none of which the notebook can reach:

1. The learner's notebook runs in a sandbox of its own (tools/sandbox.py: its own PID and
   network namespaces, only its own scratch folder writable, the course, the gradebook,
   other learners, solutions and hidden tests invisible; time, memory, task, file-size
   and output limits), on a workspace shared only with that learner's other notebooks.
2. The judge (``python -m ros2nb.judge grade``) runs every graded cell of the course's
   source notebook, hidden tests included, on what the learner wrote (their files, the
   source of their answer cells), in a second sandbox; the learner's code runs there in
   subject processes with a sandbox of their own, and the verdicts come from the judge.
3. The judge's results become the outputs of the graded cells of the executed notebook,
   which nbgrader then scores (without executing anything) and turns into feedback.

Without a sandbox (no bubblewrap, no user namespaces) grading refuses to start; with
``--no-sandbox`` (``NO_SANDBOX=1``) it grades trusted work unsandboxed.

Output (``grading/``): ``grades.csv`` (learner, notebook, score, max_score, then a TOTAL
row per learner), ``feedback/<learner>/<notebook>.html``, ``notes.json`` and ``nbgrader/``,
an nbgrader course folder with its gradebook.  Exit code 0 when grading itself worked,
whatever the learners scored.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import csv
import html
import json
import os
import shutil
import stat
import subprocess
import sys
import tempfile
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import nbformat

sys.path.insert(0, str(Path(__file__).resolve().parent))
import graded_notebook  # noqa: E402
import sandbox  # noqa: E402
from nbgrader_cli import nbgrader_argv  # noqa: E402
from submissions import Learner, find_learners, screen_zip  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
SOLUTIONS = ROOT / 'solutions'
ASSIGNMENT = 'ros2-pubsub'
WORKSPACE_NAME = 'ROS2_and_RL_Tutorials'
#: Seconds one cell may run before its kernel is interrupted (the next cell still runs).
CELL_TIMEOUT_S = 120
#: Seconds one notebook may take in all; then its sandbox is stopped.
NOTEBOOK_TIMEOUT_S = 600
#: Seconds the judge may take for one notebook.
JUDGE_TIMEOUT_S = 600
#: Notebooks graded at the same time: one more than the CPUs (a notebook often waits).
JOBS = (os.cpu_count() or 1) + 1
#: Largest executed notebook read back (the runner cuts each cell's output at 100 kB).
MAX_NOTEBOOK_BYTES = 20_000_000
#: nbgrader settings of the course under grading/: feedback shows learners' content as text.
COURSE_CONFIG = 'c = get_config()  # noqa: F821\n'
SCORE_ONLY_CONFIG = '''\
# Score notebooks that were already run and judged: execute nothing, keep the outputs.
from nbgrader.converters.autograde import Autograde
from nbgrader.preprocessors import ClearOutput, Execute

defaults = Autograde.class_traits()
c.Autograde.sanitize_preprocessors = [
    p for p in defaults['sanitize_preprocessors'].default() if p is not ClearOutput]
c.Autograde.autograde_preprocessors = [
    p for p in defaults['autograde_preprocessors'].default() if p is not Execute]
'''


@dataclass(frozen=True)
class Settings:
    """How to grade: the limits and whether to sandbox."""

    cell_timeout: int
    notebook_timeout: int
    sandboxed: bool


def nbgrader(course: Path, *args: str, log: Path) -> int:
    """Run ``nbgrader ARGS`` for the course folder (trusted: it executes nothing of learners')."""
    argv = [*nbgrader_argv(*args), f'--CourseDirectory.root={course}',
            f'--CourseDirectory.db_url=sqlite:///{course / "gradebook.db"}', '--log-level=INFO']
    env = dict(os.environ, JUPYTER_CONFIG_DIR=str(course / '.jupyter'),
               PATH=os.pathsep.join([str(Path(sys.executable).parent), os.environ['PATH']]))
    with open(log, 'a') as out:
        return subprocess.run(argv, cwd=course, env=env, stdout=out, stderr=subprocess.STDOUT,
                              stdin=subprocess.DEVNULL).returncode


def set_up_course(course: Path) -> list[str]:
    """Create the nbgrader course (source with hidden tests, release, gradebook)."""
    source = course / 'source' / ASSIGNMENT
    source.mkdir(parents=True)
    for notebook in sorted(SOLUTIONS.glob('*.ipynb')):
        shutil.copy2(notebook, source / notebook.name)
    (course / 'nbgrader_config.py').write_text(COURSE_CONFIG)
    if nbgrader(course, 'generate_assignment', ASSIGNMENT, '--force',
                log=course / 'grading.log') != 0:
        sys.exit(f'nbgrader generate_assignment failed: see {course / "grading.log"}')
    return sorted(p.stem for p in source.glob('*.ipynb'))


def collect_zip(archive: Path, course: Path) -> tuple[Path, list[str]]:
    """nbgrader's ``zip_collect`` on a screened copy of a platform download.

    :return: the folder of learner folders, and one line per member refused.
    """
    downloaded = course / 'downloaded' / ASSIGNMENT / 'archive'
    downloaded.mkdir(parents=True)
    refused = screen_zip(archive, downloaded / archive.name)
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


def readable(path: Path) -> Optional[str]:
    """Why a handed-in file cannot be graded, or None when it is a valid notebook."""
    if path.stat().st_size == 0:
        return 'the file is empty'
    try:
        nbformat.validate(nbformat.read(path, as_version=4))
    except Exception as error:  # json, schema or encoding errors alike
        return f'the file is not a valid notebook ({type(error).__name__})'
    return None


# ------------------------------------------------------------------ one notebook
class Scratch:
    """One learner's folders outside the repository, shared by their notebooks in order."""

    def __init__(self, root: Path, learner: Learner) -> None:
        self.top = Path(tempfile.mkdtemp(prefix='learner-', dir=root))
        self.home = self.top / 'home'
        self.workspace = self.home / 'workspace' / WORKSPACE_NAME
        self.home.mkdir()
        self.top.chmod(0o711)  # the sandboxes' own user may pass, nobody may list

    def snapshot(self, notebook: str) -> Path:
        """A copy of the workspace as ``notebook``'s run left it, for that notebook's judge.

        The judge reads the copy while the learner's next notebook runs (and changes the
        workspace).  Links are copied as links, never followed; colcon's ``build``,
        ``install`` and ``log`` and anything that is not a file, folder or link stay behind
        (the judge builds a package of its own when it needs one).
        """
        target = self.top / f'workspace-{notebook}' / WORKSPACE_NAME
        target.parent.mkdir()
        target.parent.chmod(0o755)
        if self.workspace.is_dir() and not self.workspace.is_symlink():
            shutil.copytree(self.workspace, target, symlinks=True, ignore=_not_for_the_judge(
                self.workspace))
        else:
            target.mkdir()  # notebooks 00 and 01 make none
        target.chmod(0o755)
        return target

    def judge_folders(self, notebook: str) -> tuple[Path, Path]:
        """A fresh judge folder (writable by the judge and its subjects) and its inputs."""
        given, scratch = self.top / f'judge-in-{notebook}', self.top / f'judge-{notebook}'
        for folder, mode in ((given, 0o755), (scratch, 0o711)):
            folder.mkdir()
            folder.chmod(mode)  # the judge's sandbox user reads the given files
        return given, scratch


def _not_for_the_judge(workspace: Path):
    """``copytree``'s ignore function for :meth:`Scratch.snapshot`."""
    def ignored(folder: str, names: list[str]) -> list[str]:
        skip = {'build', 'install', 'log'} if Path(folder) == workspace else set()
        for name in names:
            mode = os.lstat(os.path.join(folder, name)).st_mode
            if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode) or stat.S_ISLNK(mode)):
                skip.add(name)  # a FIFO or device would block or mislead the copy
        return sorted(skip)
    return ignored


def _env(home: Path, **extra: str) -> dict[str, str]:
    """The environment inside a sandbox: everything in the learner's home, grading mode."""
    venv_bin = str(Path(sys.executable).parent)
    return {'PATH': f'{venv_bin}:/usr/bin:/bin', 'HOME': str(home), 'LANG': 'C.UTF-8',
            'PYTHONUNBUFFERED': '1', 'ROS2NB_GRADING': '1', 'TMPDIR': '/tmp',
            'IPYTHONDIR': str(home / '.ipython'), 'MPLCONFIGDIR': str(home / '.matplotlib'),
            'JUPYTER_CONFIG_DIR': str(home / '.jupyter'),
            'JUPYTER_DATA_DIR': str(home / '.local/share/jupyter'),
            'JUPYTER_RUNTIME_DIR': str(home / '.local/share/jupyter/runtime'),
            'ROS_HOME': str(home / '.ros'), 'ROS_LOG_DIR': str(home / '.ros/log'), **extra}


def run_notebook(scratch: Scratch, notebook: str, prepared: nbformat.NotebookNode,
                 settings: Settings) -> tuple[nbformat.NotebookNode, dict, Optional[str]]:
    """Execute the prepared notebook in the learner's sandbox.

    :return: the executed notebook (what ran of it), the runner's status, and a note when
        the sandbox had to be stopped.
    """
    folder = scratch.home / 'notebooks'
    folder.mkdir(exist_ok=True)
    given, done = folder / f'{notebook}.ipynb', folder / f'{notebook}.run.ipynb'
    nbformat.write(prepared, given)
    argv = [sys.executable, str(ROOT / 'tools' / 'notebook_runner.py'), str(given), str(done),
            f'--cell-timeout={settings.cell_timeout}']
    env = _env(scratch.home, ROS2NB_WORKSPACE=str(scratch.workspace))
    limits = sandbox.Limits(wall_s=settings.notebook_timeout)
    stopped = None
    if settings.sandboxed:
        box = sandbox.Sandbox(writable=[scratch.home], env=env, cwd=folder,
                              readable=[ROOT / 'src', ROOT / 'tools' / 'notebook_runner.py'],
                              hidden=[ROOT / 'src' / 'ros2nb' / 'reference'])
        result = box.run(argv, limits, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        if result.timed_out:
            stopped = (f'it ran longer than the {settings.notebook_timeout} s limit for a '
                       'notebook and was stopped')
    else:
        try:
            subprocess.run(argv, env=env, cwd=folder, timeout=settings.notebook_timeout,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            stopped = (f'it ran longer than the {settings.notebook_timeout} s limit for a '
                       'notebook and was stopped')
    try:
        if done.stat().st_size > MAX_NOTEBOOK_BYTES:
            raise ValueError('too large')
        executed = nbformat.read(done, as_version=4)
        status = json.loads(Path(str(done) + '.status.json').read_text())
    except (OSError, ValueError):  # it deleted, broke or bloated what the runner wrote
        return prepared, {'ran': 0, 'timed_out': [], 'output_cut': [], 'kernel_died_at': None,
                          'runner_error': 'its run left no readable notebook'}, stopped
    return executed, status, stopped


def judge_notebook(scratch: Scratch, notebook: str, submitted: Path, settings: Settings,
                   workspace: Path) -> tuple[dict, Optional[str]]:
    """Run the judge on what the learner wrote; return ``{grade_id: result}`` or a problem.

    :param workspace: the snapshot of the learner's workspace this notebook left
        (:meth:`Scratch.snapshot`).
    """
    given, folder = scratch.judge_folders(notebook)
    source = given / 'source.ipynb'
    shutil.copy2(SOLUTIONS / f'{notebook}.ipynb', source)
    shutil.copy2(submitted, given / 'submission.ipynb')
    for path in (source, given / 'submission.ipynb'):
        path.chmod(0o644)
    home = folder / 'home'
    home.mkdir()
    tmp = folder / 'tmp'
    tmp.mkdir()
    argv = [sys.executable, '-m', 'ros2nb.judge', 'grade', str(source),
            str(given / 'submission.ipynb')]
    env = _env(home, ROS2NB_WORKSPACE=str(workspace), ROS2NB_JUDGE='1', TMPDIR=str(tmp))
    limits = sandbox.Limits(wall_s=JUDGE_TIMEOUT_S)
    if settings.sandboxed:
        env['FASTDDS_BUILTIN_TRANSPORTS'] = 'UDPv4'  # judge and subjects: own /dev/shm each
        env['ROS2NB_SUBJECT_PREFIX'] = json.dumps(sandbox.inner_prefix(  # the course may be
            readable=[workspace, ROOT / 'src'], writable=[folder],  # under /tmp too
            hidden=[ROOT / 'src' / 'ros2nb' / 'reference']))
        box = sandbox.Sandbox(writable=[folder], env=env, cwd=folder, nested=True,
                              readable=[ROOT / 'src', workspace, given],
                              hidden=[ROOT / 'src' / 'ros2nb' / 'reference'])
        try:
            result = box.run(argv, limits, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
        except OSError as error:  # e.g. the notebook made its workspace unreadable
            return {}, f'the grader could not check it: {error}'
        out, err, code, timed_out = result.stdout, result.stderr, result.returncode, \
            result.timed_out
    else:
        try:
            done = subprocess.run(argv, env={**os.environ, **env}, cwd=folder, text=True,
                                  capture_output=True, timeout=JUDGE_TIMEOUT_S)
            out, err, code, timed_out = done.stdout, done.stderr, done.returncode, False
        except subprocess.TimeoutExpired:
            out, err, code, timed_out = '', '', -9, True
    if timed_out:
        return {}, f'checking it took longer than {JUDGE_TIMEOUT_S} s'
    try:
        return json.loads(out.strip().splitlines()[-1]), None
    except (IndexError, ValueError):
        last = (err or '').strip().splitlines()[-1:] or ['no message']
        return {}, f'the grader could not check it (judge exit code {code}: {last[0][:200]})'


def _run_note(status: dict, stopped: Optional[str]) -> Optional[str]:
    """What happened while the notebook ran, in words (None when nothing worth saying)."""
    notes = [stopped] if stopped else []
    if status.get('kernel_died_at') is not None:
        notes.append(f'its kernel died while cell {status["kernel_died_at"] + 1} ran (the '
                     'process was killed or exited); the cells after it did not run')
    if status.get('timed_out'):
        cells = ', '.join(str(i + 1) for i in status['timed_out'])
        notes.append(f'cell(s) {cells} ran longer than the limit and were interrupted; the '
                     'cells after them still ran')
    if status.get('output_cut'):
        cells = ', '.join(str(i + 1) for i in status['output_cut'])
        notes.append(f'the output of cell(s) {cells} was cut (too large to keep)')
    if status.get('runner_error'):
        notes.append(f'running it stopped early: {status["runner_error"]}')
    if not notes and not status.get('finished'):
        notes.append(f'its run ended at cell {status["ran"] + 1} of {status["cells"]}: the '
                     'notebook stopped or killed the processes running it')
    return '; '.join(notes) or None


class Judges:
    """The judges of a class, working while the learners' next notebooks run.

    A notebook's judge needs only what that notebook left (a snapshot of the workspace
    and the submitted file), so it runs beside the learner's next notebook.
    """

    def __init__(self, jobs: int) -> None:
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs),
                                                           thread_name_prefix='judge')

    def submit(self, *arguments: object) -> concurrent.futures.Future:
        return self._pool.submit(judge_notebook, *arguments)

    def close(self) -> None:
        self._pool.shutdown(wait=True)


def grade_learner(course: Path, scratch_root: Path, learner: Learner, notebooks: list[str],
                  settings: Settings, judges: Judges) -> None:
    """Grade a learner's notebooks in course order; file them in the nbgrader course.

    The notebooks run one after the other (each on the workspace the previous ones left);
    each one's judge starts as soon as it has run.
    """
    scratch = Scratch(scratch_root, learner)
    target = course / 'submitted' / learner.id / ASSIGNMENT
    target.mkdir(parents=True, exist_ok=True)
    judged = []
    try:
        for notebook in (n for n in notebooks if n in learner.files):
            release = nbformat.read(course / 'release' / ASSIGNMENT / f'{notebook}.ipynb',
                                    as_version=4)
            problem = readable(learner.files[notebook])
            if problem:
                learner.note(notebook, f'{problem}; 0 points')
                nbformat.write(graded_notebook.note_notebook(release, f'{problem}; 0 points.'),
                               target / f'{notebook}.ipynb')
                continue
            submitted = nbformat.read(learner.files[notebook], as_version=4)
            prepared = graded_notebook.for_the_run(release, submitted)
            executed, status, stopped = run_notebook(scratch, notebook, prepared, settings)
            happened = _run_note(status, stopped)
            if happened:
                learner.note(notebook, happened)
            verdict = judges.submit(scratch, notebook, learner.files[notebook], settings,
                                    scratch.snapshot(notebook))
            judged.append((notebook, release, executed, verdict))
        for notebook, release, executed, verdict in judged:
            results, problem = verdict.result()
            if problem:
                learner.note(notebook, problem)
            nbformat.write(graded_notebook.for_scoring(release, executed, results, problem),
                           target / f'{notebook}.ipynb')
    finally:
        for _notebook, _release, _executed, verdict in judged:
            concurrent.futures.wait([verdict])  # nothing of the scratch is removed in use
        shutil.rmtree(scratch.top, ignore_errors=True)


# ------------------------------------------------------------------ results
def _not_submitted_page(learner: Learner, notebook: str, points: float) -> str:
    return (f'<!DOCTYPE html><html><head><meta charset="utf-8"><title>{notebook}</title></head>'
            f'<body><h1>{html.escape(learner.name)}: {notebook}</h1><p>Not submitted: 0 of '
            f'{points:g} points.</p></body></html>\n')


def write_results(course: Path, out: Path, learners: list[Learner],
                  notebooks: list[str]) -> list[list[str]]:
    """grades.csv from nbgrader's gradebook, and the feedback files; return the CSV rows."""
    from nbgrader.api import Gradebook, MissingEntry
    rows = []
    with Gradebook(f'sqlite:///{course / "gradebook.db"}') as gb:
        maxima = {nb.name: nb.max_score for nb in gb.find_assignment(ASSIGNMENT).notebooks}
        for learner in learners:
            total = 0.0
            folder = out / 'feedback' / learner.name
            folder.mkdir(parents=True, exist_ok=True)
            for notebook in notebooks:
                try:
                    score = gb.find_submission_notebook(notebook, ASSIGNMENT, learner.id).score
                except MissingEntry:
                    score = 0.0
                total += score
                rows.append([learner.name, notebook, f'{score:g}', f'{maxima[notebook]:g}'])
                made = course / 'feedback' / learner.id / ASSIGNMENT / f'{notebook}.html'
                page = folder / f'{notebook}.html'
                if notebook in learner.files and made.is_file():
                    shutil.copy2(made, page)
                else:
                    page.write_text(_not_submitted_page(learner, notebook, maxima[notebook]))
            rows.append([learner.name, 'TOTAL', f'{total:g}', f'{sum(maxima.values()):g}'])
    with open(out / 'grades.csv', 'w', newline='') as stream:
        writer = csv.writer(stream)
        writer.writerow(['learner', 'notebook', 'score', 'max_score'])
        writer.writerows(rows)
    return rows


def score_and_feedback(course: Path) -> None:
    """nbgrader scores what was filed (executing nothing), then writes the feedback."""
    log = course / 'grading.log'
    config = course / 'nbgrader_config.py'
    # nbgrader reads the course's nbgrader_config.py (its command line has no --config);
    # the score-only settings are there only for this one run.
    config.write_text(COURSE_CONFIG + SCORE_ONLY_CONFIG)
    try:
        nbgrader(course, 'autograde', ASSIGNMENT, '--force', log=log)
    finally:
        config.write_text(COURSE_CONFIG)
    nbgrader(course, 'generate_feedback', ASSIGNMENT, '--force', log=log)


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('submissions', type=Path, help='folder of learner folders, or a .zip')
    parser.add_argument('--out', type=Path, default=ROOT / 'grading')
    parser.add_argument('--cell-timeout', type=int, default=CELL_TIMEOUT_S)
    parser.add_argument('--notebook-timeout', type=int, default=NOTEBOOK_TIMEOUT_S)
    parser.add_argument('--jobs', type=int, default=JOBS)
    parser.add_argument('--force', action='store_true',
                        help='replace an earlier grading/ (and any manual grades in it)')
    parser.add_argument('--no-sandbox', action='store_true',
                        help='grade without a sandbox: only for work you trust')
    args = parser.parse_args(argv)
    started = time.monotonic()
    submissions, out = args.submissions.resolve(), args.out.resolve()
    if not submissions.exists():
        print(f'{submissions} does not exist: pass SUBMISSIONS=folder-of-learner-folders or a .zip')
        return 2
    why = None if args.no_sandbox else sandbox.problem()
    if why:
        print(f'No sandbox can be made here ({why}); grading runs learners\' code, so it stops. '
              'For work you trust, run again with NO_SANDBOX=1 (--no-sandbox).')
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
    refused: list[str] = []
    if submissions.suffix == '.zip':
        if not zipfile.is_zipfile(submissions):
            print(f'{submissions} is not a zip file: download the submissions again.')
            return 2
        submissions, refused = collect_zip(submissions, course)
    learners, not_learners = find_learners(submissions, notebooks)
    refused += not_learners
    for line in refused:
        print(f'not graded: {line}')
    if not learners:
        print(f'{submissions} has no learner folders (<learner>/NN-title.ipynb).')
        return 2
    settings = Settings(args.cell_timeout, args.notebook_timeout, not args.no_sandbox)
    with tempfile.TemporaryDirectory(prefix='ros2nb-grading-') as scratch_root:
        Path(scratch_root).chmod(0o711)
        judges = Judges(args.jobs)
        try:
            with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, args.jobs)) as pool:
                # Most notebooks first, so the longest learner does not start last.
                ordered = sorted(learners, key=lambda learner: -len(learner.files))
                for job in [pool.submit(grade_learner, course, Path(scratch_root), learner,
                                        notebooks, settings, judges) for learner in ordered]:
                    job.result()
        finally:
            judges.close()
    if any(learner.files for learner in learners):
        score_and_feedback(course)
    rows = write_results(course, out, learners, notebooks)
    (out / 'notes.json').write_text(json.dumps(
        {'learners': {l.name: l.notes for l in learners}, 'not graded': refused},
        indent=1, sort_keys=True, ensure_ascii=False) + '\n')
    totals = {row[0]: f'{row[2]}/{row[3]}' for row in rows if row[1] == 'TOTAL'}
    for learner in learners:
        notes = '; '.join(f'{k}: {v}' for k, v in sorted(learner.notes.items()))
        print(f'{learner.name}: {totals[learner.name]}' + (f'  ({notes})' if notes else ''))
    print(f'wrote {out / "grades.csv"} and {out / "feedback"} in {time.monotonic() - started:.0f} s')
    return 0


if __name__ == '__main__':
    sys.exit(main())
