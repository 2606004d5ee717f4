"""Each mutant of a notebook's answers, run as the learner meets it and as the grader does.

:class:`NotebookRun` holds, for one notebook, one real kernel and two judge sessions (this
process is the judge: ``judging.py``): the learner's lab (the kernel's workspace, the checks
they run) and the grading (a workspace of its own, written from the whole notebook with the
mistake in it, as the grader's sandbox leaves it, the course's reference nodes hidden).  It
goes through the notebook in order, as a learner does: at each answer cell, each mutant of
it runs in the kernel (its ``%%part`` or ``def``), then

- **lab**: its check as the learner runs it: a check of the kernel's objects (00-02, 09, 10)
  in the kernel itself; a check of the learner's files in the judge, with the lab session,
  on the workspace as the learner left it at that cell (the later parts not written yet);
- **grading**: the judge's path for the same graded cell (:func:`ros2nb.judge.graded_cells.grade`),
  with the grading session;

and then the answer's own cell runs again, so that the next answer starts where a learner
who got this one right stands.  What each shows the learner is kept as :class:`Shown`.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import os
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any, Iterator, Optional

from ros2nb import checks, course
from ros2nb.judge.graded_cells import grade
from ros2nb.judge.session import Session
from ros2nb.judge.subjects import SubjectProcess
from ros2nb.subject_replies import Called, Encoded
from ros2nb.temporary import temporary_folder
from ros2nb.judge_interface import captured
from ros2nb.outcomes import CheckOutcome

from judging import judging_env
from kernels import Cell, CellHung, Kernel
from mutation_cells import (Answer, MARKERS, answers, bound_names, notebook, own_names,
                            setup_cells)
from mutation_mistakes import mutants
from mutation_operators import Mutant
from mutation_verdicts import NUMBER, stated_numbers

#: The seed of every session's drawn inputs: the same inputs every run.
SEED = 65
#: Seconds a cell of the kernel may take (of its work or idle waiting, never of the wall
#: clock): 10's record_hour runs an hour of simulated time, 05 builds the package.
CELL_S = 900
#: The notebook whose catch_up makes what a notebook's own cells leave in the workspace, where
#: it is not the notebook's own (00, 01 and 09 need only the workspace; 02 makes the package).
MADE_BY = {0: 1, 1: 1, 2: 3, 9: 1}
#: Stops what the learner's cells left running, between two mutants (their nodes would
#: otherwise answer the next mutant's check).
RESET = '''
try:
    ros2nb.stop()
except Exception:
    pass
'''


@dataclass
class Shown:
    """What one check shows the learner: the lines printed and the error's lines."""

    lines: list[str] = field(default_factory=list)
    error: list[str] = field(default_factory=list)
    ename: str = ''
    hung: bool = False
    #: Numbers the learner's code produced while the check ran, as the judge heard them (the
    #: values of its messages, the numbers in its log lines, how many of each, what its
    #: functions returned), of those a shown line states
    #: (:func:`mutation_verdicts.stated_numbers`).
    produced: list[float] = field(default_factory=list)
    #: Seconds of the wall clock the check took (the learner's wait for its answer).
    seconds: float = 0.0

    @property
    def failed(self) -> bool:
        return bool(self.error) or self.hung

    @classmethod
    def of_cell(cls, cell: Cell) -> 'Shown':
        ename, traceback = cell.error or ('', [])
        return cls(lines=(cell.stdout + cell.stderr).splitlines(),
                   error=[part for line in traceback for part in line.split('\n')],
                   ename=ename)

    @classmethod
    def of_outcome(cls, outcome: CheckOutcome) -> 'Shown':
        """A judge's outcome as the kernel (``show_result``) and the feedback show it."""
        if outcome.passed:
            return cls(lines=list(outcome.lines))
        error = [*outcome.traceback, f'{outcome.type}: {outcome.message}']
        return cls(lines=list(outcome.lines), ename=outcome.type or '',
                   error=[part for line in error for part in line.split('\n')])


@dataclass
class Outcome:
    """One mutant, run: what the learner saw in the lab and in their feedback."""

    ident: str
    notebook: str
    answer: str
    operator: str
    what: str
    source: str
    changed: list[int]
    affected: list[str]
    written: list[list[int]]
    cell: Shown
    lab: Shown
    grading: Shown
    file_text: str = ''
    seconds: float = 0.0


