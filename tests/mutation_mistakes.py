"""Beginners' mistakes as operators, and every mutant of an answer cell.

The operators of :mod:`mutation_operators` change a token (a typo, a constant, a dropped
``self.``); those here make the mistakes beginners make with the shape of their code and
with ROS (:data:`BEGINNERS`), each through the standard :mod:`ast` as there: a statement
moved to another method, out of or into a block, or above the one before it; a call that
belongs in the constructor moved into a callback (or written there too); a message's field
misnamed; a blocking call in a callback; an entity created twice; a keyword argument left
out (09's ``reliability=``, 08's ``floating_point_range=``, 10's ``rate=``); a QoS policy's
value swapped for the other; a value of the wrong type; a class or method named where it is
called (``node = TemperatureSensor``).  Three more run the answer as
written, in another order (:data:`RUNS`): the cell run twice, run with an earlier cell not
run, and run again, right, after its check failed.

:func:`mutants` gives every mutant of an answer: at most :data:`PER_OPERATOR` per operator,
the same ones every run.
"""

from __future__ import annotations

import ast
import textwrap
from typing import Callable, Iterator, Optional

from mutation_cells import Answer, answers, bound_names, given_cells, setup_cells
from mutation_operators import (CLASSIC, PYTHON_OPERATORS, Cell, Mutant, _constants_of,
                                _given_answer, _ini_mutants, _replaced, make, names_in)
from mutation_tutorial import TUTORIAL

#: The operators of beginners' mistakes, in the report's order.
BEGINNERS = ('statement moved', 'call moved into a callback', 'wrong message field',
             'blocking call in a callback', 'entity created twice', 'keyword left out',
             'QoS policy swapped', 'wrong value type', 'parentheses left out')
#: Runs of the answer as written, in another order: the learner's lab must answer them
#: (the first and last pass; with an earlier cell not run, the check says which), the
#: grader, which runs the notebook in order, passes them all.
RUNS = ('cell run twice', 'earlier cell not run', 'run again after a failed check')
OPERATORS = (*CLASSIC, *BEGINNERS, *RUNS)
#: Most mutants of one operator in one answer cell (evenly chosen among those it can make).
PER_OPERATOR = 8
#: Calls that make an entity of the node (or hand one over): what a constructor does once.
CREATORS = ('create_publisher', 'create_subscription', 'create_timer', 'declare_parameter',
            'add_on_set_parameters_callback', 'add')
#: A message's field, and the name a beginner gives it instead.
WRONG_FIELD = {'data': 'value', 'value': 'data'}
#: Each QoS policy's value, and the other one.
QOS_SWAPPED = {'BEST_EFFORT': 'RELIABLE', 'RELIABLE': 'BEST_EFFORT',
               'TRANSIENT_LOCAL': 'VOLATILE', 'VOLATILE': 'TRANSIENT_LOCAL',
               'KEEP_LAST': 'KEEP_ALL', 'KEEP_ALL': 'KEEP_LAST'}
#: The blocking call a beginner puts in a callback ("wait a second between readings").
BLOCKING = 'time.sleep(1.0)'


# ------------------------------------------------------------------ lines of the cell
def _lines(cell: Cell, node: ast.stmt) -> tuple[int, int]:
    """The cell's first and last line (0-based) of a statement."""
    return cell.line(node), node.end_lineno - 1 + cell.offset


def _indent(cell: Cell, node: ast.stmt) -> str:
    first = cell.line(node)
    text = cell.lines[first]
    return text[:len(text) - len(text.lstrip())]


def _shifted(lines: list[str], by: int) -> list[str]:
    """``lines`` indented ``by`` more spaces (fewer, when negative)."""
    if by >= 0:
        return [(' ' * by + line) if line.strip() else line for line in lines]
    return [line[-by:] if line[:-by].strip() == '' else line.lstrip() for line in lines]


