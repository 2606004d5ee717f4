"""``ros2nb-grade``: grade learners' notebooks (``make grade SUBMISSIONS=DIR`` or a \
platform's .zip).

DIR/<learner>/ holds a learner's copies of notebooks/NN-*.ipynb (any subset).  nbgrader
keeps the gradebook, scores the notebooks and writes the feedback; this script decides
nothing by itself.  Per notebook, three steps, none of which the notebook can reach:

1. The learner's notebook runs in a sandbox of its own (:mod:`.bubblewrap`: its own PID and
   network namespaces, only its own scratch folder writable, the course, the gradebook,
   other learners, solutions and hidden tests invisible; time, memory, task, file-size
   and output limits), on a workspace shared only with that learner's other notebooks.
2. The judge (``python -m ros2nb.judge grade``) runs every graded cell of the course's
   source notebook, hidden tests included, on what the learner wrote (their files, the
   source of their answer cells), in a second sandbox; the learner's code runs there in
   subject processes with a sandbox of their own, and the verdicts come from the judge.
3. The judge's results become the outputs of the graded cells of the executed notebook,
   which nbgrader then scores (without executing anything) and turns into feedback.

With ``--scheduler tcp://HOST:8786`` (``SCHEDULER=...``) each learner is one task of that
Dask scheduler, graded the same way on a worker where the course is installed
(:mod:`.cluster`); nbgrader scores here, and ``grading/`` ends as it does on one machine.

Without a sandbox (no bubblewrap, no user namespaces) grading refuses to start; with
``--no-sandbox`` (``NO_SANDBOX=1``) it grades trusted work unsandboxed.

Output (``grading/``): ``grades.csv`` (learner, notebook, score, max_score, then a TOTAL
row per learner), ``feedback/<learner>/<notebook>.html``, ``notes.json``, ``report.html``
(the class at a glance, :mod:`.report`) and ``nbgrader/``,
an nbgrader course folder with its gradebook.  Exit code 0 when grading itself worked,
whatever the learners scored.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import datetime
import json
import os
import shutil
import sys
import tempfile
import threading
import time
import zipfile
from pathlib import Path
from typing import TYPE_CHECKING, Optional

from ros2nb.checks.drawn import SEED_OPTION, new_seed, parse_seed
from ros2nb.errors import Ros2nbError

from ..paths import ASSIGNMENT, ROOT
from .export.exporting import export
from .intake.hand_in_times import TimeProblem
from .intake.submissions import Learner, SubmissionProblem, find_learners
from .intake.term import (Term, add_options, forget, load_state, read_term, save_state,
                          with_extensions, with_roster)
from .judging.judges import Judges
from .judging.learners import file_graded, grade_learner
from .judging.settings import CELL_TIMEOUT_S, JOBS, NOTEBOOK_CPU_S, NOTEBOOK_TIMEOUT_S, Settings
from .reports.report import write_report
from .sandbox import bubblewrap
from .sandbox.scratch import grading_folder
from .scores.gradebook import Scoring, write_results
from .scores.nbgrader_course import collect_zip, set_up_course

if TYPE_CHECKING:
    from .cluster.client import Cluster


def _options(argv: Optional[list[str]]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('submissions', type=Path, help='folder of learner folders, or a .zip')
    parser.add_argument('--out', type=Path, default=ROOT / 'grading')
    parser.add_argument('--cell-timeout', type=int, default=CELL_TIMEOUT_S)
    parser.add_argument('--notebook-timeout', type=int, default=NOTEBOOK_TIMEOUT_S)
    parser.add_argument('--notebook-cpu', type=int, default=NOTEBOOK_CPU_S,
                        help="CPU seconds one notebook's run may use in its sandbox")
    parser.add_argument('--judge-cpu', type=int, default=None,
                        help="CPU seconds one check of a notebook's judge may use with its "
                             "subjects (default: the course's limit for each notebook)")
    parser.add_argument('--cpu-share', type=_share, default=None, metavar='CPUS',
                        help='CPUs each sandbox may use at most (e.g. 0.167: a sixth of one '
                             'core, as a small pod of a hub gets); default: what the machine '
                             'gives')
    parser.add_argument('--jobs', type=int, default=JOBS)
    parser.add_argument('--force', action='store_true',
                        help='replace an earlier grading/ (and any manual grades in it)')
    parser.add_argument('--no-sandbox', action='store_true',
                        help='grade without a sandbox: only for work you trust')
    parser.add_argument(SEED_OPTION, type=_seed, default=None,
                        help='the seed of the judges\' drawn inputs, to grade again with the '
                             'inputs of an earlier grading (its notes.json); new by default')
    parser.add_argument('--scheduler', metavar='ADDRESS',
                        help='grade on the workers of this Dask scheduler (tcp://host:8786)')
    add_options(parser)
    return parser.parse_args(argv)


def _share(text: str) -> float:
    """``--cpu-share``'s value: CPUs, more than 0 and at most this machine's."""
    share = float(text) if text.replace('.', '', 1).isdigit() else -1.0
    if not 0 < share <= (os.cpu_count() or 1):
        raise argparse.ArgumentTypeError(
            f'{text!r} is no share of this machine\'s {os.cpu_count() or 1} CPUs: give a '
            'number above 0, e.g. 0.167 for a sixth of one core')
    return share


def _seed(text: str) -> int:
    """``--seed``'s value (:func:`ros2nb.checks.drawn.parse_seed`), as argparse wants it."""
    try:
        return parse_seed(text)
    except Ros2nbError as problem:
        raise argparse.ArgumentTypeError(str(problem)) from None


