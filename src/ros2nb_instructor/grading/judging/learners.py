"""Grading one learner: their notebooks in course order, each run, judged, made ready to score.

Runs on the instructor's host (or a Dask worker, :mod:`.worker`).  What grading makes
of a learner is one value, :class:`Graded`, the same wherever it was made: the course files
it (:func:`file_graded`) and nbgrader scores it.
"""

from __future__ import annotations

import concurrent.futures
import errno
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Mapping, Union

import nbformat
from ros2nb.outcomes import CheckOutcome

from ...paths import ASSIGNMENT
from ..intake.submissions import Learner, readable
from ..sandbox.scratch import HOME_BYTES, OUT_OF_SPACE, Scratch
from . import notebooks as notebooks_of
from .judges import Judges, Verdict
from .runs import run_note, run_notebook
from .settings import Settings

#: How a note introduces the judge's flags (code that reaches into the course or its
#: process, ros2nb.judge.flags): the grade does not depend on them.
FLAGGED = 'code to look at (no points changed; it reaches past what the lessons use):'


@dataclass(frozen=True)
class Graded:
    """What grading made of one learner, whole: what travels back from a Dask worker, and what
    a grading on one machine files alike.  Frozen, and built once: nothing adds to it later.

    :ivar filed: notebook -> the notebook filed for nbgrader to score (nbformat 4 JSON text).
    :ivar notes: notebook -> what happened to it, in sentences joined by ``; ``.
    :ivar results: notebook -> the judge's outcomes (grade id ->
        :class:`~ros2nb.outcomes.CheckOutcome`).
    :ivar flags: notebook -> the judge's flags (:mod:`ros2nb.judge.flags`): its note says
        them, and the learner's feedback page heads with them.
    """

    filed: Mapping[str, str]
    notes: Mapping[str, str]
    results: Mapping[str, Mapping[str, CheckOutcome]]
    flags: Mapping[str, tuple[str, ...]]

    @classmethod
    def of(cls, parts: Iterable['Graded']) -> 'Graded':
        """The notebooks of ``parts`` (each of other notebooks) as one learner's value."""
        parts = list(parts)
        return cls({k: v for p in parts for k, v in p.filed.items()},
                   {k: v for p in parts for k, v in p.notes.items()},
                   {k: v for p in parts for k, v in p.results.items()},
                   {k: v for p in parts for k, v in p.flags.items()})


@dataclass(frozen=True)
class NotRun:
    """A notebook that is not run (unreadable, not attempted, or a grader's failure): it
    scores 0, and ``why`` (its last note) is what its feedback says.

    :ivar said: the notes before ``why``.
    """

    said: tuple[str, ...]
    why: str


@dataclass(frozen=True)
class Judging:
    """A notebook that ran in its sandbox, its judge at work.

    :ivar said: the notes of its run (output cut, a cell that ran too long, ...).
    :ivar executed: the notebook as the sandbox left it.
    :ivar verdict: the judge's :class:`.judges.Verdict`, once it is done.
    """

    said: tuple[str, ...]
    executed: nbformat.NotebookNode
    verdict: concurrent.futures.Future[Verdict]


#: What became of one notebook once its run was over: never a ``str`` or a bare tuple.
Outcome = Union[NotRun, Judging]


def grade_learner(course: Path, scratch_root: Path, learner: Learner, notebooks: list[str],
                  settings: Settings, judges: Judges) -> Graded:
    """Grade a learner's notebooks in course order; return what grading made of them.

    The notebooks run one after the other (each on the workspace the previous ones left);
    each one's judge starts as soon as it has run.  A notebook not attempted (its code cells
    as handed out) is not run: it scores 0 with a note saying so, as if not handed in.
    Whatever goes wrong with one notebook (a malformed file, a dead runner, a full disk) is
    a note for that notebook, which scores 0 unless what was judged stands; the learner's
    other notebooks and the rest of the class are graded all the same.

    :param course: the nbgrader course whose ``release/`` holds the notebooks as handed out;
        nothing is written there (:func:`file_graded` does).
    """
    scratch = Scratch(scratch_root, learner)
    outcomes: dict[str, tuple[nbformat.NotebookNode, Outcome]] = {}
    try:
        for notebook in (n for n in notebooks if n in learner.files):
            release = nbformat.read(course / 'release' / ASSIGNMENT / f'{notebook}.ipynb',
                                    as_version=4)
            said: list[str] = []
            try:
                outcome = _run_and_judge(scratch, learner, notebook, release, settings, judges,
                                         said)
            except Exception as error:  # noqa: BLE001 - one learner's problem, said in a note
                outcome = NotRun(tuple(said), _not_gradable(error))
            outcomes[notebook] = release, outcome
        return Graded.of(judged(notebook, release, outcome)
                         for notebook, (release, outcome) in outcomes.items())
    finally:
        concurrent.futures.wait([o.verdict for _r, o in outcomes.values()
                                 if isinstance(o, Judging)])  # the scratch stays while in use
        scratch.remove()