def _moved(cell: Cell, node: ast.stmt, to: int, indent: str) -> str:
    """The cell with statement ``node`` taken out and put before line ``to`` (of the cell
    as it was), indented with ``indent``."""
    first, last = _lines(cell, node)
    by = len(indent) - len(_indent(cell, node))
    taken = _shifted(cell.lines[first:last + 1], by)
    lines = list(cell.lines)
    if to > last:
        lines[to:to] = taken
        del lines[first:last + 1]
    else:
        del lines[first:last + 1]
        lines[to:to] = taken
    return '\n'.join(lines)


def _body_indent(cell: Cell, block: list[ast.stmt]) -> str:
    return _indent(cell, block[0])


def _shown(node: ast.AST) -> str:
    return ast.unparse(node).split('\n')[0][:50]


def _written_statement(cell: Cell, node: ast.stmt) -> bool:
    first, last = _lines(cell, node)
    return all(cell.answer.written(i) for i in range(first, last + 1))


def _methods(cell: Cell) -> list[ast.FunctionDef]:
    """Every method of the cell (a ``def`` whose first argument is ``self``), whether in a
    class of the cell or alone in a ``%%part`` of one."""
    return [n for n in ast.walk(cell.tree) if isinstance(n, ast.FunctionDef)
            and n.args.args and n.args.args[0].arg == 'self']


def _callbacks(cell: Cell) -> list[ast.FunctionDef]:
    """The cell's methods other than ``__init__`` that the learner writes in."""
    return [m for m in _methods(cell) if m.name != '__init__'
            and any(_written_statement(cell, s) for s in m.body)]


def _first_statement(function: ast.FunctionDef) -> ast.stmt:
    body = function.body
    if len(body) > 1 and isinstance(body[0], ast.Expr) and isinstance(body[0].value,
                                                                      ast.Constant):
        return body[1]  # after its docstring
    return body[0]


def _inserted(cell: Cell, before: ast.stmt, text: str) -> str:
    """The cell with ``text`` (one or more lines) put before statement ``before``, at its
    indentation."""
    indent = _indent(cell, before)
    lines = list(cell.lines)
    first = cell.line(before)
    lines[first:first] = [indent + line for line in text.split('\n')]
    return '\n'.join(lines)


# ------------------------------------------------------------------ statement moved
def _moves(cell: Cell) -> Iterator[Mutant]:
    op = 'statement moved'
    yield from _methods_moved(cell)
    yield from _to_other_method(cell)
    yield from _out_of_function(cell)
    for node in ast.walk(cell.tree):
        blocks = [getattr(node, name, None) for name in ('body', 'orelse', 'finalbody')]
        for block in [b for b in blocks if isinstance(b, list) and b
                      and isinstance(b[0], ast.stmt)]:
            yield from _order_swapped(cell, block)
            for index, statement in enumerate(block):
                if isinstance(statement, (ast.FunctionDef, ast.ClassDef)):
                    continue
                yield from _out_of_block(cell, statement)
                after = block[index + 1] if index + 1 < len(block) else None
                if after is not None and _compound(statement) and \
                        not isinstance(statement, (ast.Try, ast.With)) and \
                        _written_statement(cell, after) and not _ends(after):
                    inner = _last_block(statement)
                    yield make(cell.answer, op,
                               f'{_shown(after)} moved into the block above '
                               f'(line {cell.line(after) + 1})',
                               _moved(cell, after, _lines(cell, inner[-1])[1] + 1,
                                      _body_indent(cell, inner)),
                               affected=frozenset(names_in(after)))
                if _compound(statement) and index > 0 and not isinstance(statement, ast.Try):
                    yield from _into_next_block(cell, block[:index], statement)


def _compound(node: ast.stmt) -> bool:
    return isinstance(node, (ast.If, ast.For, ast.While, ast.With, ast.Try))


def _ends(node: ast.stmt) -> bool:
    return isinstance(node, (ast.Return, ast.Pass, ast.Raise, ast.Break, ast.Continue))


def _last_block(node: ast.stmt) -> list[ast.stmt]:
    if isinstance(node, ast.Try) and node.finalbody:
        return node.finalbody
    if isinstance(node, (ast.If, ast.For, ast.While)) and node.orelse:
        return node.orelse
    return node.body


