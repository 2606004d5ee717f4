"""Learners of our own, each one notebook, graded through the judge's grading path.

Three corpora (``corpus_honest.py``, ``corpus_wrong.py``, ``corpus_attacks.py``) describe
learners as the course's solution notebook with some answer cells written another way.
:func:`grade_learner` grades one the way ``make grade`` does after the learner's notebook
ran: the workspace holds what the notebook's ``%%part`` cells write on top of what
``catch_up`` writes while grading (no reference node: the grader hides them), and the judge's
own command (``python -m ros2nb.judge grade``, in a process and session of its own:
``judge_apart.py``) runs every graded cell of the course's notebook, hidden tests included,
on the submission.  Only the learner's kernel and the sandboxes are left out: a notebook's
answer cells reach the judge as its files and its answer cells, which is all the judge reads.

``python tests/corpora.py [--seed N] [--cpu-share CPUS] [--json] [NAME ...]`` prints
``name<TAB>score<TAB>full marks less the parts it must lose<TAB>failed grade ids``, one line
per learner (with ``--json`` every part's result); with an older
checkout's ``src`` on ``PYTHONPATH`` it scores the same learners with that checkout's judge
(the closing notes' "before" column).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator, Optional, Union

from ros2nb.outcomes import CellChecked, CheckOutcome, NotebookChecked
from ros2nb.temporary import temporary_folder
from ros2nb.typed_json import decoded

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / 'tests'))  # judging.py, the corpora
SOLUTIONS = ROOT / 'solutions'
NOTEBOOKS = {p.stem[:2]: p for p in SOLUTIONS.glob('*.ipynb')}
#: Seconds one learner's judge may take; then, as at its CPU limit, the cells it had not
#: checked fail with the line that says so.
JUDGE_TIMEOUT_S = 270
#: Seconds a test of the corpora takes beside its judges (writing each learner's workspace,
#: comparing the results).
BESIDE_JUDGES_S = 30
#: Simulated seconds of notebook 03's hidden hour, and of the hour notebook 10 records, for a
#: learner graded for other parts: each hour is most of its grading's CPU time, and what it
#: checks (every reading's step and range; every reading and status in the bag) holds from
#: the first minutes.  A learner who must lose that hour gets the whole of it, and so does
#: the sample class's complete learner (tests/test_grading.py), through the grader.
SHORT_HOUR_S = 300
#: Each notebook's hour: the part that judges it, and the grading context's line that sets
#: the hour the learner's function records (notebook 10's ``HOUR_S``).
HOURS = {'03': ('sensor-hour', None), '10': ('record-hour', 'HOUR_S = 3600\n')}


def time_limit_s(gradings: int) -> int:
    """pytest-timeout's limit for a test that grades ``gradings`` learners one after
    another: each judge is already bounded (:data:`JUDGE_TIMEOUT_S`), so the test's own
    limit only catches a hang outside them and must never cut a judge short."""
    return gradings * (JUDGE_TIMEOUT_S + BESIDE_JUDGES_S)


#: A cell's new text, or (old, new) replacements in it.
Change = Union[str, list[tuple[str, str]]]


@dataclass
class Learner:
    """One learner's one notebook.

    :ivar notebook: the notebook's number, e.g. ``'03'``.
    :ivar cells: answer cell (its grade id without ``NN-`` and ``-answer``) -> new text
        (its ``%%part`` line is kept) or a list of ``(old, new)`` replacements.
    :ivar loses: grade ids (without ``NN-``) of the parts this learner must fail.
    :ivar twin: for an attack, the learner it must score the same as (unless
        ``same_on_the_wire``: then the score it deserves).
    """

    name: str
    notebook: str
    cells: dict[str, Change]
    loses: tuple[str, ...] = ()
    twin: Optional[str] = None
    #: code that reaches into the course or its process: the judge flags it for the instructor
    flagged: bool = False
    #: an attack the wire cannot tell from honest code (its score may exceed its twin's;
    #: only the flag tells the instructor)
    same_on_the_wire: bool = False
    #: code the subject's audit hook sees reaching in as it runs (a flag at run time)
    seen: bool = False
    #: cells the learner added (not answer cells), each after the answer cell named: run in
    #: the kernel in notebook order, as the grader's run of the notebook runs them
    added: tuple[tuple[str, str], ...] = ()
    why: str = ''
    extra: dict = field(default_factory=dict)


def _source(cell: dict) -> str:
    text = cell['source']
    return ''.join(text) if isinstance(text, list) else text


def _grade_id(cell: dict) -> str:
    return cell.get('metadata', {}).get('nbgrader', {}).get('grade_id', '')


def submission(learner: Learner) -> dict:
    """The learner's notebook: the solution with ``learner.cells`` written in.

    :raises KeyError: naming an answer cell or a replacement that is not there.
    """
    number = learner.notebook
    nb = json.loads(NOTEBOOKS[number].read_text())
    by_key = {_grade_id(c)[3:-len('-answer')]: c for c in nb['cells']
              if _grade_id(c).endswith('-answer')}
    for key, change in learner.cells.items():
        cell = by_key.get(key)
        if cell is None:
            raise KeyError(f'{learner.name}: no answer cell {key} in {number} '
                           f'(there are {sorted(by_key)})')
        text = _source(cell)
        if isinstance(change, str):
            first = text.splitlines()[0]
            new = change.strip('\n') + '\n'
            text = (first + '\n' + new) if first.startswith('%%part') and \
                not new.startswith('%%') else new
        else:
            for old, replacement in change:
                if old not in text:
                    raise KeyError(f'{learner.name}: {old!r} is not in {key}')
                text = text.replace(old, replacement)
        cell['source'] = text
        cell['outputs'] = []
    for key, text in learner.added:
        at = nb['cells'].index(by_key[key]) + 1
        nb['cells'].insert(at, {'cell_type': 'code', 'execution_count': None, 'id': f'added-{at}',
                                'metadata': {}, 'outputs': [], 'source': text})
    return nb


def points(number: str) -> dict[str, float]:
    """grade id (without ``NN-``) -> points, of the course's notebook ``number``."""
    nb = json.loads(NOTEBOOKS[number].read_text())
    return {_grade_id(c)[3:]: c['metadata']['nbgrader']['points'] for c in nb['cells']
            if c.get('metadata', {}).get('nbgrader', {}).get('grade')}