def _refusal(submissions: Path, out: Path, args: argparse.Namespace) -> Optional[str]:
    """Why grading cannot start, in one line saying what to do; None when it can."""
    if not submissions.exists():
        return f'{submissions} does not exist: pass SUBMISSIONS=folder-of-learner-folders or a .zip'
    # On a cluster, learners' code runs on the workers, each checked for a sandbox there.
    why = None if args.no_sandbox or args.scheduler else bubblewrap.problem()
    if why:
        return (f'No sandbox can be made here ({why}); grading runs learners\' code, so it stops. '
                'For work you trust, run again with NO_SANDBOX=1 (--no-sandbox).')
    if args.learner and not (out / 'learners.json').is_file():
        return (f'{out} holds no earlier grading to grade {args.learner} again into: grade the '
                'class first (without LEARNER).')
    if out.exists() and any(out.iterdir()) and not args.force and not args.learner:
        return (f'{out} holds an earlier grading (maybe with manual grades): move it away, '
                'or run again with FORCE=1 to replace it.')
    if submissions.suffix == '.zip' and not zipfile.is_zipfile(submissions):
        return f'{submissions} is not a zip file: download the submissions again.'
    return None


def _grade_all(course: Path, learners: list[Learner], notebooks: list[str],
               settings: Settings, jobs: int, everyone: list[Learner]) -> None:
    """Grade every learner, ``jobs`` at a time, each notebook's judge beside the next run.

    nbgrader scores each learner as soon as they are done (with whoever else is done by
    then), in one process for the class (:class:`.gradebook.Scoring`), while the others
    still run: a class's longest learner (every notebook, one after another) is then
    followed by nbgrader scoring that learner alone, not half the class.
    """
    with grading_folder('ros2nb-grading-') as scratch_root:
        judges = Judges(jobs)
        # Most notebooks first, so the longest learner does not start last.
        ordered = sorted(learners, key=lambda learner: -len(learner.files))
        progress = Progress(sum(len(learner.files) for learner in learners), len(learners))

        def grade(learner: Learner) -> None:
            try:
                file_graded(course, learner, grade_learner(course, scratch_root, learner,
                                                           notebooks, settings, judges))
            finally:
                print(progress.learner_done(learner), flush=True)

        try:
            with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool, \
                    Scoring(course) as scoring:
                jobs_of = {pool.submit(grade, learner): learner for learner in ordered}
                scored: set[str] = set()
                while len(scored) < len(jobs_of):
                    waiting = {learner.id for job, learner in jobs_of.items()
                               if job.done()} - scored
                    if waiting:
                        _score(scoring, everyone, waiting)
                        scored |= waiting
                    else:
                        concurrent.futures.wait([job for job in jobs_of if not job.done()],
                                                return_when='FIRST_COMPLETED')
                for job, learner in jobs_of.items():
                    try:
                        job.result()
                    except Exception as error:  # noqa: BLE001 - that learner's, in a note
                        _not_graded(learner, error)
        finally:
            judges.close()


def _not_graded(learner: Learner, error: BaseException) -> None:
    """The note of a learner whose grading failed as a whole (the class goes on)."""
    learner.note('_folder', f'the grader could not grade this learner '
                            f'({type(error).__name__}: {str(error)[:200]})')


def _grade_all_on(cluster: 'Cluster', course: Path, learners: list[Learner],
                  notebooks: list[str], everyone: list[Learner]) -> None:
    """Grade every learner on ``cluster``; nbgrader scores each batch as it comes back, and
    the progress lines are a local grading's."""
    progress = Progress(sum(len(learner.files) for learner in learners), len(learners))
    with Scoring(course) as scoring:
        for batch in cluster.graded(course, learners, notebooks):
            for learner, error in batch:
                if error is not None:
                    _not_graded(learner, error)
                print(progress.learner_done(learner), flush=True)
            _score(scoring, everyone, {learner.id for learner, _error in batch})