def _out_of_block(cell: Cell, statement: ast.stmt) -> Iterator[Mutant]:
    """The last statement of a block (of an ``if``, ``else``, ``for``, ``with``) taken out of
    it, to the line after the block, one level less indented."""
    if not _compound(statement) or isinstance(statement, ast.Try):
        return
    for block in (statement.body, getattr(statement, 'orelse', [])):
        if len(block) < 2 or not _written_statement(cell, block[-1]) or _ends(block[-1]):
            continue
        last = block[-1]
        yield make(cell.answer, 'statement moved',
                   f'{_shown(last)} moved out of its block (line {cell.line(last) + 1})',
                   _moved(cell, last, _lines(cell, statement)[1] + 1, _indent(cell, statement)),
                   affected=frozenset(names_in(last)))


def _into_next_block(cell: Cell, before: list[ast.stmt], compound: ast.stmt) -> Iterator[Mutant]:
    """The statement before a block (and the calls of the same function just before it, as
    10's ``ros2nb.add(...)`` twice) moved into the block's start."""
    previous = before[-1]
    if not _written_statement(cell, previous) or _compound(previous) or \
            isinstance(previous, (ast.FunctionDef, ast.ClassDef)):
        return
    if isinstance(compound, ast.With) and not _called(previous):
        return  # a name set inside a with block is set all the same
    taken = [previous]
    if _called(previous):
        for statement in reversed(before[:-1]):
            if _called(statement) != _called(previous) or not _written_statement(cell,
                                                                                  statement):
                break
            taken.insert(0, statement)
    inner = compound.body
    indent = _body_indent(cell, inner)
    first, last = cell.line(taken[0]), _lines(cell, taken[-1])[1]
    moving = _shifted(cell.lines[first:last + 1], len(indent) - len(_indent(cell, previous)))
    lines = list(cell.lines)
    at = cell.line(inner[0])
    lines[at:at] = moving
    del lines[first:last + 1]
    shown = _shown(previous) + (f' and {len(taken) - 1} more' if len(taken) > 1 else '')
    yield make(cell.answer, 'statement moved',
               f'{shown} moved into the block below (line {first + 1})', '\n'.join(lines),
               affected=frozenset(names_in(*taken)))


def _called(statement: ast.stmt) -> Optional[str]:
    """The function an expression statement calls (``ros2nb.add``), or None."""
    if isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Call):
        return ast.unparse(statement.value.func)
    return None


def _order_swapped(cell: Cell, block: list[ast.stmt]) -> Iterator[Mutant]:
    """A statement written above the one before it (both simple statements)."""
    for a, b in zip(block, block[1:]):
        if any(isinstance(s, (ast.FunctionDef, ast.ClassDef)) or _compound(s) or _ends(s)
               for s in (a, b)) or not (_written_statement(cell, a)
                                        and _written_statement(cell, b)):
            continue
        if ast.unparse(a) == ast.unparse(b) or not _depend(a, b):
            continue
        yield make(cell.answer, 'statement moved',
                   f'{_shown(b)} above {_shown(a)} (line {cell.line(b) + 1})',
                   _moved(cell, b, cell.line(a), _indent(cell, a)),
                   affected=frozenset(names_in(a, b)))


#: Calls whose order counts whatever names they share: ROS brought up, nodes spun, stopped,
#: a bag recorded or played (a seed or a node handed over counts only before these).
ORDERED_CALLS = ('init', 'spin', 'stop', 'start', 'bag_record', 'bag_play')


def _depend(a: ast.stmt, b: ast.stmt) -> bool:
    """Whether swapping ``a`` and ``b`` can change what they do: one sets a name (or an
    attribute) the other uses, or both call what must come in order (:data:`ORDERED_CALLS`);
    two independent statements in either order are no mistake."""
    def set_by(node: ast.stmt) -> set[str]:
        targets = node.targets if isinstance(node, ast.Assign) else \
            [node.target] if isinstance(node, (ast.AugAssign, ast.AnnAssign)) else []
        return names_in(*targets) if targets else set()

    def ordered(node: ast.stmt) -> bool:
        return any(isinstance(n, ast.Call) and isinstance(n.func, (ast.Attribute, ast.Name))
                   and (n.func.attr if isinstance(n.func, ast.Attribute) else n.func.id)
                   in ORDERED_CALLS for n in ast.walk(node))

    if set_by(a) & names_in(b) or set_by(b) & names_in(a):
        return True
    return (ordered(a) or ordered(b)) and _called(a) != _called(b)


