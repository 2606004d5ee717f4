"""The learner's files read as text by the judge, only to word a failure it saw.

Part of :mod:`ros2nb.checks`.  No point depends on anything here: every check decides from
what the judge observes (messages, /rosout, the graph, exit codes, files after the subject
ended).  Once a check has failed, the text may choose the line that explains it (no timer,
a lambda, a misspelt name).  Every read of a learner's file goes through :data:`TEXT`, so a
test can replace it with a reader that knows nothing and show the scores unchanged.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Optional

from ..errors import CheckFailed

#: What :meth:`ClassSource.value` returns for an expression it cannot work out as text.
UNKNOWN: Any = object()
#: The list methods that add to a list in place (what :meth:`ClassSource.reaches_change` counts).
LIST_GROWERS = frozenset({'append', 'extend', 'insert'})
#: How many names deep :meth:`ClassSource.value` follows ``A = B`` (a guard against loops).
MAX_DEPTH = 8


class TextReader:
    """Reads a learner's file as text (one place, so that a test can make it know nothing)."""

    def read(self, path: Path) -> Optional[str]:
        """The file's text (undecodable bytes replaced), or None when it cannot be read."""
        try:
            return path.read_text(errors='replace')
        except OSError:
            return None


#: The one reader of the learner's text.
TEXT = TextReader()
_OPERATORS = {ast.Add: lambda a, b: a + b, ast.Sub: lambda a, b: a - b,
              ast.Mult: lambda a, b: a * b, ast.Div: lambda a, b: a / b}


@dataclass(frozen=True)
class Timer:
    """A ``create_timer`` call in the class.

    :ivar period: the period in seconds, or :data:`UNKNOWN` when it is not a constant.
    :ivar callback: the method's name for ``self.NAME``, else the argument's source text.
    :ivar line: the line of the call in the file.
    :ivar named: the name given as the period (``PUBLISH_PERIOD_S``), or '' for another
        expression (a number written out).
    """

    period: Any
    callback: str
    line: int = 0
    named: str = ''


def _assigned(function: Optional[ast.AST], target: str) -> list[ast.expr]:
    """Values assigned to ``target`` (``'X'`` or ``'self.X'``) anywhere in ``function``."""
    values = []
    for node in ast.walk(function) if function is not None else ():
        if isinstance(node, ast.Assign):
            targets, value = node.targets, node.value
        elif isinstance(node, (ast.AnnAssign, ast.AugAssign)) and node.value is not None:
            targets, value = [node.target], node.value
            if isinstance(node, ast.AugAssign):
                value = UNKNOWN
        else:
            continue
        if any(ast.unparse(t) == target for t in targets):
            values.append(value)
    return values


def read_module(workspace: Path, relative: str) -> Optional[ast.Module]:
    """The file ``relative`` to ``workspace``, parsed; None when it cannot be read or parsed
    (the subject's import says why, in the learner's words).

    :raises CheckFailed: when the file is a link to outside the workspace (the judge
        reads what the learner wrote there, never a file a subject may rewrite).
    """
    path = workspace / relative
    target = path.resolve()
    if not target.is_relative_to(workspace.resolve()):
        raise CheckFailed(f'{relative} is a link to {target}, outside your '
                          'workspace: the grader reads your files in the workspace only; '
                          'put the file itself there.')
    text = TEXT.read(path)
    try:
        return ast.parse(text) if text is not None else None
    except (SyntaxError, ValueError):
        return None


def module_function(module: ast.Module, name: str) -> Optional[ast.FunctionDef]:
    """The last top-level ``def name`` of ``module``, or None."""
    found = [s for s in module.body if isinstance(s, ast.FunctionDef) and s.name == name]
    return found[-1] if found else None