class Progress:
    """How far grading a class has come: notebooks and learners done, and the time left.

    The estimate is the time per notebook so far times the notebooks left, shared by the
    jobs running at once; it is said once a learner is done, so it is never a guess from
    nothing.  Thread-safe (each job reports its own learner).
    """

    def __init__(self, notebooks: int, learners: int) -> None:
        self._notebooks, self._learners = notebooks, learners
        self._done_notebooks = self._done_learners = 0
        self._began = time.monotonic()
        self._lock = threading.Lock()

    def learner_done(self, learner: Learner) -> str:
        """Count ``learner``'s notebooks as done; the progress line to print."""
        with self._lock:
            self._done_learners += 1
            self._done_notebooks += len(learner.files)
            elapsed = time.monotonic() - self._began
            left = self._notebooks - self._done_notebooks
            rate = elapsed / self._done_notebooks if self._done_notebooks else 0.0
            estimate = f'about {_duration(rate * left)} left' if left else 'the last one'
            return (f'[{self._done_notebooks}/{self._notebooks} notebooks, '
                    f'{self._done_learners}/{self._learners} learners; {_duration(elapsed)} '
                    f'so far, {estimate}] {learner.shown} graded')


def _duration(seconds: float) -> str:
    """``seconds`` as ``1 h 05 min``, ``4 min 10 s`` or ``12 s``."""
    seconds = round(seconds)
    if seconds >= 3600:
        return f'{seconds // 3600} h {seconds % 3600 // 60:02d} min'
    if seconds >= 60:
        return f'{seconds // 60} min {seconds % 60:02d} s'
    return f'{seconds} s'


def _score(scoring: Scoring, learners: list[Learner], batch: set[str]) -> None:
    """nbgrader scores the learners whose ids are in ``batch`` and writes their feedback."""
    if any(learner.files for learner in learners if learner.id in batch):
        scoring.score(exclude=[learner.id for learner in learners if learner.id not in batch])


def _report(out: Path, learners: list[Learner], rows: list[list[str]],
            refused: list[str], seed: Optional[int]) -> None:
    """notes.json (with the seed that grades again with the same inputs: ``--seed``), and
    one line per learner: their total and what happened."""
    (out / 'notes.json').write_text(json.dumps(
        {'learners': {learner.shown: learner.notes for learner in learners}, 'not graded': refused,
         'seed': seed}, indent=1, sort_keys=True, ensure_ascii=False) + '\n')
    totals = {row[0]: f'{row[2]}/{row[3]}' for row in rows if row[1] == 'TOTAL'}
    for learner in learners:
        notes = '; '.join(f'{k}: {v}' for k, v in sorted(learner.notes.items()))
        print(f'{learner.shown}: {totals[learner.shown]}' + (f'  ({notes})' if notes else ''))


def main(argv: Optional[list[str]] = None) -> int:
    """``ros2nb-grade SUBMISSIONS [--out DIR] ...``: grade a class; 0 when grading worked."""
    args = _options(argv)
    started = time.monotonic()
    submissions, out = args.submissions.resolve(), args.out.resolve()
    refusal = _refusal(submissions, out, args)
    if refusal:
        print(refusal)
        return 2
    # A new grading is made beside the old one and replaces it only once complete: a
    # grading that stops half-way leaves an earlier grading/ (FORCE=1) as it was.
    out.parent.mkdir(parents=True, exist_ok=True)
    final, out = out, Path(tempfile.mkdtemp(prefix=f'.{out.name}-new-', dir=out.parent))
    if args.learner:  # the earlier grading, with one learner graded again
        shutil.copytree(final, out, symlinks=True, dirs_exist_ok=True)
    try:
        code = _grade(args, submissions, out, started)
        if code == 0:
            _replace(final, out)
        return code
    finally:
        shutil.rmtree(out, ignore_errors=True)


def _replace(final: Path, new: Path) -> None:
    """Put the complete grading ``new`` at ``final`` (an earlier one there goes only now)."""
    new.chmod(0o755)
    old = None
    if final.exists() or final.is_symlink():
        old = Path(tempfile.mkdtemp(prefix=f'.{final.name}-old-', dir=final.parent))
        os.replace(final, old / final.name)
    os.replace(new, final)
    if old:
        shutil.rmtree(old, ignore_errors=True)


