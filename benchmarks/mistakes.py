"""``make mistakes``: every answer cell of solutions/ mutated, each mutant's answer judged.

The mutation test of the course's checks (issue 65): every answer cell (``solutions/``,
nbgrader ``solution: true``) is mutated by a fixed set of operators
(``tests/mutation_operators.py``); each mutant runs in a real kernel as the learner meets it
and through the grader's path (``tests/mutation_runs.py``), and its answer is judged
(``tests/mutation_verdicts.py``): killed well, survived (equivalent or weak), or bad.

    .venv/bin/python benchmarks/mistakes.py [--notebooks 03,04] [--workers 2] [--out mistakes]

One process per notebook (its kernel and its judge sessions), ``--workers`` of them at a
time, the longest first.  Each writes its outcomes as JSON lines (``OUT/NN.jsonl``); at the
end ``OUT/report.md`` has a table per notebook and operator, every bad answer shown, every
survivor with its reason, and the run's wall seconds and CPU seconds (of every process it
started: this process is their subreaper, as ``tests/run_counted.py`` is for ``make test``).
``--report`` only writes the report again from the JSON lines there.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import os
import resource
import subprocess
import sys
import time
from collections import Counter, defaultdict
from pathlib import Path
from typing import Optional

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / 'tests')]  # the root's conftest: the tests' set-up

from mutation_cells import answers  # noqa: E402
from mutation_mistakes import OPERATORS, mutants  # noqa: E402
from mutation_verdicts import verdict  # noqa: E402

PR_SET_CHILD_SUBREAPER = 36  # linux/prctl.h
#: Relative cost of one mutant's checks, by notebook (what runs longest goes first).
COST = {'05': 6, '10': 5, '06': 3, '03': 3, '04': 2, '08': 2, '07': 2}
KINDS = ('killed well', 'passes', 'survived (equivalent)', 'survived (weak)', 'bad')


def _one(number: str, out: Path, chosen: list[str]) -> int:
    """Run notebook ``number``'s mutants in this process (the notebooks' test set-up)."""
    import conftest  # noqa: F401 - the tests' environment: no domain, discovery on localhost
    from mutation_runs import run_notebook
    try:
        run_notebook(number, out, set(chosen) or None)
    finally:
        conftest.pytest_sessionfinish(None, 0)
    return 0


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _reap_orphans() -> None:
    while True:
        try:
            if os.waitpid(-1, os.WNOHANG)[0] == 0:
                return
        except ChildProcessError:
            return


def run_all(numbers: list[str], workers: int, out: Path) -> tuple[float, float]:
    """Run each notebook in a process of its own, ``workers`` at a time; return the wall
    and CPU seconds of it all."""
    ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    began, cpu = time.monotonic(), _cpu_seconds()
    waiting = sorted(numbers, key=lambda n: -COST.get(n, 1) * len(
        [m for a in answers(n) for m in mutants(a)]))
    running: dict[str, subprocess.Popen] = {}
    while waiting or running:
        while waiting and len(running) < workers:
            number = waiting.pop(0)
            log = (out / f'{number}.log').open('w')
            running[number] = subprocess.Popen(
                [sys.executable, __file__, '--one', number, '--out', str(out)],
                stdout=log, stderr=subprocess.STDOUT, start_new_session=True, cwd=ROOT)
            print(f'notebook {number}: started', flush=True)
        for number, proc in list(running.items()):
            if proc.poll() is not None:
                del running[number]
                print(f'notebook {number}: done (exit {proc.returncode}) after '
                      f'{time.monotonic() - began:.0f} s', flush=True)
        time.sleep(0.5)
        _reap_orphans()
    _reap_orphans()
    return time.monotonic() - began, _cpu_seconds() - cpu


# ------------------------------------------------------------------ the report
def _shown(outcome: dict, path: str) -> str:
    shown = outcome[path]
    if shown['hung']:
        return '(no answer)'
    if not shown['error']:
        return 'passed: ' + ' / '.join(shown['lines'][-1:])
    return '\n'.join(shown['error'])


def _fenced(text: str) -> str:
    return '```\n' + text.replace('```', "'''") + '\n```'


def _judged(out: Path) -> list[tuple[dict, str, list[str]]]:
    outcomes = [json.loads(line) for path in sorted(out.glob('*.jsonl'))
                for line in path.read_text().splitlines() if line.strip()]
    return [(o, *verdict(o)) for o in outcomes]


def _compared(before: Path, after: list[tuple[dict, str, list[str]]]) -> list[str]:
    """A table of the counts by notebook, before (the outcomes in ``before``) and after."""
    then = _judged(before)
    lines = ['## Before and after', '', f'Before: the outcomes in `{before}`.', '',
             '| notebook | mutants | killed well | passes | survived (equivalent / weak) | bad |',
             '|---|---|---|---|---|---|']
    for number in sorted({o['notebook'] for o, _k, _w in then + after}):
        cells = []
        for judged in (then, after):
            kinds = Counter(k for o, k, _w in judged
                            if o['notebook'] == number and o['operator'] != 'none')
            cells.append((sum(kinds.values()), kinds['killed well'], kinds['passes'],
                          f'{kinds["survived (equivalent)"]} / {kinds["survived (weak)"]}',
                          kinds['bad']))
        lines.append(f'| {number} | ' + ' | '.join(f'{a} → {b}' for a, b in zip(*cells)) + ' |')
    return lines + ['']


def report(out: Path, wall_s: float = 0.0, cpu_s: float = 0.0,
           before: Optional[Path] = None) -> dict[str, int]:
    """Write ``out/report.md`` from the outcomes there (and a table against the outcomes in
    ``before``, when given); return the totals by kind."""
    judged = _judged(out)
    outcomes = [o for o, _kind, _why in judged]
    totals: Counter = Counter(kind for o, kind, _ in judged if o['operator'] != 'none')
    lines = ['# Mutants of the answers: what each check answered', '',
             'Made by `make mistakes` (`benchmarks/mistakes.py`): each answer cell of solutions/ '
             'mutated by a fixed operator, run in a real kernel as the learner meets it (lab) '
             "and through the grader's path (grading).", '']
    if wall_s:
        lines += [f'Wall {wall_s:.0f} s, CPU {cpu_s:.0f} s (every process of the run).', '']
    mutated = sum(totals.values())
    lines += [f'**{mutated} mutants** of {len({o["answer"] for o in outcomes})} answer cells: '
              + ', '.join(f'{totals[k]} {k}' for k in KINDS) + '.', '']
    if before is not None:
        lines += _compared(before, judged)
    baseline = [(o, why) for o, kind, why in judged if o['operator'] == 'none' and kind != 'passes']
    for o, why in baseline:
        lines += [f'- the answer {o["answer"]} as written fails: {"; ".join(why)}',
                  _fenced(_shown(o, 'lab') + '\n--- grading:\n' + _shown(o, 'grading'))]
    by_notebook: dict[str, list] = defaultdict(list)
    for item in judged:
        if item[0]['operator'] != 'none':
            by_notebook[item[0]['notebook']].append(item)
    lines += ['## Totals by notebook and operator', '',
              '| notebook | operator | mutants | killed well | passes | survived (equivalent / '
              'weak) | bad |', '|---|---|---|---|---|---|---|']
    for number, items in sorted(by_notebook.items()):
        for operator in OPERATORS:
            kinds = Counter(kind for o, kind, _ in items if o['operator'] == operator)
            if kinds:
                lines.append(f'| {number} | {operator} | {sum(kinds.values())} | '
                             f'{kinds["killed well"]} | {kinds["passes"]} | '
                             f'{kinds["survived (equivalent)"]} / {kinds["survived (weak)"]} | '
                             f'{kinds["bad"]} |')
    for number, items in sorted(by_notebook.items()):
        lines += ['', f'## Notebook {number}', '']
        for o, kind, why in items:
            if kind == 'killed well':
                continue
            lines += [f'### {kind}: {o["ident"]}', '']
            if why:
                lines += ['- ' + w for w in why] + ['']
            if kind == 'bad':
                lines += ['lab:', _fenced(_shown(o, 'lab')), 'grading:',
                          _fenced(_shown(o, 'grading')), '']
        lines += ['', f'<details><summary>Every answer of notebook {number}</summary>', '',
                  '| answer | mutant | verdict | the lab shows (last line) |',
                  '|---|---|---|---|']
        for o, kind, _ in items:
            last = (o['lab']['error'] or o['lab']['lines'] or [''])[-1]
            lines.append(f'| {o["answer"]} | {o["operator"]}: {o["what"]} | {kind} | '
                         f'{last.replace("|", "/")[:300]} |')
        lines += ['', '</details>']
    (out / 'report.md').write_text('\n'.join(lines) + '\n')
    return dict(totals)


#: Characters a page's text escapes (MyST reads them as markup).
_MARKUP = set('\\`*_[]<>|${}#~')


def _plain(text: str) -> str:
    """``text`` as a page shows it, every markup character escaped."""
    return ''.join('\\' + c if c in _MARKUP else c for c in ' '.join(text.split()))


def _learner_reads(outcome: dict) -> str:
    """What the learner reads in the lab after the mutant's check: its line, or 'passed'."""
    shown = outcome['lab']
    if shown['hung']:
        return '(no answer)'
    if not shown['error']:
        return 'passed: ' + (shown['lines'] or [''])[0]
    return shown['error'][-1]


