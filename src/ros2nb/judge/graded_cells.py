"""Grading a notebook in the judge: every graded cell of the course, on what the learner wrote.

Part of the judge (:mod:`ros2nb.judge`).  The graded cells come from the course's own
source notebook (hidden tests included); of the learner's submission only the answer
cells are read, as text: the names they define become :class:`AnswerRef` for the checks.
"""

from __future__ import annotations

import ast
import dataclasses
from typing import Any, Callable, Optional

from .. import checks, nbmeta
from ..judge_interface import AnswerRef, Judge, captured
from ..outcomes import CheckOutcome


def _is_check_call(node: ast.AST) -> Optional[str]:
    """``ros2nb.checks.NAME(...)`` -> NAME, else None."""
    if not (isinstance(node, ast.Expr) and isinstance(node.value, ast.Call)):
        return None
    func = node.value.func
    if (isinstance(func, ast.Attribute) and isinstance(func.value, ast.Attribute)
            and isinstance(func.value.value, ast.Name) and func.value.value.id == 'ros2nb'
            and func.value.attr == 'checks'):
        return func.attr
    return None


def _value(node: ast.expr, names: dict[str, Any]) -> Any:
    if isinstance(node, ast.Name):
        if node.id not in names:
            return AnswerRef(node.id, ())  # not defined in any answer cell
        return names[node.id]
    return ast.literal_eval(node)


def graded_calls(source: str) -> list[tuple[str, list[ast.expr], list[ast.keyword]]]:
    """The ``ros2nb.checks`` calls of a graded cell, the only statements the judge runs.

    :raises ValueError: for any other statement (a mistake in the course, not the learner's).
    """
    lines = [line for line in source.splitlines() if not line.lstrip().startswith('###')]
    calls = []
    for statement in ast.parse('\n'.join(lines)).body:
        name = _is_check_call(statement)
        if name is None:
            raise ValueError(f'a graded cell may only call ros2nb.checks functions: '
                             f'{ast.unparse(statement)[:80]}')
        call = statement.value  # type: ignore[attr-defined]  # a call, _is_check_call said
        calls.append((name, call.args, call.keywords))
    return calls


def _defined_names(source: str) -> set[str]:
    try:
        tree = ast.parse(source)
    except SyntaxError:
        return set()
    names = set()
    for statement in tree.body:
        if isinstance(statement, (ast.FunctionDef, ast.ClassDef, ast.AsyncFunctionDef)):
            names.add(statement.name)
        elif isinstance(statement, ast.Assign):
            names.update(t.id for t in statement.targets if isinstance(t, ast.Name))
    return names


def grade(source: dict[str, Any], submission: dict[str, Any], judge: Judge,
          checked: Callable[[str, CheckOutcome], None] = lambda grade_id, result: None,
          starting: Callable[[str], None] = lambda grade_id: None
          ) -> dict[str, CheckOutcome]:
    """Run every graded cell of ``source`` (the course's notebook, hidden tests included).

    Names in a graded call (``LoudListener``) are the learner's: the judge passes an
    :class:`AnswerRef` with the course's context cells and every answer cell of the
    submission, and the check runs it in a subject.

    :param source: the course's source notebook (nbformat JSON).
    :param submission: the learner's notebook (nbformat JSON); only its answer cells
        (nbgrader ``solution: true``) are used.
    :param judge: the session every check's body runs with (:func:`ros2nb.checks.run_check`).
    :param checked: called with each graded cell's id and outcome as soon as it is decided.
    :param starting: called with each graded cell's id before its checks run.
    :return: ``{grade_id: outcome}``: a cell's checks run in turn up to the first that fails;
        its outcome holds the lines of all that ran, and the failure.
    """
    context = [nbmeta.text(c) for c in nbmeta.cells(source) if nbmeta.CONTEXT_TAG in
               nbmeta.tags(c)]
    answers = [nbmeta.text(c) for c in nbmeta.cells(submission)
               if nbmeta.nbgrader_metadata(c).get('solution') and c.get('cell_type') == 'code']
    sources = tuple(context + answers)
    names = {name: AnswerRef(name, sources) for text in answers for name in _defined_names(text)}
    results = {}
    for grade_id, cell in nbmeta.graded_cells(source):
        starting(grade_id)
        lines: list[str] = []
        result = CheckOutcome(True)
        for name, args, keywords in graded_calls(nbmeta.text(cell)):
            values = [_value(a, names) for a in args]
            options = {k.arg: _value(k.value, names) for k in keywords if k.arg is not None}
            outcome = captured(lambda: checks.run_check(name, judge, *values, **options))
            lines += outcome.lines
            if not outcome.passed:
                result = outcome
                break
        results[grade_id] = result = dataclasses.replace(result, lines=tuple(lines))
        checked(grade_id, result)
    return results