def made_by(module: ast.Module, function: Optional[ast.AST], node: ast.expr,
            depth: int = 0) -> Optional[ast.expr]:
    """What makes the value of ``node`` in ``function``: local names are followed to their
    last assignment, and calls of the file's own top-level functions to what they return
    (when they have one ``return``).  The result is a call (``MultiThreadedExecutor(...)``),
    a tuple, a constant, or None when the text does not say."""
    if depth > MAX_DEPTH:
        return None
    if isinstance(node, ast.Name):
        local = _assigned(function, node.id)
        return made_by(module, function, local[-1], depth + 1) if local else None
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
        callee = module_function(module, node.func.id)
        if callee is not None:
            returns = [r.value for r in ast.walk(callee)
                       if isinstance(r, ast.Return) and r.value is not None]
            return made_by(module, callee, returns[0], depth + 1) if len(returns) == 1 else None
    if isinstance(node, (ast.Call, ast.Tuple, ast.Constant)):
        return node
    return None


class ClassSource:
    """One class of the learner's file, as the judge reads it (text only)."""

    def __init__(self, module: ast.Module, cls: ast.ClassDef) -> None:
        self.module, self.cls = module, cls

    @classmethod
    def read(cls, workspace: Path, relative: str, name: str) -> Optional['ClassSource']:
        """The class ``name`` of the file ``relative`` to ``workspace``; None when the file
        cannot be read or parsed, or holds no such class (the subject's import says why, in
        the learner's words).

        :raises CheckFailed: when the file is a link to outside the workspace (the judge
            reads what the learner wrote there, never a file a subject may rewrite).
        """
        module = read_module(workspace, relative)
        if module is None:
            return None
        found = [s for s in module.body if isinstance(s, ast.ClassDef) and s.name == name]
        return cls(module, found[-1]) if found else None

    def method(self, name: str) -> Optional[ast.FunctionDef]:
        found = [s for s in self.cls.body if isinstance(s, ast.FunctionDef) and s.name == name]
        return found[-1] if found else None

    def computes(self, name: str) -> bool:
        """True when the class body makes ``name`` something other than a plain value: a
        method or ``@property`` of that name, or a class attribute set to what is not a
        constant (``property(...)``, a descriptor).  Reading it may then run any code."""
        for statement in self.cls.body:
            if isinstance(statement, (ast.FunctionDef, ast.AsyncFunctionDef)) \
                    and statement.name == name:
                return True
            if isinstance(statement, (ast.Assign, ast.AnnAssign)) and statement.value is not None \
                    and any(isinstance(t, ast.Name) and t.id == name for t in (
                        statement.targets if isinstance(statement, ast.Assign)
                        else [statement.target])) \
                    and self.value(statement.value) is UNKNOWN:
                return True
        return False

    def value(self, node: Any, function: Optional[ast.AST] = None, depth: int = 0) -> Any:
        """The constant an expression stands for, following names; else :data:`UNKNOWN`."""
        if node is UNKNOWN or depth > MAX_DEPTH:
            return UNKNOWN
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            inner = self.value(node.operand, function, depth + 1)
            if isinstance(inner, (int, float)) and not isinstance(inner, bool):
                return -inner if isinstance(node.op, ast.USub) else inner
            return UNKNOWN
        if isinstance(node, ast.BinOp) and type(node.op) in _OPERATORS:
            left = self.value(node.left, function, depth + 1)
            right = self.value(node.right, function, depth + 1)
            try:
                return _OPERATORS[type(node.op)](left, right)
            except Exception:
                return UNKNOWN
        if isinstance(node, ast.Name):
            local = _assigned(function, node.id)
            if local:
                return self.value(local[-1], function, depth + 1)
            scope = [s for s in self.module.body if not isinstance(
                s, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))]
            found = _assigned(ast.Module(body=scope, type_ignores=[]), node.id)
            return self.value(found[-1], None, depth + 1) if found else UNKNOWN
        if isinstance(node, ast.Attribute) and ast.unparse(node.value) == 'self':
            return self.attribute(node.attr, depth + 1)
        return UNKNOWN

    def defined_at(self, name: str) -> Optional[int]:
        """The line where the file's top level last assigns ``name``, or None."""
        scope: list[ast.stmt] = [s for s in self.module.body
                                 if isinstance(s, (ast.Assign, ast.AnnAssign))]
        found = _assigned(ast.Module(body=scope, type_ignores=[]), name)
        return found[-1].lineno if found else None

    def assignments(self, attribute: str) -> list[ast.expr]:
        """Values ``__init__`` assigns to ``self.<attribute>``, in order."""
        return _assigned(self.method('__init__'), f'self.{attribute}')

    def attribute(self, attribute: str, depth: int = 0) -> Any:
        """The constant ``__init__`` last assigns to ``self.<attribute>``, or UNKNOWN."""
        found = self.assignments(attribute)
        return self.value(found[-1], self.method('__init__'), depth) if found else UNKNOWN

    def timers(self) -> list[Timer]:
        """Every ``create_timer(period, callback)`` call in the class's methods."""
        timers = []
        for function in self.cls.body:
            if not isinstance(function, ast.FunctionDef):
                continue
            for node in ast.walk(function):
                if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                        and node.func.attr == 'create_timer':
                    given = {k.arg: k.value for k in node.keywords}
                    period = node.args[0] if node.args else given.get('timer_period_sec')
                    callback = node.args[1] if len(node.args) > 1 else given.get('callback')
                    timers.append(Timer(self.value(period, function) if period else UNKNOWN,
                                        _method_name(callback), node.lineno,
                                        period.id if isinstance(period, ast.Name) else ''))
        return timers

    def callbacks(self, factory: str, position: int) -> list[str]:
        """The callbacks given to every ``factory(...)`` call (``create_subscription``) in
        the class: the argument at ``position`` or the keyword ``callback``, by name."""
        found = []
        for node in ast.walk(self.cls):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                    and node.func.attr == factory:
                given = {k.arg: k.value for k in node.keywords}
                found.append(_method_name(node.args[position] if len(node.args) > position
                                          else given.get('callback')))
        return found

    def reaches_assignment(self, method: str, attribute: str) -> bool:
        """True when ``method`` assigns ``self.<attribute>`` (``=``, ``+=``, ``setattr``),
        itself or through ``self.m()`` calls of the class."""
        target = f'self.{attribute}'

        def assigns(node: ast.AST) -> bool:
            if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
                targets = node.targets if isinstance(node, ast.Assign) else [node.target]
                return any(ast.unparse(t) == target for t in targets)
            return isinstance(node, ast.Call) and ast.unparse(node.func) == 'setattr' \
                and len(node.args) > 1 and ast.unparse(node.args[0]) == 'self' \
                and ast.unparse(node.args[1]) in (repr(attribute), f'"{attribute}"')

        return self._reaches(method, assigns)

    def reaches_change(self, method: str, attribute: str) -> bool:
        """True when ``method`` changes ``self.<attribute>``: assigns it (as
        :meth:`reaches_assignment` says) or calls a list method that grows it
        (``self.<attribute>.append(...)``, ``extend``, ``insert``), itself or through
        ``self.m()`` calls of the class."""
        target = f'self.{attribute}'
        return self.reaches_assignment(method, attribute) or self._reaches(
            method, lambda node: isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute) and node.func.attr in LIST_GROWERS
            and ast.unparse(node.func.value) == target)

    def _reaches(self, method: str, hit: Any) -> bool:
        """True when ``hit(node)`` holds for a node of ``method`` (a method's name, or a
        callback's lambda as :meth:`callbacks` gives it) or of a method it calls as
        ``self.m()``, however deep."""
        seen: set[str] = set()
        todo = [method]
        while todo:
            name = todo.pop()
            if name in seen:
                continue
            seen.add(name)
            function: Optional[ast.AST] = self.method(name)
            if function is None and name.startswith('lambda'):
                function = ast.parse(name, mode='eval').body
            if function is None:
                continue
            for node in ast.walk(function):
                if hit(node):
                    return True
                if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) \
                        and ast.unparse(node.func.value) == 'self':
                    todo.append(node.func.attr)
        return False


def _method_name(callback: Optional[ast.expr]) -> str:
    if callback is None:
        return 'nothing'
    if isinstance(callback, ast.Attribute) and ast.unparse(callback.value) == 'self':
        return callback.attr
    return ast.unparse(callback)
