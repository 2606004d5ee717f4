"""Grading one learner: their notebooks in course order, each run, judged and filed for nbgrader.

Runs on the instructor's host.
"""

from __future__ import annotations

import concurrent.futures
import shutil
from pathlib import Path

import nbformat

from ..paths import ASSIGNMENT
from . import notebooks as notebooks_of
from .judging import Judges
from .runs import run_note, run_notebook
from .scratch import Scratch
from .settings import Settings
from .submissions import Learner, readable


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
                nbformat.write(notebooks_of.note_notebook(release, f'{problem}; 0 points.'),
                               target / f'{notebook}.ipynb')
                continue
            submitted = nbformat.read(learner.files[notebook], as_version=4)
            prepared = notebooks_of.for_the_run(release, submitted)
            executed, status, stopped = run_notebook(scratch, notebook, prepared, settings)
            happened = run_note(status, stopped)
            if happened:
                learner.note(notebook, happened)
            verdict = judges.submit(scratch, notebook, learner.files[notebook], settings,
                                    scratch.snapshot(notebook))
            judged.append((notebook, release, executed, verdict))
        for notebook, release, executed, verdict in judged:
            results, problem = verdict.result()
            if problem:
                learner.note(notebook, problem)
            nbformat.write(notebooks_of.for_scoring(release, executed, results, problem),
                           target / f'{notebook}.ipynb')
    finally:
        for _notebook, _release, _executed, verdict in judged:
            concurrent.futures.wait([verdict])  # nothing of the scratch is removed in use
        shutil.rmtree(scratch.top, ignore_errors=True)