def _grade(args: argparse.Namespace, submissions: Path, out: Path, started: float) -> int:
    """Grade into the empty folder ``out`` (here, or on ``args.scheduler``'s workers); 0 when
    grading worked."""
    seed = new_seed() if args.seed is None else args.seed  # one for the class: notes.json
    settings = Settings(args.cell_timeout, args.notebook_timeout, not args.no_sandbox, seed,
                        args.notebook_cpu, args.judge_cpu, args.cpu_share)
    if not args.scheduler:
        return _grade_with(None, args, submissions, out, started, settings)
    from .cluster.client import Cluster, ClusterProblem  # Dask is imported for a cluster only
    try:
        cluster = Cluster(args.scheduler, settings)
    except ClusterProblem as problem:
        print(problem)
        return 2
    try:
        return _grade_with(cluster, args, submissions, out, started, settings)
    finally:
        cluster.close()


def _grade_with(cluster: Optional['Cluster'], args: argparse.Namespace, submissions: Path,
                out: Path, started: float, settings: Settings) -> int:
    """Grade into ``out``, here (``cluster`` None) or on ``cluster``; 0 when grading worked."""
    course = out / 'nbgrader'
    if args.learner:
        notebooks = sorted(p.stem for p in (course / 'source' / ASSIGNMENT).glob('*.ipynb'))
    else:
        course.mkdir()
        notebooks = set_up_course(course)
    term, mistakes = read_term(args, notebooks)
    for line in mistakes:
        print(line)
    if term is None:
        return 2
    try:
        submissions, learners, refused = _find(submissions, course, notebooks, term)
    except (SubmissionProblem, TimeProblem) as problem:
        print(problem)
        return 2
    for line in refused:
        print(f'not graded: {line}')
    if not learners:
        print(f'{submissions} has no learner folders (<learner>/NN-title.ipynb).')
        return 2
    extended, mistakes = with_extensions(term, args, notebooks, learners)
    for line in mistakes:
        print(line)
    if extended is None:
        return 2
    term = extended
    learners = with_roster(learners, term.roster)
    graded = learners
    if args.learner:
        graded = [lr for lr in learners if lr.name == args.learner]
        if not graded:
            print(f'{args.learner} has no folder in {submissions}: name a learner who has one.')
            return 2
        kept = {learner.name: learner for learner in load_state(out)}
        graded[0].id = kept[args.learner].id if args.learner in kept else graded[0].id
        forget(course, graded[0])
        learners = sorted({**kept, args.learner: graded[0]}.values(), key=lambda lr: lr.name)
    if cluster is None:
        _grade_all(course, graded, notebooks, settings, args.jobs, learners)
    else:
        _grade_all_on(cluster, course, graded, notebooks, learners)
    save_state(out, learners)
    rows = write_results(course, out, learners, notebooks, term.deadlines, term.extensions)
    if term.export:
        for line in export(out, term.export, term.roster, term.deadlines, term.extensions,
                           learners=learners):  # out moves to args.out once complete (main)
            print(f'export: {line.replace(str(out), str(args.out.resolve()))}')
    _report(out, learners, rows, refused, settings.seed)
    try:
        write_report(out, learners, notebooks, rows, refused)
    except Exception as error:  # noqa: BLE001 - the grades stand without the overview
        print(f'grading/report.html could not be written ({type(error).__name__}: {error}); '
              'grades.csv, the feedback and notes.json are complete')
    print(f'wrote {args.out.resolve() / "grades.csv"} and {args.out.resolve() / "feedback"} in '
          f'{time.monotonic() - started:.0f} s')
    return 0


def _find(submissions: Path, course: Path, notebooks: list[str], term: Term
          ) -> tuple[Path, list[Learner], list[str]]:
    """The learners of ``submissions`` (a folder, or a platform's zip taken in through
    nbgrader's ``zip_collect``), with their hand-in times; also the folder they are in, and
    one line per entry not graded.

    :raises SubmissionProblem, TimeProblem: for a hand-in time the grader does not read.
    """
    refused: list[str] = []
    times: dict[tuple[str, str], tuple[datetime.datetime, str]] = {}
    if submissions.suffix == '.zip':
        submissions, refused = collect_zip(submissions, course, times,
                                           term.deadlines.zip_time_zone, term.canvas_learners())
    learners, not_learners = find_learners(submissions, notebooks)
    for learner in learners:  # a platform zip's times, where its folder had no timestamp.txt
        learner.handed_in.update({n: times[learner.name, p.name]
                                  for n, p in learner.files.items() if n not in learner.handed_in
                                  and (learner.name, p.name) in times})
    return submissions, learners, refused + not_learners


if __name__ == '__main__':
    sys.exit(main())
