"""Which branch of an ``if`` a call of the learner's function took, and what it left unset.

Part of :mod:`ros2nb.explain`, for :mod:`.everyday`: a name that a function sets in some
branches of an ``if``/``elif``/``else`` and reads after it has no value when the call took a
branch that does not set it.  The line that says so names that branch (its first line, the
one the learner wrote there in place of the name's), not the line that read the name, which
is right.  Introduced in ``04-write-the-subscriber.ipynb``.
"""

from __future__ import annotations

import ast
import inspect
import textwrap
from dataclasses import dataclass
from types import FrameType
from typing import Optional

#: What a branch's condition may hold for it to be worked out again from the frame's values:
#: names, attributes, numbers and comparisons, never a call (which could do anything twice).
_PLAIN = (ast.Expression, ast.Compare, ast.BoolOp, ast.UnaryOp, ast.BinOp, ast.Name,
          ast.Attribute, ast.Constant, ast.Load, ast.cmpop, ast.boolop, ast.unaryop,
          ast.operator)


@dataclass(frozen=True)
class Unset:
    """The branch of an ``if`` a call took that sets no value for a name it reads after.

    :ivar line: the line of the file (or cell) where that branch starts: the first
        statement of its body, or, where the call took no branch (no ``else``), the last
        ``if``/``elif`` line.
    :ivar words: what the learner reads: the branch, and what to do.
    """

    line: int
    words: str


def _sets(statements: list[ast.stmt], name: str) -> bool:
    """Whether ``statements`` assign ``name`` anywhere in them (a nested block included)."""
    return any(isinstance(node, ast.Name) and node.id == name and isinstance(node.ctx, ast.Store)
               for statement in statements for node in ast.walk(statement))


def _chain(node: ast.If) -> tuple[list[tuple[ast.expr, list[ast.stmt]]], list[ast.stmt]]:
    """An ``if``'s branches, ``elif``s included, as ``(condition, body)``, and its ``else``."""
    branches = [(node.test, node.body)]
    rest = node.orelse
    while len(rest) == 1 and isinstance(rest[0], ast.If):
        branches.append((rest[0].test, rest[0].body))
        rest = rest[0].orelse
    return branches, rest


def _holds(condition: ast.expr, frame: FrameType) -> Optional[bool]:
    """Whether ``condition`` holds with the frame's values now, or None when that cannot be
    said without running more than names, attributes and comparisons."""
    expression = ast.Expression(condition)
    if not all(isinstance(node, _PLAIN) for node in ast.walk(expression)):
        return None
    try:
        code = compile(expression, '<condition>', 'eval')
        return bool(eval(code, frame.f_globals, dict(frame.f_locals)))  # noqa: S307 - plain
    except Exception:
        return None


def _taken(branches: list[tuple[ast.expr, list[ast.stmt]]], orelse: list[ast.stmt], name: str,
           frame: FrameType) -> Optional[tuple[Optional[ast.expr], list[ast.stmt]]]:
    """The branch the call took, ``(condition or None for the else, body)``: the first whose
    condition holds; where a condition cannot be worked out, the one branch that sets no
    ``name``, if only one does not."""
    for condition, body in branches:
        holds = _holds(condition, frame)
        if holds is None:
            break
        if holds:
            return condition, body
    else:
        return None, orelse
    unset = [(c, b) for c, b in [*branches, (None, orelse)] if not _sets(b, name)]
    return unset[0] if len(unset) == 1 else None


def unset_on_path(frame: FrameType, name: str) -> Optional[Unset]:
    """The branch of an ``if`` before the frame's line that sets ``name`` in other branches
    but not in the one this call took, or None (no such ``if``, or its source is gone)."""
    try:
        lines, first = inspect.getsourcelines(frame.f_code)
        tree = ast.parse(textwrap.dedent(''.join(lines)))
    except (OSError, TypeError, SyntaxError):
        return None
    first = max(first, 1) - 1  # the file's line of the parsed text's line 1, less one
    inner = {id(node.orelse[0]) for node in ast.walk(tree) if isinstance(node, ast.If)
             and len(node.orelse) == 1 and isinstance(node.orelse[0], ast.If)}
    for node in ast.walk(tree):
        if not isinstance(node, ast.If) or id(node) in inner or node.end_lineno is None \
                or node.end_lineno + first >= frame.f_lineno:
            continue
        branches, orelse = _chain(node)
        if not any(_sets(body, name) for _c, body in [*branches, (None, orelse)]):
            continue
        taken = _taken(branches, orelse, name, frame)
        if taken is None or _sets(taken[1], name):
            continue
        return _described(taken, branches, name, frame, first)
    return None


def _described(taken: tuple[Optional[ast.expr], list[ast.stmt]],
               branches: list[tuple[ast.expr, list[ast.stmt]]], name: str, frame: FrameType,
               first: int) -> Unset:
    condition, body = taken
    function = frame.f_code.co_name
    if body:
        branch = (f'the branch where {ast.unparse(condition)}' if condition is not None
                  else 'its else')
        return Unset(body[0].lineno + first,
                     f'{name} has no value here: {function} sets it in the other branches of '
                     f'its if/elif/else, but not in {branch}, which this call took: set '
                     f'{name} there too.')
    held = ' or '.join(ast.unparse(c) for c, _b in branches)
    return Unset(branches[-1][0].lineno + first,
                 f'{name} has no value here: {function} sets it only when {held}, and '
                 f'none of these held for this call: add an else that sets {name}.')