def docs_report(judged: list, path: Path, wall_s: float, cpu_s: float) -> None:
    """``docs/mistakes.md``: the counts by notebook and operator, then every mutant with the
    line the learner reads in the lab (the grader's, where it says otherwise)."""
    mutated = [(o, kind, why) for o, kind, why in judged if o['operator'] != 'none']
    totals: Counter = Counter(kind for _o, kind, _w in mutated)
    lines = ['# Mistakes and what the checks answer', '',
             'Made by `make mistakes` (`benchmarks/mistakes.py`, [developing.md]'
             '(developing.md#mutants-every-answers-mistakes-answered-well)): every answer cell '
             'of the notebooks mutated as a beginner errs, each mutant run in a real kernel as '
             "the learner meets it (the lab) and through the grader's path, and each answer "
             'judged on what it says: **killed well** (both fail with one true line that names '
             'the change, states only numbers the code produced and says what to do), '
             '**passes** (a run of the answer as written), **survived (equivalent)** (no '
             'mistake: its excuse says why), **survived (weak)** or **bad**.', '',
             f'**{len(mutated)} mutants** of {len({o["answer"] for o, _k, _w in mutated})} '
             'answer cells: ' + ', '.join(f'{totals[k]} {k}' for k in KINDS) + '.', '']
    if wall_s:
        lines += [f'The run took {wall_s:.0f} s of wall time and {cpu_s:.0f} CPU seconds.', '']
    operators = [op for op in OPERATORS if any(o['operator'] == op for o, _k, _w in mutated)]
    numbers = sorted({o['notebook'] for o, _k, _w in mutated})
    lines += ['## Mutants by operator and notebook', '',
              'Each cell: mutants, then how many were killed well (or, for the runs of the '
              'answer as written, passed).', '',
              '| operator | ' + ' | '.join(numbers) + ' |',
              '|---|' + '---|' * len(numbers)]
    for op in operators:
        cells = []
        for number in numbers:
            kinds = Counter(k for o, k, _w in mutated
                            if o['operator'] == op and o['notebook'] == number)
            good = kinds['killed well'] + kinds['passes'] + kinds['survived (equivalent)']
            cells.append(f'{sum(kinds.values())} / {good}' if kinds else '')
        lines.append(f'| {op} | ' + ' | '.join(cells) + ' |')
    for number in numbers:
        lines += ['', f'## Notebook {number}']
        for answer in dict.fromkeys(o['answer'] for o, _k, _w in mutated
                                    if o['notebook'] == number):  # in the notebook's order
            lines += ['', f'### {answer}', '', '| mutant | verdict | the learner reads |',
                      '|---|---|---|']
            for o, kind, why in mutated:
                if o['answer'] != answer:
                    continue
                said = _learner_reads(o)
                grader = o['grading']['error'][-1] if o['grading']['error'] else ''
                if grader and grader != said:
                    said += f' (the grader: {grader})'
                if kind == 'survived (equivalent)':
                    said += f' (equivalent: {why[0]})'
                lines.append(f'| {_plain(o["operator"] + ": " + o["what"])} | {kind} | '
                             f'{_plain(said)} |')
    path.write_text('\n'.join(lines) + '\n')