#: What the learner's functions returned to the judge (each :class:`Call`'s reply, in
#: order) while :func:`_returns_kept` keeps them.
RETURNED: list[Encoded] = []


@contextlib.contextmanager
def _returns_kept() -> Iterator[None]:
    """Keep in :data:`RETURNED` what every subject's learner function returns (a check of
    10's ``read_temperatures`` quotes the times it returned: numbers the learner's code
    produced that no topic or log carried)."""
    reply_to = SubjectProcess.reply_to

    def kept(command: Any, data: Any) -> Any:
        reply = reply_to(command, data)
        if isinstance(reply, Called):
            RETURNED.extend(o.result for o in reply.outputs if o.result is not None)
        return reply

    SubjectProcess.reply_to = staticmethod(kept)
    try:
        yield
    finally:
        SubjectProcess.reply_to = staticmethod(reply_to)
        RETURNED.clear()


def _numbers_of(value: Any) -> Iterator[float]:
    """The numbers in a returned value (:class:`Encoded`): itself, its items', its text's."""
    if isinstance(value, Encoded):
        yield from _numbers_of(value.value)
    elif isinstance(value, list):
        for item in value:
            yield from _numbers_of(item)
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        yield float(value)
    elif isinstance(value, str):
        yield from (float(n) for n in NUMBER.findall(value))


class Produced:
    """What the learner's code produced while one check ran, as the judge heard it: every
    message's value (and the step from the one before) and every number of every log line
    from the mark on, how many messages and lines came (a count a line may state), and the
    numbers its functions returned to the judge (:data:`RETURNED`)."""

    def __init__(self, session: Session) -> None:
        self.observer = session.observer
        self.marks = {topic: len(heard) for topic, heard in self.observer.heard.items()}
        self.log_mark = len(self.observer.logs)
        self.returned_mark = len(RETURNED)

    def numbers(self) -> set[float]:
        found: set[float] = set()
        counts = [len(self.observer.logs) - self.log_mark]
        for topic, heard in list(self.observer.heard.items()):
            new = heard[self.marks.get(topic, 0):]
            counts.append(len(new))
            values = [float(h.value) for h in new
                      if isinstance(h.value, (int, float)) and not isinstance(h.value, bool)]
            found.update(values)
            found.update(b - a for a, b in zip(values, values[1:]))  # a step of the walk
        for line in self.observer.logs[self.log_mark:]:
            found.update(float(n) for n in NUMBER.findall(line.text))
        found.update(float(n) for n in range(max(counts) + 1))  # a count, or which one
        for value in RETURNED[self.returned_mark:]:
            found.update(_numbers_of(value))
        return found


def _without_markers(text: str) -> str:
    return '\n'.join(line for line in text.split('\n') if line.strip() not in MARKERS)