def expected_score(learner: Learner) -> float:
    """Full marks less the points of the parts the learner must lose."""
    return sum(p for gid, p in points(learner.notebook).items() if gid not in learner.loses)


def write_parts(nb: dict) -> None:
    """What the notebook's ``%%part`` cells write, in notebook order (as its kernel did), and
    what the cells a learner added (no nbgrader metadata, no ``id`` of the course's) do."""
    import ros2nb
    from ros2nb import course
    from ros2nb.terminal.files import write_part
    names: dict = {'ros2nb': ros2nb}
    for cell in nb['cells']:
        if cell['cell_type'] == 'code':
            for name, constant in re.findall(r'^(\w+) = ros2nb\.course\.(\w+)', _source(cell),
                                             re.M):
                names[name] = getattr(course, constant)
    for cell in nb['cells']:
        text = _source(cell)
        if cell['cell_type'] != 'code':
            continue
        with contextlib.redirect_stdout(io.StringIO()):
            if str(cell.get('id', '')).startswith('added-'):
                exec(compile(text, cell['id'], 'exec'), dict(names))  # noqa: S102 - the corpus'
            elif text.startswith('%%part'):
                first, _, body = text.partition('\n')
                words = shlex.split(first)[1:]
                write_part(names[words[0].strip('{}')], int(words[1]), body,
                           overwrite='--overwrite' in words)


@contextlib.contextmanager
def _grading_env(root: Path) -> Iterator[Path]:
    """This process as a judge on ``root/ws`` (:func:`judging.judging_env`), the course's
    reference nodes hidden from ``catch_up`` (as in the grader's sandbox)."""
    from ros2nb import course
    from judging import judging_env
    reference = course.reference_source
    course.reference_source = lambda name: None
    try:
        with judging_env(root) as ws:
            yield ws
    finally:
        course.reference_source = reference


@contextlib.contextmanager
def learner_workspace(learner: Learner, root: Path) -> Iterator[tuple[Path, dict]]:
    """The learner's workspace under ``root`` as their notebook left it, and the notebook:
    what ``catch_up`` writes while grading, then what its ``%%part`` cells write."""
    from ros2nb import course
    from ros2nb.terminal.workspace import create_workspace
    nb = submission(learner)
    number = int(learner.notebook)
    with _grading_env(root) as ws, contextlib.redirect_stdout(io.StringIO()):
        if number in course.STEPS:
            course.catch_up(number)
        else:
            create_workspace()
        write_parts(nb)
        yield ws, nb


def grade_learner(learner: Learner, root: Path, *, knows_nothing: bool = False,
                  seed: Optional[int] = None, cpu_share: Optional[float] = None
                  ) -> dict[str, CheckOutcome]:
    """Grade one learner's notebook in a fresh workspace under ``root``, with the judge's
    own command in a process and session of its own (``judge_apart.py``), as the grader
    runs it (with the grading's ``seed`` of the drawn inputs, when given).

    :param knows_nothing: the judge's reader of the learner's text finds nothing.
    :param cpu_share: CPUs the judge and its subjects may use together (a CPU quota; None:
        what the machine gives), as the grader's ``--cpu-share``.
    :return: ``{grade id without NN-: outcome}``.
    :raises AssertionError: when the judge printed no result (its output in the message).
    """
    return judged(learner, root, knows_nothing=knows_nothing, seed=seed, cpu_share=cpu_share)[0]