def _to_other_method(cell: Cell) -> Iterator[Mutant]:
    """A statement of one method of the class written in the other (the constructor's log
    line in the callback, the callback's count in the constructor)."""
    methods = [m for m in _methods(cell) if any(_written_statement(cell, s) for s in m.body)]
    for source in methods:
        for target in methods:
            if target is source:
                continue
            start = _first_statement(target)
            for statement in [s for s in source.body if _written_statement(cell, s)
                              and not _compound(s) and not _ends(s)][-1:]:
                yield make(cell.answer, 'statement moved',
                           f'{_shown(statement)} moved from {source.name} into {target.name} '
                           f'(line {cell.line(statement) + 1})',
                           _moved(cell, statement, cell.line(start), _indent(cell, start)),
                           affected=frozenset(names_in(statement) | {source.name, target.name}))


def _out_of_function(cell: Cell) -> Iterator[Mutant]:
    """The last statement of a function or method indented as its ``def`` line: out of it,
    into the class's body or the file's."""
    for function in [n for n in ast.walk(cell.tree) if isinstance(n, ast.FunctionDef)]:
        last = function.body[-1]
        if not _written_statement(cell, last) or _ends(last) or len(function.body) < 2:
            continue
        first, end = _lines(cell, function)
        yield make(cell.answer, 'statement moved',
                   f'{_shown(last)} indented as the def of {function.name} '
                   f'(line {cell.line(last) + 1})',
                   _moved(cell, last, end + 1, _indent(cell, function)),
                   affected=frozenset(names_in(last) | {function.name}))


def _methods_moved(cell: Cell) -> Iterator[Mutant]:
    """A method indented into the method above it (the part of a ``%%part`` cell that starts
    with a method, or a class's second method), or out of its class."""
    op = 'statement moved'
    methods = _methods(cell)
    top = [m for m in methods if m in cell.tree.body]
    if cell.answer.is_part and top and cell.pad:  # a part of methods, after the class's part
        code = cell.lines[1:]
        first = top[0]
        yield make(cell.answer, op, f'{first.name} indented into the method above it',
                   '\n'.join([cell.lines[0], *_shifted(code, 4)]),
                   affected=frozenset({first.name}))
        yield make(cell.answer, op, f'{first.name} written outside the class',
                   '\n'.join([cell.lines[0], *_shifted(code, -cell.pad)]),
                   affected=frozenset({first.name}))
    for klass in [n for n in cell.tree.body if isinstance(n, ast.ClassDef)]:
        inside = [m for m in klass.body if isinstance(m, ast.FunctionDef)]
        for method in inside[1:]:
            if not any(_written_statement(cell, s) for s in method.body):
                continue
            first, last = _lines(cell, method)
            lines = list(cell.lines)
            lines[first:last + 1] = _shifted(lines[first:last + 1], 4)
            yield make(cell.answer, op, f'{method.name} indented into the method above it',
                       '\n'.join(lines), affected=frozenset({method.name}))


# ------------------------------------------------------------------ call moved into a callback
def _creations(function: ast.FunctionDef) -> list[ast.stmt]:
    """The statements of ``function`` that create an entity (:data:`CREATORS`)."""
    found = []
    for statement in function.body:
        calls = [n for n in ast.walk(statement) if isinstance(n, ast.Call)
                 and isinstance(n.func, ast.Attribute) and n.func.attr in CREATORS]
        if calls:
            found.append(statement)
    return found