class NotebookRun:
    """One notebook's kernel and judge sessions, and its mutants run through them."""

    def __init__(self, number: str, root: Path) -> None:
        self.number, self.root = number, root
        self.answers = answers(number)
        self.lab_ws = root / 'lab' / 'ws'
        self.grading_root = root / 'grading'
        self.stack = contextlib.ExitStack()
        with judging_env(root / 'lab'):
            with contextlib.redirect_stdout(io.StringIO()):
                course.catch_up(int(number)) if int(number) in course.STEPS else None
            self.session = Session(self.lab_ws, SEED)
        self.kernel = Kernel(str(self.lab_ws))

    @contextlib.contextmanager
    def _grading(self) -> Iterator[Path]:
        """This process as the grader's judge on the grading workspace: the session's
        subjects ended before and after, the course's reference nodes hidden."""
        saved = course.reference_source
        os.environ[course.GRADING_ENV] = '1'
        course.reference_source = lambda name: None
        self.session.drop_all()
        try:
            with judging_env(self.grading_root) as ws:
                self.session.workspace = ws
                yield ws
        finally:
            self.session.drop_all()
            self.session.workspace = self.lab_ws
            course.reference_source = saved
            os.environ.pop(course.GRADING_ENV, None)

    def close(self) -> None:
        for closing in (self.kernel.close, self.session.close):
            with contextlib.suppress(Exception):
                closing()

    # ------------------------------------------------------------------ the kernel
    def _run(self, source: str) -> Shown:
        try:
            return Shown.of_cell(self.kernel.run(source, CELL_S))
        except CellHung:
            return Shown(hung=True)

    def _answer_cell(self, answer: Answer, source: str) -> Shown:
        return self._run(source)

    # ------------------------------------------------------------------ the two paths
    def _lab_check(self, answer: Answer) -> tuple[Shown, set[float]]:
        began = time.monotonic()
        if not answer.judged:
            shown = self._run(answer.check_source)
            shown.seconds = round(time.monotonic() - began, 1)
            return shown, set()
        self.session.drop_all()
        produced = Produced(self.session)
        with judging_env(self.root / 'lab'):
            outcome = captured(lambda: checks.run_check(answer.check_name, self.session))
        self.session.drop_all()
        shown = Shown.of_outcome(outcome)
        shown.seconds = round(time.monotonic() - began, 1)
        return shown, produced.numbers()

    def _submission(self, mutant: Optional[Mutant]) -> dict:
        nb = copy.deepcopy(notebook(self.number))
        if mutant is not None:
            nb['cells'][mutant.answer.index]['source'] = mutant.source
            for index, text in mutant.given.items():
                nb['cells'][index]['source'] = text
        for cell in nb['cells']:
            text = cell['source'] if isinstance(cell['source'], str) else ''.join(cell['source'])
            cell['source'] = _without_markers(text)
        return nb

    def _grading_check(self, answer: Answer, mutant: Optional[Mutant]
                       ) -> tuple[Shown, set[float]]:
        from corpora import write_parts
        nb = self._submission(mutant)
        source = notebook(self.number)
        graded = {'cells': [c for c in source['cells']
                            if 'grading-context' in c.get('metadata', {}).get('tags', [])]
                  + [source['cells'][answer.check_index]], 'metadata': source['metadata']}
        began = time.monotonic()
        with self._grading() as ws, contextlib.redirect_stdout(io.StringIO()):
            if not ws.exists():  # what the notebook's own cells made, then its parts
                course.catch_up(MADE_BY.get(int(self.number), int(self.number)))
            write_parts(nb)
            produced = Produced(self.session)
            result = grade(graded, nb, self.session)[answer.check_id]
        shown = Shown.of_outcome(result)
        shown.seconds = round(time.monotonic() - began, 1)
        return shown, produced.numbers()

    # ------------------------------------------------------------------ going through it
    def run(self, chosen: Optional[set[str]] = None, baseline: bool = True
            ) -> Iterator[Outcome]:
        """Go through the notebook: set-up cells, then at each answer its mutants (those
        named in ``chosen``, or all), then the answer itself; yield each mutant's outcome.

        With ``baseline``, the unchanged answer runs first at each cell with mutants, as a
        mutant of its own (operator ``none``): it must pass both ways.
        """
        setup = setup_cells(self.number)
        by_index = {a.index: a for a in self.answers}
        last = max((a.index for a in self.answers if chosen is None or any(
            m.ident in chosen for m in mutants(a))), default=-1)
        for index in sorted(i for i in {*setup, *by_index} if i <= last):
            if index in setup:
                self._run(setup[index])
                continue
            answer = by_index[index]
            made = [m for m in mutants(answer) if chosen is None or m.ident in chosen]
            for mutant in [*([None] if baseline else []), *made] if chosen is None or made \
                    else []:
                yield self._one(answer, mutant)
            self._run(self._cell(index))  # the answer as written, for the cells after it

    def _cell(self, index: int) -> str:
        """The solution's cell ``index`` as a learner's notebook holds it (no markers)."""
        return _without_markers(''.join(notebook(self.number)['cells'][index]['source']))

    def _one(self, answer: Answer, mutant: Optional[Mutant]) -> Outcome:
        began = time.monotonic()
        given = mutant.given if mutant else {}
        for index, text in given.items():
            self._run(text)
        source = mutant.source if mutant else answer.source
        forgotten = sorted(own_names(answer))  # as when the learner first runs the cell
        if forgotten:
            self._run(f'for _name in {forgotten!r}:\n    globals().pop(_name, None)')
        plan = mutant.plan if mutant else ''
        if plan == 'again':  # a mistake first, its check failed, then the answer
            self._answer_cell(answer, mutant.first)
            self._lab_check(answer)
        restore = self._skip(answer, plan)
        cell = self._answer_cell(answer, source)
        if plan == 'twice':
            cell = self._answer_cell(answer, source)
        lab, lab_numbers = self._lab_check(answer)
        file_text = self._file_text(answer)
        for index in [*given, *restore]:
            self._run(self._cell(index))
        self._run(RESET)
        grading, grading_numbers = self._grading_check(answer, mutant)
        # A check in the kernel is heard by no judge: what the grader's run of the same code
        # produced stands for it (the two must say the same anyway), with what the kernel
        # printed.
        printed = {float(n) for line in [*cell.lines, *lab.lines] for n in NUMBER.findall(line)}
        lab_numbers = lab_numbers if answer.judged else grading_numbers | printed
        shown_numbers = stated_numbers([*lab.error, *grading.error], every=True)
        for shown, numbers in ((lab, lab_numbers), (grading, grading_numbers)):
            shown.produced = sorted(_matching(numbers, shown_numbers))
        return Outcome(
            ident=mutant.ident if mutant else f'{answer.key} | none | the answer as written',
            notebook=self.number, answer=answer.key,
            operator=mutant.operator if mutant else 'none',
            what=mutant.what if mutant else 'the answer as written', source=source,
            changed=list(mutant.changed) if mutant else [],
            affected=sorted(mutant.affected) if mutant else [],
            written=[list(r) for r in answer.regions], cell=cell, lab=lab, grading=grading,
            file_text=file_text, seconds=round(time.monotonic() - began, 1))

    def _skip(self, answer: Answer, plan: str) -> list[int]:
        """Undo an earlier cell for a run with it not run (``'skip part N'``: the part taken
        out of the file's saved parts; ``'skip NAMES'``: the names it bound forgotten);
        return the cells that redo it."""
        if not plan.startswith('skip '):
            return []
        cells = notebook(self.number)['cells']
        if plan.startswith('skip part '):
            number = plan.split()[-1]
            target = answer.source.split('\n')[0].split()[1]
            index = next(i for i, c in enumerate(cells) if ''.join(c['source']).startswith(
                f'%%part {target} {number}\n'))
            record = self.lab_ws / '.ros2nb-parts.json'
            saved = json.loads(record.read_text())
            relative = str(self._file(answer).relative_to(self.lab_ws))
            saved.get(relative, {}).pop(number, None)
            record.write_text(json.dumps(saved, indent=1, sort_keys=True) + '\n')
            return [index]
        names = plan.split()[1:]
        self._run(f'for _name in {names!r}:\n    globals().pop(_name, None)')
        return [max(i for i, text in setup_cells(self.number).items()
                    if i < answer.index and set(names) & bound_names(text))]

    def _file(self, answer: Answer) -> Path:
        """The learner's file a ``%%part`` answer goes into."""
        name = answer.source.split('\n')[0].split()[1].strip('{}')
        return self.lab_ws / getattr(course, {'PUBLISHER': 'PUBLISHER_FILE',
                                              'SUBSCRIBER': 'SUBSCRIBER_FILE',
                                              'SETUP_PY': 'SETUP_PY_FILE',
                                              'SETUP_CFG': 'SETUP_CFG_FILE',
                                              'FAN': 'FAN_FILE', 'PROMISES': 'PROMISES_FILE',
                                              'LIVE_PLOT': 'LIVE_PLOT_FILE'}[name])

    def _file_text(self, answer: Answer) -> str:
        """The learner's file the answer's part went into, as the check read it."""
        if not answer.is_part:
            return ''
        path = self._file(answer)
        return path.read_text() if path.is_file() else ''


def _matching(numbers: set[float], stated: list[tuple[float, float]]) -> set[float]:
    """Those of ``numbers`` a stated number (value, tolerance) may be."""
    return {n for n in numbers for value, tolerance in stated if abs(n - value) <= tolerance}


def run_notebook(number: str, out: Path, chosen: Optional[set[str]] = None,
                 baseline: bool = True) -> list[dict]:
    """Run notebook ``number``'s mutants (``chosen``, or all, with the unchanged answers
    when ``baseline``); write each outcome to ``out`` as a JSON line as it comes; return
    them."""
    found = []
    with temporary_folder(f'mutants-{number}') as root, _returns_kept():
        run = NotebookRun(number, Path(root))
        try:
            with out.open('w') as written:
                for outcome in run.run(chosen, baseline):
                    found.append(asdict(outcome))
                    written.write(json.dumps(found[-1]) + '\n')
                    written.flush()
        finally:
            run.close()
    return found