def judged(learner: Learner, root: Path, *, knows_nothing: bool = False,
           seed: Optional[int] = None, cpu_share: Optional[float] = None
           ) -> tuple[dict[str, CheckOutcome], list[str], dict[str, float]]:
    """:func:`grade_learner`'s results, the judge's flags (its text scan's and what the
    subjects' audit hooks saw, ``at run time``), and what each check cost (CPU seconds, judge
    and subjects, by grade id without NN-; none for a judge stopped at a limit)."""
    from ros2nb import domains
    from ros2nb.course import GRADING_ENV
    from ros2nb.processes import kill_process_group
    from ros2nb.terminal.workspace import WORKSPACE_ENV
    with learner_workspace(learner, root) as (ws, nb):
        pass  # written: the judge reads it from its own process
    given = root / 'given'
    given.mkdir()
    short = learner.notebook in HOURS and not _hour_judged(learner)
    source = NOTEBOOKS[learner.notebook].read_text()
    hour_line = HOURS.get(learner.notebook, ('', None))[1]
    if short and hour_line:  # the context cell's hour, as the judge runs it (JSON-escaped)
        assert json.dumps(hour_line)[1:-1] in source, hour_line
        source = source.replace(json.dumps(hour_line)[1:-1],
                                json.dumps(f'HOUR_S = {SHORT_HOUR_S}\n')[1:-1])
    (given / 'source.ipynb').write_text(source)
    (given / 'submission.ipynb').write_text(json.dumps(nb))
    env = {k: v for k, v in os.environ.items() if k != domains.DOMAIN_ENV}
    env.update({WORKSPACE_ENV: str(ws), GRADING_ENV: '1'})
    command = [sys.executable, str(ROOT / 'tests' / 'judge_apart.py'),
               *(['--knows-nothing'] if knows_nothing else []),
               *(['--hour-s', str(SHORT_HOUR_S)] if short else []),
               str(given / 'source.ipynb'), str(given / 'submission.ipynb'),
               *(['--seed', str(seed)] if seed is not None else [])]
    # Bounded as the grader bounds a judge: each check's CPU time and its subjects' together.
    from ros2nb_instructor.grading.sandbox import bubblewrap
    from ros2nb_instructor.grading.judging.judges import check_begins, stopped_verdict
    from ros2nb_instructor.grading.judging.settings import JUDGE_CPU_S
    cpu_s = JUDGE_CPU_S[learner.notebook]
    judge = bubblewrap.watched(command, bubblewrap.Limits(wall_s=JUDGE_TIMEOUT_S, cpu_step_s=cpu_s,
                                                    cpu_share=cpu_share),
                            env=env, cwd=root, text=True, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, start_new_session=True)
    try:
        ended = bubblewrap.run_to_end(judge, steps=check_begins)
    finally:
        kill_process_group(judge.process)  # what it left (nothing, once it answered)
    out, err = ended.stdout, ended.stderr
    if ended.out_of_cpu or ended.timed_out:  # what it had not checked scores nothing, as
        verdict = stopped_verdict(out, given / 'source.ipynb',  # in the grader
                                  ended.out_of_cpu and cpu_s, ended.step)
        unchecked = CheckOutcome(False, (), 'GradingError', verdict.problem)
        return ({gid: verdict.results.get(f'{learner.notebook}-{gid}', unchecked)
                 for gid in points(learner.notebook)}, [], {})
    lines = out.strip().splitlines()
    assert lines and lines[-1].startswith('{'), f'the judge printed no result: {out}{err}'
    verdict = decoded(NotebookChecked, json.loads(lines[-1]))
    decided = [decoded(CellChecked, json.loads(line)) for line in lines[:-1]
               if line.startswith('{"cell"')]  # each as it was decided, with its cost
    return ({gid[3:]: result for gid, result in verdict.results.items()}, verdict.flags,
            {checked.cell[3:]: checked.cpu_s for checked in decided})


def _hour_judged(learner: Learner) -> bool:
    """Whether the learner (or, for an attack, its twin) must lose its notebook's hour
    (:data:`HOURS`): then the whole hour decides it."""
    twin = every_learner().get(learner.twin) if learner.twin else None
    return HOURS[learner.notebook][0] in (*learner.loses, *(twin.loses if twin else ()))