def _constructor_of(answer: Answer) -> list[str]:
    """The creating statements of the constructor the notebook writes into the same file
    (the answer's part is a method of that class), as text."""
    target = answer.source.split('\n')[0].split()[1]
    texts = [a.source for a in answers(answer.notebook) if a.is_part and a is not answer
             and a.source.split('\n')[0].split()[1] == target]
    texts += [t for t in given_cells(answer.notebook).values() if t.split()[1] == target]
    found = []
    for text in texts:
        body = textwrap.dedent(text.split('\n', 1)[1])
        try:
            tree = ast.parse(body)
        except SyntaxError:
            continue
        for function in ast.walk(tree):
            if isinstance(function, ast.FunctionDef) and function.name == '__init__':
                found += [ast.unparse(s) for s in _creations(function)]
    return found


def _into_callback(cell: Cell) -> Iterator[Mutant]:
    op = 'call moved into a callback'
    callbacks = _callbacks(cell)
    inits = [m for m in _methods(cell) if m.name == '__init__']
    for callback in callbacks:
        start = _first_statement(callback)
        moving = [s for init in inits for s in _creations(init) if _written_statement(cell, s)]
        for statement in moving:
            yield make(cell.answer, op, f'{_shown(statement)} moved into {callback.name} '
                       f'(line {cell.line(statement) + 1})',
                       _moved(cell, statement, cell.line(start), _indent(cell, start)),
                       affected=frozenset(names_in(statement) | {callback.name}))
        if inits or not cell.answer.is_part:
            continue
        for text in _constructor_of(cell.answer):
            yield make(cell.answer, op, f'{text.splitlines()[0][:50]} written in '
                       f'{callback.name} too', _inserted(cell, start, text),
                       affected=frozenset(names_in(ast.parse(text)) | {callback.name}))