def _run_and_judge(scratch: Scratch, learner: Learner, notebook: str,
                   release: nbformat.NotebookNode, settings: Settings, judges: Judges,
                   said: list[str]) -> Outcome:
    """Run one notebook and submit it to its judge; its notes so far go into ``said``."""
    submitted, problem = readable(learner.files[notebook])
    if problem or submitted is None:
        return NotRun(tuple(said), f'{problem}; 0 points')
    if notebooks_of.not_attempted(release, submitted):  # nothing to run: 0, said in a note
        return NotRun(tuple(said), notebooks_of.NOT_ATTEMPTED)
    said += [*notebooks_of.drop_large_attachments(submitted),
             *notebooks_of.bound_markdown(release, submitted)]
    prepared = notebooks_of.for_the_run(release, submitted)
    run = run_notebook(scratch, notebook, prepared, settings)
    happened = run_note(run)
    if scratch.home_full():
        happened = '; '.join(filter(None, [OUT_OF_SPACE.format(HOME_BYTES >> 20), happened]))
    if happened:
        said.append(happened)
    snapshot = scratch.snapshot(notebook)
    verdict = judges.submit(scratch, notebook, submitted, settings, snapshot)
    verdict.add_done_callback(lambda _done: scratch.release(snapshot))
    return Judging(tuple(said), run.executed, verdict)


#: The note of a notebook with cells its judge could not decide.
UNDECIDED = ('the grader could not decide {cells} (what it waited for from its own side never '
             'came: the machine was too busy), which score nothing for now: grade this learner '
             'again (LEARNER=) when the machine is calm')


def _not_gradable(error: Exception) -> str:
    """The note of a notebook the grader could not take through (its feedback says it)."""
    if isinstance(error, OSError) and error.errno == errno.ENOSPC:
        why = OUT_OF_SPACE.format(HOME_BYTES >> 20)
    else:
        why = f'the grader could not grade it ({type(error).__name__}: {str(error)[:200]})'
    return f'{why}; 0 points'


def judged(notebook: str, release: nbformat.NotebookNode, outcome: Outcome) -> Graded:
    """One notebook's :class:`Graded` once its judge is done (it waits for it): the notebook
    nbgrader scores (the judge's results as the graded cells' outputs, or a note why there
    are none), its notes, the judge's results and flags."""
    said, results = list(outcome.said), {}
    flags: tuple[str, ...] = ()
    if isinstance(outcome, NotRun):
        said.append(outcome.why)
        scored = notebooks_of.note_notebook(release, f'{outcome.why}.')
    else:
        try:
            verdict: Verdict = outcome.verdict.result()
            if verdict.problem:
                said.append(verdict.problem)
            undecided = sorted(gid for gid, r in verdict.results.items() if r.undecided)
            if undecided:  # not the learner's failure: grade them again once the host is calm
                said.append(UNDECIDED.format(cells=', '.join(undecided)))
            if verdict.flags:  # the instructor's to look at; the points are the verdict alone
                said.append(f'{FLAGGED} ' + ' | '.join(verdict.flags))
                flags = tuple(verdict.flags)
            scored = notebooks_of.for_scoring(release, outcome.executed, verdict.results,
                                              verdict.problem)
            results = verdict.results  # what nbgrader scores: the report counts it
        except Exception as error:  # noqa: BLE001 - one learner's problem, said in a note
            why = _not_gradable(error)
            said.append(why)
            scored = notebooks_of.note_notebook(release, f'{why}.')
    return Graded({notebook: nbformat.writes(scored) + '\n'},
                  {notebook: '; '.join(said)} if said else {},
                  {notebook: results} if results else {}, {notebook: flags} if flags else {})


def file_graded(course: Path, learner: Learner, graded: Graded) -> None:
    """Put what grading made of ``learner`` where nbgrader scores it (``submitted/<id>/``; only
    the course's notebooks the learner handed in), and add its notes, results and flags to
    the learner's, for grades.csv, the feedback pages and the report.  The one way a grading,
    here or on a Dask worker, reaches the course."""
    target = course / 'submitted' / learner.id / ASSIGNMENT
    target.mkdir(parents=True, exist_ok=True)
    for notebook, text in graded.filed.items():
        if notebook in learner.files:
            (target / f'{notebook}.ipynb').write_text(text)
    for key, text in graded.notes.items():
        learner.note(key, text)
    learner.results.update({n: dict(r) for n, r in graded.results.items()})
    learner.flags.update({n: list(f) for n, f in graded.flags.items()})