def judged_in_sandbox(learner: Learner, root: Path, *, seed: Optional[int] = None
                      ) -> tuple[dict[str, CheckOutcome], list[str]]:
    """:func:`judged`, the way the grader judges: its judge and each subject in sandboxes of
    their own (``grading.judging.judge_notebook``), where the course's answers are not on a
    subject's disk and no subject reads what another wrote.  Needs the grader's sandbox."""
    import nbformat
    from ros2nb import course
    from ros2nb.terminal import workspace as ws_module
    from ros2nb.terminal.workspace import WORKSPACE_ENV, create_workspace
    from ros2nb_instructor.grading.judging.judges import judge_notebook
    from ros2nb_instructor.grading.sandbox.scratch import Scratch
    from ros2nb_instructor.grading.judging.settings import Settings
    from ros2nb_instructor.grading.intake.submissions import Learner as Handed
    scratch, nb, notebook = Scratch(root, Handed('learner', 'learner')), \
        submission(learner), NOTEBOOKS[learner.notebook].stem
    saved, reference = os.environ.get(WORKSPACE_ENV), course.reference_source
    try:
        os.environ[WORKSPACE_ENV], ws_module._current = str(scratch.workspace), None
        course.reference_source = lambda name: None  # hidden while grading
        with contextlib.redirect_stdout(io.StringIO()):
            if int(learner.notebook) in course.STEPS:
                course.catch_up(int(learner.notebook))
            else:
                create_workspace()
            write_parts(nb)
        results, problem, flags = judge_notebook(
            scratch, notebook, nbformat.from_dict(nb), Settings(120, 600, True, seed=seed),
            scratch.snapshot(notebook))
    finally:
        course.reference_source = reference
        if saved is None:
            os.environ.pop(WORKSPACE_ENV, None)
        else:
            os.environ[WORKSPACE_ENV] = saved
        ws_module._current = None
        scratch.remove()
    unchecked = CheckOutcome(False, (), 'GradingError', problem)
    return ({gid: results.get(f'{learner.notebook}-{gid}', unchecked)
             for gid in points(learner.notebook)}, list(flags))


def flags_of(learner: Learner, root: Path) -> list[str]:
    """What the judge's text scan flags for the instructor in the learner's notebook (its
    answer cells and the cells it added) and files."""
    from ros2nb.judge.flags import notebook_flags
    with learner_workspace(learner, root) as (ws, nb):
        return notebook_flags(nb, ws, json.loads(NOTEBOOKS[learner.notebook].read_text()))


def score(learner: Learner, results: dict[str, CheckOutcome]) -> float:
    """The points ``results`` earn in the learner's notebook."""
    worth = points(learner.notebook)
    return sum(worth[gid] for gid, result in results.items() if result.passed)


def every_learner() -> dict[str, Learner]:
    """All three corpora, by name."""
    from corpus_attacks import ATTACKS
    from corpus_honest import HONEST
    from corpus_reaching import REACHING, SEVENTH_TWINS
    from corpus_wrong import WRONG
    found = {}
    for learner in [*HONEST, *WRONG, *ATTACKS, *REACHING, *SEVENTH_TWINS]:
        assert learner.name not in found, learner.name
        found[learner.name] = learner
    return found


def main(argv: list[str]) -> int:
    """Print each named learner's score (all of them without names).  Options first:
    ``--seed N``, the grading's seed of the drawn inputs (else the judge draws one);
    ``--cpu-share CPUS``, the judge's CPU quota (:func:`grade_learner`); ``--json``, one
    JSON line per learner instead: its name and every part's result
    (``benchmarks/load_harness.py`` compares them)."""
    seed, share, as_json, names = None, None, False, list(argv)
    while names[:1] in (['--seed'], ['--cpu-share'], ['--json']):
        option = names.pop(0)
        if option == '--json':
            as_json = True
        elif option == '--seed':
            seed = int(names.pop(0))
        else:
            share = float(names.pop(0))
    learners = every_learner()
    for name in names or learners:
        learner = learners[name]
        with temporary_folder('corpus') as root:
            try:
                results, _flags, cpu_s = judged(learner, Path(root), seed=seed,
                                                cpu_share=share)
                failed = sorted(gid for gid, r in results.items() if not r.passed)
                shown = f'{score(learner, results):g}'
            except Exception as error:  # an older judge may not grade it at all
                results, cpu_s = {}, {}
                failed, shown = [f'{type(error).__name__}: {error}'[:120]], 'error'
        if as_json:
            print(json.dumps({'name': name, 'results': {
                gid: {'passed': r.passed, 'type': r.type, 'message': r.message}
                for gid, r in results.items()}, 'cpu_s': {
                gid: cpu_s.get(gid) for gid in results},
                'error': None if results else failed[0]}), flush=True)
        else:
            print(f'{name}\t{shown}\t{expected_score(learner):g}\t{",".join(failed)}',
                  flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
