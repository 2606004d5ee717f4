"""Judging one learner notebook: ros2nb's judge in a sandbox, its subjects sandboxed again.

Runs on the instructor's host.  The judge (``python -m ros2nb.judge grade``) runs every
graded cell of the course's source notebook on what the learner wrote, in a second
sandbox; a notebook's judge works beside the learner's next notebook.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any, NamedTuple, Optional

import nbformat

from ros2nb import nbmeta
from ros2nb.checks.drawn import SEED_OPTION
from ros2nb.judge.subjects import HANDED, SUBJECTS_FOLDER_ENV
from ros2nb.outcomes import CellChecked, CheckOutcome, NotebookChecked
from ros2nb.typed_json import Unreadable, decoded

from ...paths import ROOT, SOLUTIONS
from ..sandbox import bubblewrap
from ..sandbox.scratch import Scratch, sandbox_env
from .settings import JUDGE_TIMEOUT_S, Settings


#: What the subjects never see: the course's reference nodes, the checks and the judge (their
#: expectations, the stand-ins), the rules, the grader, each with its compiled forms (a
#: subject needs none: the judge sends the stand-ins it runs, ros2nb.subject.out_of_reach).
ANSWER_FOLDERS = [ROOT / 'src' / 'ros2nb' / 'reference', ROOT / 'src' / 'ros2nb' / 'checks',
                  ROOT / 'src' / 'ros2nb' / 'judge', ROOT / 'src' / 'ros2nb_instructor',
                  ROOT / 'src' / 'ros2nb' / 'rules.py',
                  *(ROOT / 'src' / 'ros2nb' / '__pycache__').glob('rules.*'),
                  *(ROOT / 'src' / 'ros2nb' / 'subject' / '__pycache__').glob('stand_ins.*')]
#: Flags of one notebook kept for the instructor's notes (each cut to 300 characters).
MAX_FLAGS = 20


class Verdict(NamedTuple):
    """What the judge decided about one notebook.

    :ivar results: ``{grade_id: outcome}`` (empty when nothing could be checked).
    :ivar problem: why nothing could be checked, or None.
    :ivar flags: code that reaches into the course, for the instructor (:mod:`ros2nb.judge.flags`).
    """

    results: dict[str, CheckOutcome]
    problem: Optional[str]
    flags: tuple[str, ...] = ()


def judge_notebook(scratch: Scratch, notebook: str, submitted: nbformat.NotebookNode,
                   settings: Settings, workspace: Path) -> Verdict:
    """Run the judge on what the learner wrote; return its :class:`Verdict`.

    :param submitted: the learner's notebook as the grader read it (nbformat 4, whatever
        version was handed in; attachments too large to keep already dropped).
    :param workspace: the snapshot of the learner's workspace this notebook left
        (:meth:`Scratch.snapshot`).
    """
    given, folder = scratch.judge_folders(notebook)
    source = given / 'source.ipynb'
    shutil.copyfile(SOLUTIONS / f'{notebook}.ipynb', source)
    (given / 'submission.ipynb').write_text(nbformat.writes(submitted))
    for path in (source, given / 'submission.ipynb'):
        path.chmod(0o644)
    # The judge's own files (home, temporary files) and the subjects' are apart: a subject
    # or program may write only a folder of its own under subjects/ (the judge binds it in
    # for it), and read the judge's inputs in subjects/handed/; so nothing the judge later
    # loads, imports or reads as its own (its cwd is `given`, sys.path[0] of `python -m`;
    # its home) is the learner's, and nothing one of them wrote reaches the next.
    own, subjects = folder / 'judge', folder / 'subjects'
    for part in (own / 'home', own / 'tmp', subjects / HANDED):
        part.mkdir(parents=True)
    argv = judge_argv(source, given / 'submission.ipynb', settings)
    env = sandbox_env(own / 'home', ROS2NB_WORKSPACE=str(workspace),
                      TMPDIR=str(own / 'tmp'), **{SUBJECTS_FOLDER_ENV: str(subjects)})
    limits = bubblewrap.Limits(wall_s=JUDGE_TIMEOUT_S, cpu_step_s=settings.judge_cpu_for(notebook),
                            cpu_share=settings.cpu_share)
    try:
        if settings.sandboxed:
            env['FASTDDS_BUILTIN_TRANSPORTS'] = 'UDPv4'  # judge and subjects: own /dev/shm each
            env['ROS2NB_SUBJECT_PREFIX'] = json.dumps(bubblewrap.inner_prefix(  # the course may
                readable=[workspace, ROOT / 'src', subjects / HANDED],  # be under /tmp too
                hidden=[*ANSWER_FOLDERS, own, given]))
            # The judge may read the course's reference nodes (a notebook handed in alone runs
            # on them where it relies on an earlier one's, as catch_up promises); its subjects
            # see only the copies it hands them.
            box = bubblewrap.Sandbox(writable=[folder], env=env, cwd=given, nested=True,
                                  readable=[ROOT / 'src', workspace, given])
            result = box.run(argv, limits, steps=check_begins, stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
        else:  # no sandbox: its limits all the same
            result = bubblewrap.run_to_end(bubblewrap.watched(
                argv, limits, env={**os.environ, **env}, cwd=given, stdout=subprocess.PIPE,
                stderr=subprocess.PIPE, text=True), steps=check_begins)
    except OSError as error:  # e.g. the notebook made its workspace unreadable
        return Verdict({}, f'the grader could not check it: {error}')
    if result.timed_out or result.out_of_cpu:
        return stopped_verdict(result.stdout or '', source,
                               result.out_of_cpu and limits.cpu_step_s, result.step)
    return _read_verdict(result.stdout, result.stderr, result.returncode)


def check_begins(line: str) -> Optional[str]:
    """The graded cell whose check begins at this line of the judge's (``{"begin": ID}``),
    or None: each check's CPU time counts from there (``Limits.cpu_step_s``)."""
    if not line.startswith('{"begin"'):
        return None
    with contextlib.suppress(ValueError):
        begun = json.loads(line)
        if isinstance(begun, dict) and isinstance(begun.get('begin'), str):
            return begun['begin']
    return None