def sample(out: Path) -> dict[str, list[str]]:
    """``tests/test_mutants.py``'s sample from a whole run's outcomes: for each notebook, the
    cheapest mutant (wall seconds) of each operator that made one there."""
    chosen: dict[tuple[str, str], dict] = {}
    for o, _kind, _why in _judged(out):
        key = (o['notebook'], o['operator'])
        if o['operator'] != 'none' and (key not in chosen
                                        or o['seconds'] < chosen[key]['seconds']):
            chosen[key] = o
    found: dict[str, list[str]] = defaultdict(list)
    for (number, _operator), o in sorted(chosen.items()):
        found[number].append(o['ident'])
    return dict(found)


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--notebooks', default='', help='e.g. 03,04 (default: all)')
    parser.add_argument('--workers', type=int, default=2)
    parser.add_argument('--out', default=str(ROOT / 'mistakes'))
    parser.add_argument('--one', help=argparse.SUPPRESS)
    parser.add_argument('--only', nargs='*', default=[], help=argparse.SUPPRESS)
    parser.add_argument('--report', action='store_true', help='only write the report again')
    parser.add_argument('--before', help='a folder of earlier outcomes to compare with')
    parser.add_argument('--sample', action='store_true',
                        help="print tests/test_mutants.py's sample from the outcomes in --out")
    parser.add_argument('--docs', action='store_true',
                        help='with --report: write docs/mistakes.md too (a whole run does)')
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.one:
        return _one(args.one, out / f'{args.one}.jsonl', args.only)
    before = Path(args.before) if args.before else None
    if args.sample:
        print(json.dumps(sample(out), indent=1))
        return 0
    if args.report:
        print(report(out, before=before))
        if args.docs:
            run = json.loads((out / 'run.json').read_text()) if (out / 'run.json').is_file() \
                else {'wall_s': 0.0, 'cpu_s': 0.0}
            docs_report(_judged(out), ROOT / 'docs' / 'mistakes.md', run['wall_s'],
                        run['cpu_s'])
        return 0
    numbers = args.notebooks.split(',') if args.notebooks else \
        sorted({a.notebook for a in answers()})
    wall_s, cpu_s = run_all(numbers, args.workers, out)
    (out / 'run.json').write_text(json.dumps({'wall_s': wall_s, 'cpu_s': cpu_s,
                                              'notebooks': numbers}) + '\n')
    totals = report(out, wall_s, cpu_s, before)
    if not args.notebooks:  # the whole run: the committed page
        docs_report(_judged(out), ROOT / 'docs' / 'mistakes.md', wall_s, cpu_s)
    print(f'{sum(totals.values())} mutants: {totals}; wall {wall_s:.0f} s, CPU {cpu_s:.0f} s; '
          f'report: {out / "report.md"}')
    return 1 if totals.get('bad') else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
