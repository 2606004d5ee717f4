"""Grading one learner: their notebooks in course order, each run, judged and filed for nbgrader.

Runs on the instructor's host.
"""

from __future__ import annotations

import concurrent.futures
import errno
from typing import Any
from pathlib import Path

import nbformat

from ..paths import ASSIGNMENT
from . import notebooks as notebooks_of
from .judging import Judges
from .runs import run_note, run_notebook
from .scratch import HOME_BYTES, OUT_OF_SPACE, Scratch
from .settings import Settings
from .submissions import Learner, readable

#: How a note introduces the judge's flags (code that reaches into the course or its
#: process, ros2nb.judge.flags): the grade does not depend on them.
FLAGGED = 'code to look at (no points changed; it reaches past what the lessons use):'


def grade_learner(course: Path, scratch_root: Path, learner: Learner, notebooks: list[str],
                  settings: Settings, judges: Judges) -> None:
    """Grade a learner's notebooks in course order; file them in the nbgrader course.

    The notebooks run one after the other (each on the workspace the previous ones left);
    each one's judge starts as soon as it has run.  A notebook not attempted (its code cells
    as handed out) is not run: it scores 0 with a note saying so, as if not handed in.
    Whatever goes wrong with one notebook (a malformed file, a dead runner, a full disk) is
    a note for that notebook, which scores 0 unless what was judged stands; the learner's
    other notebooks and the rest of the class are graded all the same.
    """
    scratch = Scratch(scratch_root, learner)
    target = course / 'submitted' / learner.id / ASSIGNMENT
    target.mkdir(parents=True, exist_ok=True)
    judged = []
    try:
        for notebook in (n for n in notebooks if n in learner.files):
            release = nbformat.read(course / 'release' / ASSIGNMENT / f'{notebook}.ipynb',
                                    as_version=4)
            try:
                verdict = _run_and_judge(scratch, learner, notebook, release, settings, judges)
            except Exception as error:  # noqa: BLE001 - one learner's problem, said in a note
                verdict = _not_gradable(learner, notebook, error)
            if isinstance(verdict, tuple):
                judged.append((notebook, release, *verdict))
            else:
                nbformat.write(notebooks_of.note_notebook(release, verdict),
                               target / f'{notebook}.ipynb')
        for notebook, release, executed, verdict in judged:
            _file(target, learner, notebook, release, executed, verdict)
    finally:
        for _notebook, _release, _executed, verdict in judged:
            concurrent.futures.wait([verdict])  # nothing of the scratch is removed in use
        scratch.remove()


def _run_and_judge(scratch: Scratch, learner: Learner, notebook: str,
                   release: nbformat.NotebookNode, settings: Settings, judges: Judges
                   ) -> Any:
    """Run one notebook and submit it to its judge: ``(executed, future)``, or why not (str)."""
    submitted, problem = readable(learner.files[notebook])
    if problem:
        learner.note(notebook, f'{problem}; 0 points')
        return f'{problem}; 0 points.'
    assert submitted is not None  # readable() gives the notebook or the problem
    if notebooks_of.not_attempted(release, submitted):  # nothing to run: 0, said in a note
        learner.note(notebook, notebooks_of.NOT_ATTEMPTED)
        return f'{notebooks_of.NOT_ATTEMPTED}.'
    for dropped in [*notebooks_of.drop_large_attachments(submitted),
                    *notebooks_of.bound_markdown(release, submitted)]:
        learner.note(notebook, dropped)
    prepared = notebooks_of.for_the_run(release, submitted)
    executed, status, stopped = run_notebook(scratch, notebook, prepared, settings)
    happened = run_note(status, stopped)
    if scratch.home_full():
        happened = '; '.join(filter(None, [OUT_OF_SPACE.format(HOME_BYTES >> 20), happened]))
    if happened:
        learner.note(notebook, happened)
    snapshot = scratch.snapshot(notebook)
    verdict = judges.submit(scratch, notebook, submitted, settings, snapshot)
    verdict.add_done_callback(lambda _done: scratch.release(snapshot))
    return executed, verdict


def _not_gradable(learner: Learner, notebook: str, error: Exception) -> str:
    """The note for a notebook the grader could not take through (its text for the feedback)."""
    if isinstance(error, OSError) and error.errno == errno.ENOSPC:
        why = OUT_OF_SPACE.format(HOME_BYTES >> 20)
    else:
        why = f'the grader could not grade it ({type(error).__name__}: {str(error)[:200]})'
    learner.note(notebook, f'{why}; 0 points')
    return f'{why}; 0 points.'


def _file(target: Path, learner: Learner, notebook: str, release: nbformat.NotebookNode,
          executed: nbformat.NotebookNode, verdict: concurrent.futures.Future) -> None:
    """Put the judged notebook where nbgrader scores it (or a note why it could not be)."""
    try:
        results, problem, flags = verdict.result()
        if problem:
            learner.note(notebook, problem)
        if flags:  # the instructor's to look at; the points are the judge's verdict alone
            learner.note(notebook, f'{FLAGGED} ' + ' | '.join(flags))
            learner.flags[notebook] = list(flags)  # and the learner's feedback page
        scored = notebooks_of.for_scoring(release, executed, results, problem)
        learner.results[notebook] = results  # what nbgrader scores: the report counts it
    except Exception as error:  # noqa: BLE001 - one learner's problem, said in a note
        scored = notebooks_of.note_notebook(release, _not_gradable(learner, notebook, error))
    nbformat.write(scored, target / f'{notebook}.ipynb')