def stopped_verdict(out: str, source: Path, cpu_s: Optional[float] = None,
                    check: Optional[str] = None) -> Verdict:
    """The verdict of a judge stopped at a limit (``cpu_s``: the CPU time of one ``check``,
    else its wall time): the results of the graded cells it had checked (one JSON line each,
    as it went), and a line that says so and names the cells not checked, which score
    nothing."""
    results = {}
    for line in out.splitlines():
        with contextlib.suppress(ValueError):  # not JSON, or another line (Unreadable)
            checked: CellChecked = decoded(CellChecked, json.loads(line))
            results[checked.cell] = checked.result
    unchecked = [grade_id for grade_id, _cell in nbmeta.graded_cells(
        json.loads(source.read_text())) if grade_id not in results]
    limit = (f'the grader\'s limit of {cpu_s:g} CPU-seconds for one check (the check and the '
             'processes that ran your code, together)' if cpu_s else
             f'the grader\'s limit of {JUDGE_TIMEOUT_S} s for checking a notebook')
    one = len(unchecked) == 1
    said = (f'{", ".join(unchecked)} {"was" if one else "were"} not checked and '
            f'score{"s" if one else ""} nothing' if unchecked else 'every graded cell was checked')
    what = f'checking {check}' if check else 'checking it'
    return Verdict(results, f'{what} reached {limit} and was stopped: its points come '
                            f'from the checks that had run; {said}')


def judge_argv(source: Path, submission: Path, settings: Settings) -> list[str]:
    """The judge's command for one notebook, with the grading's seed of the drawn inputs
    (:mod:`ros2nb.checks.drawn`) when it has one: on the command line, which the judge's
    subjects (each with a PID namespace of its own) never see."""
    argv = [sys.executable, '-m', 'ros2nb.judge', 'grade', str(source), str(submission)]
    return argv + ([SEED_OPTION, str(settings.seed)] if settings.seed is not None else [])


def _read_verdict(out: str, err: Optional[str], code: int) -> Verdict:
    """The judge's verdict from the last line it printed (:class:`NotebookChecked`)."""
    try:
        printed: NotebookChecked = decoded(NotebookChecked, json.loads(
            out.strip().splitlines()[-1]))
    except Unreadable as error:  # JSON, but not the answer: the field that does not fit
        return Verdict({}, f'the grader could not check it (judge exit code {code}: its '
                           f'answer did not fit: {str(error)[:200]})')
    except (IndexError, ValueError):  # no line, or not JSON: what the judge said last
        last = (err or '').strip().splitlines()[-1:] or ['no message']
        return Verdict({}, f'the grader could not check it (judge exit code {code}: '
                           f'{last[0][:200]})')
    return Verdict(printed.results, None,
                   tuple(flag[:300] for flag in printed.flags[:MAX_FLAGS]))


class Judges:
    """The judges of a class, working while the learners' next notebooks run.

    A notebook's judge needs only what that notebook left (a snapshot of the workspace
    and the submitted file), so it runs beside the learner's next notebook.
    """

    def __init__(self, jobs: int) -> None:
        self._pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs),
                                                           thread_name_prefix='judge')

    def submit(self, *arguments: Any) -> concurrent.futures.Future[Verdict]:
        return self._pool.submit(judge_notebook, *arguments)

    def close(self) -> None:
        self._pool.shutdown(wait=True)