# ------------------------------------------------------------------ a field, a call, an entity
def _wrong_fields(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes(ast.Attribute):
        wrong = WRONG_FIELD.get(node.attr)
        if wrong is None or not isinstance(node.value, (ast.Name, ast.Call)):
            continue
        if isinstance(node.value, ast.Name) and node.value.id == 'self':
            continue
        new = ast.Attribute(node.value, wrong, node.ctx)
        yield _replaced(cell, node, new, 'wrong message field',
                        f'{ast.unparse(node)} -> {ast.unparse(new)}')


def _import_given(answer: Answer, module: str) -> Optional[dict]:
    """The given cell that holds the imports of the answer's file, with ``import module``
    added (``{index: text}``; {} when it imports it already), or None when there is none."""
    target = answer.source.split('\n')[0].split()[1]
    for index, text in given_cells(answer.notebook).items():
        if text.split('\n')[0].split()[1] != target:
            continue
        given = Cell(_given_answer(answer, text))
        imports = [n for n in given.tree.body if isinstance(n, (ast.Import, ast.ImportFrom))]
        if not imports:
            continue
        if any(isinstance(n, ast.Import) and any(a.name == module for a in n.names)
               for n in imports):
            return {}
        first = given.line(imports[0])
        lines = list(given.lines)
        lines[first:first] = [f'import {module}']
        return {index: '\n'.join(lines)}
    return None


def _blocking(cell: Cell) -> Iterator[Mutant]:
    """``time.sleep(1.0)`` at the start of a callback, ``time`` imported with the file's
    other imports."""
    if not cell.answer.is_part:
        return
    given = _import_given(cell.answer, 'time')
    if given is None:
        return
    for callback in _callbacks(cell):
        start = _first_statement(callback)
        yield make(cell.answer, 'blocking call in a callback',
                   f'{BLOCKING} in {callback.name} (line {cell.line(start) + 1})',
                   _inserted(cell, start, BLOCKING), given,
                   frozenset({'time', 'sleep', callback.name}))


def _twice(cell: Cell) -> Iterator[Mutant]:
    """A statement that creates an entity of a node written twice (a callback registered twice
    is none: rclpy asks it twice, the same; nor is a node handed over twice: ros2nb.add
    replaces a node of the same name, as notebook 00 says)."""
    for node in ast.walk(cell.tree):
        for statement in getattr(node, 'body', []) if isinstance(node, (
                ast.FunctionDef, ast.With, ast.Module)) else []:
            calls = [n for n in ast.walk(statement) if isinstance(n, ast.Call)
                     and isinstance(n.func, ast.Attribute) and n.func.attr in CREATORS
                     and n.func.attr not in ('add_on_set_parameters_callback', 'add')]
            if not calls or not _written_statement(cell, statement) or _compound(statement):
                continue
            first, last = _lines(cell, statement)
            lines = list(cell.lines)
            lines[last + 1:last + 1] = cell.lines[first:last + 1]
            yield make(cell.answer, 'entity created twice',
                       f'{_shown(statement)} twice (line {first + 1})', '\n'.join(lines),
                       affected=frozenset(names_in(statement)))


def _keywords(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes(ast.Call):
        for keyword in node.keywords:
            if keyword.arg is None:
                continue
            new = ast.Call(node.func, node.args, [k for k in node.keywords if k is not keyword])
            yield _replaced(cell, node, new, 'keyword left out',
                            f'{ast.unparse(node.func)}: {keyword.arg}= left out')


def _qos_swapped(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes(ast.Attribute):
        other = QOS_SWAPPED.get(node.attr)
        if other is None or not isinstance(node.value, ast.Name) or \
                not node.value.id.endswith('Policy'):
            continue
        new = ast.Attribute(node.value, other, node.ctx)
        yield _replaced(cell, node, new, 'QoS policy swapped',
                        f'{ast.unparse(node)} -> {ast.unparse(new)}')


def _wrong_types(cell: Cell) -> Iterator[Mutant]:
    """A number given as text (``depth='5'``, ``QUEUE_DEPTH`` as ``'10'``), a message's field
    given text (``msg.data = str(...)``), a list of arguments given as one string."""
    op = 'wrong value type'
    named = _constants_of(cell.answer)
    for call in cell.nodes(ast.Call):
        for argument in [*call.args, *(k.value for k in call.keywords)]:
            if isinstance(argument, ast.Constant) and isinstance(argument.value, (int, float)) \
                    and not isinstance(argument.value, bool):
                yield _replaced(cell, argument, ast.Constant(str(argument.value)), op,
                                f'{argument.value} -> {str(argument.value)!r}')
            elif isinstance(argument, ast.Name) and argument.id in named:
                text = str(named[argument.id])
                yield _replaced(cell, argument, ast.Constant(text), op,
                                f'{argument.id} -> {text!r}')
    for node in cell.nodes(ast.Assign):
        target = node.targets[0]
        if isinstance(target, ast.Attribute) and target.attr == 'data':
            for kind in ('str', 'int'):
                new = ast.Assign([target], ast.Call(ast.Name(kind, ast.Load()), [node.value], []))
                new.lineno = node.lineno
                yield _replaced(cell, node, new, op, f'{ast.unparse(target)} = {kind}(...)')
    for node in cell.nodes(ast.Return):
        if isinstance(node.value, ast.List):
            joined = ast.Call(ast.Attribute(ast.Constant(' '), 'join', ast.Load()),
                              [node.value], [])
            yield _replaced(cell, node, ast.Return(joined), op, 'the list returned as one string')
        elif isinstance(node.value, ast.Call) and isinstance(node.value.func, ast.Attribute):
            text = ast.Call(ast.Name('str', ast.Load()), [node.value], [])
            yield _replaced(cell, node, ast.Return(text), op, 'the value returned as text')


def _no_parentheses(cell: Cell) -> Iterator[Mutant]:
    """A class or a method named where it should be called: ``node = TemperatureSensor``,
    ``self.redraw``, ``msg = Float32``."""
    for node in cell.nodes(ast.Call):
        if node.args or node.keywords or ast.unparse(node.func) == 'super':
            continue
        yield _replaced(cell, node, node.func, 'parentheses left out',
                        f'{ast.unparse(node)} -> {ast.unparse(node.func)}')


BEGINNER_OPERATORS: tuple[Callable[[Cell], Iterator[Mutant]], ...] = (
    _moves, _into_callback, _wrong_fields, _blocking, _twice, _keywords, _qos_swapped,
    _wrong_types, _no_parentheses)


# ------------------------------------------------------------------ runs in another order
def _earlier(answer: Answer) -> Optional[tuple[str, str]]:
    """``(what, plan)`` for the cell before the answer it needs: the part before a
    ``%%part`` answer (``'part 3'``), or the set-up cell that binds names the answer's
    functions use (those no other cell before it binds too: a learner who skipped it still
    has them; a name the cell itself needs to run is Python's to report, at once)."""
    if answer.is_part:
        number = int(answer.source.split('\n')[0].split()[2])
        return (f'part {number - 1} not run', f'skip part {number - 1}') if number > 1 \
            else None
    try:
        tree = ast.parse(answer.source)
    except SyntaxError:
        return None
    used = {n.id for f in ast.walk(tree) if isinstance(f, ast.FunctionDef)  # when it is called
            for n in ast.walk(f) if isinstance(n, ast.Name)}
    before = {i: bound_names(t) for i, t in setup_cells(answer.notebook).items()
              if i < answer.index}
    for index in sorted(before, reverse=True):
        others = set().union(*(names for i, names in before.items() if i != index))
        needed = sorted(before[index] & used - bound_names(answer.source) - others)
        if needed:
            return f'the cell binding {", ".join(needed)} not run', f'skip {" ".join(needed)}'
    return None


def _runs(answer: Answer, failing: Optional[Mutant]) -> Iterator[Mutant]:
    yield make(answer, 'cell run twice', 'the answer run twice, then its check',
               answer.source, plan='twice')
    earlier = _earlier(answer)
    if earlier is not None:
        what, plan = earlier
        named = {' '.join(plan.split()[1:])} if plan.startswith('skip part') else \
            set(plan.split()[1:])
        yield make(answer, 'earlier cell not run', what, answer.source, plan=plan,
                   affected=frozenset(named))
    if failing is not None:
        yield make(answer, 'run again after a failed check',
                   f'after {failing.operator}: {failing.what}', answer.source,
                   plan='again', first=failing.source)


def _spread(found: list[Mutant], most: int) -> list[Mutant]:
    """At most ``most`` of ``found``, evenly spread over it (always the same ones)."""
    if len(found) <= most:
        return found
    step = len(found) / most
    return [found[int(i * step)] for i in range(most)]


def mutants(answer: Answer, most: int = PER_OPERATOR) -> list[Mutant]:
    """The mutants of ``answer``: at most ``most`` per operator, the same ones every run,
    none that leaves the cell as it was (but :data:`RUNS`), none twice."""
    if answer.is_ini:
        made = list(_ini_mutants(answer))
    else:
        cell = Cell(answer)
        made = [m for operator in (*PYTHON_OPERATORS, *BEGINNER_OPERATORS) for m in operator(cell)]
    made += [make(answer, 'tutorial mistake', what, text(answer))
             for key, what, text in TUTORIAL if key == answer.key]
    chosen, seen = [], {answer.source + '[]'}
    for operator in OPERATORS:
        if operator in RUNS:
            continue
        of_it = []
        for mutant in made:
            fingerprint = mutant.source + repr(sorted(mutant.given.items()))
            if mutant.operator == operator and fingerprint not in seen and _parses(mutant):
                seen.add(fingerprint)
                of_it.append(mutant)
        chosen += _spread(of_it, most)
    typo = next((m for m in chosen if m.operator == 'name one edit away'), None)
    return chosen + list(_runs(answer, typo))


def _parses(mutant: Mutant) -> bool:
    """Whether the mutant is still Python (a move can leave a block empty): a learner's
    SyntaxError is Python's to explain, not a check's."""
    if mutant.answer.is_ini or mutant.operator in CLASSIC:
        return True
    code = mutant.source.split('\n', 1)[1] if mutant.answer.is_part else mutant.source
    try:
        ast.parse(textwrap.dedent(code))
    except SyntaxError:
        return False
    return True
