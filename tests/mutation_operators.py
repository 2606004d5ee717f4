"""Mutants of the course's answers: each a plausible mistake, made by a fixed operator.

Each operator takes an answer cell (:class:`mutation_cells.Answer`, as :class:`Cell`) and
makes its mutants (:func:`mutation_mistakes.mutants` gathers them with the beginners' ones).
Python answers are rewritten through the standard :mod:`ast`: an operator finds a node among
the lines the learner writes, builds the node the mistake would make, and the cell's text at
that node's position (``lineno``/``col_offset``, as ast gives it) is replaced by
``ast.unparse`` of the new node; everything else in the cell stays as it was.  05's setup.cfg
is rewritten through :mod:`configparser`.  No regular expression touches the text.

Operators (:data:`CLASSIC`): a name one edit away (identifiers, topic and parameter
strings, entry points), ``self.`` dropped or added, positional arguments swapped, a constant
changed, a comparison flipped or loosened, a statement deleted, a ``return`` removed, a local
assigned instead of an attribute, a method called where it should be passed, an import
removed, a wrong message type, a message used for its value (``msg`` for ``msg.data``), an
argument left out, and the tutorial's own mistakes (:mod:`mutation_tutorial`).
"""

from __future__ import annotations

import ast
import configparser
import copy
import dataclasses
import difflib
import textwrap
from dataclasses import dataclass, field
from typing import Callable, Iterator, Optional

from mutation_cells import Answer, answers, given_cells

CLASSIC = ('name one edit away', 'self. dropped', 'self. added', 'arguments swapped',
             'constant changed', 'comparison flipped', 'comparison loosened',
             'statement deleted', 'return removed', 'local, not attribute',
             'method called, not passed', 'import removed', 'wrong message type',
             'message for its value', 'argument left out', 'tutorial mistake')
#: Most mutants of one operator in one answer cell (evenly chosen among those it can make).
PER_OPERATOR = 6
#: The message types a learner confuses: each with the one taken by mistake.
WRONG_TYPE = {'Float32': 'Float64', 'Bool': 'Float32', 'String': 'Float32', 'Float64': 'Float32'}
MESSAGE_MODULE = 'std_msgs.msg'


@dataclass(frozen=True)
class Mutant:
    """One mistake in one answer cell.

    :ivar answer: the answer cell it changes.
    :ivar operator: one of :data:`mutation_mistakes.OPERATORS`.
    :ivar what: the change in a few words, e.g. ``'TOPIC' -> 'TOIC' (line 12)``.
    :ivar source: the mutated cell.
    :ivar changed: the lines (0-based, of ``source``) the mutant changed or added; empty
        when it only removed lines.
    :ivar affected: the names and strings the mutant removed, changed or added: a line of the
        learner's that uses one of them shows the mutant's effect.
    :ivar given: given cells of the notebook the mutant changes too (an import removed from
        part 1), by index, with their new text.
    :ivar plan: how the lab runs the cell, for a run in another order
        (:data:`mutation_mistakes.RUNS`): ``'twice'``, ``'skip part N'`` or ``'skip NAMES'``
        (an earlier cell not run), ``'again'`` (after ``first`` failed its check); empty
        for a mutant of the text.
    :ivar first: the cell run (and checked) before the answer, for ``'again'``.
    """

    answer: Answer
    operator: str
    what: str
    source: str
    changed: tuple[int, ...]
    affected: frozenset[str]
    given: dict = field(default_factory=dict, hash=False, compare=False)
    plan: str = ''
    first: str = ''

    @property
    def ident(self) -> str:
        """A name unique within a run: the answer, the operator and the change."""
        return f'{self.answer.key} | {self.operator} | {self.what}'


# ------------------------------------------------------------------ words
def one_edit(word: str) -> Optional[str]:
    """``word`` with one letter left out, as a typo leaves it (``temperature`` ->
    ``temprature``): the first ``e`` from the fourth letter on, else the middle letter."""
    if len(word) < 3:
        return None
    for index in range(3, len(word) - 1):
        if word[index] in 'eE':
            return word[:index] + word[index + 1:]
    middle = (len(word) - 1) // 2
    return word[:middle] + word[middle + 1:]


def _words(value: str) -> set[str]:
    """The words of a string literal: a topic's, an entry point's parts."""
    for separator in '/:=.':
        value = value.replace(separator, ' ')
    return set(value.split())


def names_in(*nodes: ast.AST) -> set[str]:
    """The identifiers, attributes, keywords and words of string literals in ``nodes``
    (``self`` left out: every method uses it)."""
    found: set[str] = set()
    for root in nodes:
        for node in ast.walk(root):
            if isinstance(node, ast.Name):
                found.add(node.id)
            elif isinstance(node, ast.Attribute):
                found.add(node.attr)
            elif isinstance(node, ast.keyword) and node.arg:
                found.add(node.arg)
            elif isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                found.add(node.name)
            elif isinstance(node, ast.alias):
                found.add((node.asname or node.name).split('.')[0])
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                found |= _words(node.value)
    return found - {'self'}


def _names(text: str) -> set[str]:
    """:func:`names_in` of a piece of Python (nothing for text that is not)."""
    for attempt in (text, text + '\n    pass'):  # a class or def line alone takes a body
        try:
            return names_in(ast.parse(textwrap.dedent(attempt)))
        except SyntaxError:
            continue
    return set()


# ------------------------------------------------------------------ the cell as ast sees it
class Cell:
    """An answer cell's Python, parsed, with ast's positions turned into the cell's."""

    def __init__(self, answer: Answer) -> None:
        self.answer = answer
        self.lines = answer.source.split('\n')
        self.offset = 1 if answer.is_part else 0  # the %%part line
        code = '\n'.join(self.lines[self.offset:])
        dedented = textwrap.dedent(code)
        first = next((line for line in code.split('\n') if line.strip()), '')
        self.pad = len(first) - len(first.lstrip()) if dedented != code else 0
        self.code_lines = dedented.split('\n')
        self.tree = ast.parse(dedented)
        for parent in ast.walk(self.tree):
            for child in ast.iter_child_nodes(parent):
                child.parent = parent

    def line(self, node: ast.AST) -> int:
        """The cell's line (0-based) where ``node`` starts."""
        return node.lineno - 1 + self.offset

    def _column(self, lineno: int, col: int) -> int:
        return len(self.code_lines[lineno - 1].encode()[:col].decode()) + self.pad

    def span(self, node: ast.AST) -> tuple[int, int, int, int]:
        """``node``'s first line, column, last line, end column, in the cell (characters)."""
        return (node.lineno - 1 + self.offset,
                self._column(node.lineno, node.col_offset),
                node.end_lineno - 1 + self.offset,
                self._column(node.end_lineno, node.end_col_offset))

    def written(self, node: ast.AST) -> bool:
        """Whether ``node`` starts on a line the learner writes."""
        return hasattr(node, 'lineno') and self.answer.written(self.line(node))

    def nodes(self, kind: type | tuple[type, ...]) -> list:
        """Every node of ``kind`` the learner writes, in the order of the text."""
        found = [n for n in ast.walk(self.tree) if isinstance(n, kind) and self.written(n)]
        return sorted(found, key=lambda n: (n.lineno, n.col_offset))

    def segment(self, node: ast.AST) -> str:
        first, col, last, end = self.span(node)
        if first == last:
            return self.lines[first][col:end]
        return '\n'.join([self.lines[first][col:], *self.lines[first + 1:last],
                          self.lines[last][:end]])


Edit = tuple[int, int, int, int, str]  # first line, column, last line, end column, new text


def apply(lines: list[str], edits: list[Edit]) -> str:
    """``lines`` with each edit's span replaced by its text (edits may not overlap)."""
    text = list(lines)
    for first, col, last, end, new in sorted(edits, reverse=True):
        joined = text[first][:col] + new + text[last][end:]
        text[first:last + 1] = joined.split('\n')
    return '\n'.join(text)


def make(answer: Answer, operator: str, what: str, new_source: str,
         given: Optional[dict] = None, affected: frozenset[str] = frozenset(), *,
         plan: str = '', first: str = '') -> Mutant:
    """A mutant whose cell is ``new_source``: its changed lines found by difflib."""
    old, new = answer.source.split('\n'), new_source.split('\n')
    changed, removed = [], []
    for tag, i1, i2, j1, j2 in difflib.SequenceMatcher(a=old, b=new, autojunk=False
                                                       ).get_opcodes():
        if tag in ('replace', 'insert'):
            changed.extend(range(j1, j2))
        if tag in ('replace', 'delete'):
            removed.extend(old[i1:i2])
    if not affected:
        added = '\n'.join(new[i] for i in changed)
        affected = frozenset(_names('\n'.join(removed)) ^ _names(added))
    return Mutant(answer, operator, what, new_source, tuple(changed), affected, given or {},
                  plan, first)


def _node_edit(cell: Cell, node: ast.AST, new: ast.AST) -> Edit:
    first, col, last, end = cell.span(node)
    return first, col, last, end, ast.unparse(new)


def _replaced(cell: Cell, node: ast.AST, new: ast.AST, operator: str, what: str,
              extra: tuple[Edit, ...] = ()) -> Mutant:
    """The mutant with ``node`` replaced by ``new``: it affects the names that differ between
    them (both, where they hold the same names: a swap, a flipped comparison)."""
    edits = [_node_edit(cell, node, new), *extra]
    line = cell.line(node) + 1
    old_names, new_names = names_in(node), names_in(new)
    affected = (old_names ^ new_names) or (old_names | new_names)
    return make(cell.answer, operator, f'{what} (line {line})', apply(cell.lines, edits),
                affected=frozenset(affected))


def _first_each(nodes: list, key: Callable) -> list:
    seen, chosen = set(), []
    for node in nodes:
        k = key(node)
        if k is not None and k not in seen:
            seen.add(k)
            chosen.append(node)
    return chosen


# ------------------------------------------------------------------ the operators
def _typos(cell: Cell) -> Iterator[Mutant]:
    op = 'name one edit away'
    strings = {k: v for k, v in _constants_of(cell.answer, str).items()}
    uses = [n for n in cell.nodes(ast.Name) if n.id in strings and isinstance(n.ctx, ast.Load)]
    for node in _first_each(uses, lambda n: n.id):  # the topic written out, misspelt
        for what, new in _string_typos(strings[node.id]):
            yield _replaced(cell, node, ast.Constant(new), op, f'{node.id} as {what}')
    names = _first_each(cell.nodes(ast.Name), lambda n: None if n.id == 'self' else n.id)
    for node in names:
        typo = one_edit(node.id)
        if typo:
            yield _replaced(cell, node, ast.Name(typo, node.ctx), op, f'{node.id} -> {typo}')
    for node in _first_each(cell.nodes(ast.Attribute), lambda n: n.attr):
        typo = one_edit(node.attr)
        if typo:
            new = ast.Attribute(node.value, typo, node.ctx)
            yield _replaced(cell, node, new, op, f'.{node.attr} -> .{typo}')
    for node in _first_each(cell.nodes(ast.keyword), lambda n: n.arg):
        typo = one_edit(node.arg) if node.arg else None
        if typo:
            yield _replaced(cell, node, ast.keyword(typo, node.value), op,
                            f'{node.arg}= -> {typo}=')
    strings = [n for n in cell.nodes(ast.Constant) if isinstance(n.value, str)
               and not isinstance(getattr(n, 'parent', None), (ast.JoinedStr, ast.Expr))]
    for node in _first_each(strings, lambda n: n.value):
        for what, new in _string_typos(node.value):
            yield _replaced(cell, node, ast.Constant(new), op, what)


def _string_typos(value: str) -> Iterator[tuple[str, str]]:
    """A ROS name, a parameter or an entry point one edit away (each of its parts)."""
    name, equals, target = value.partition('=')
    module, colon, function = target.partition(':')
    if equals and colon:  # an entry point: NAME = package.module:function
        for part in (name.strip(), module.strip(), function.strip()):
            typo = one_edit(part.rpartition('.')[2])
            if typo:
                new = value.replace(part, part[:len(part) - len(part.rpartition('.')[2])]
                                    + typo, 1)
                yield f'{value!r}: {part} -> ...{typo}', new
        return
    plain = value.lstrip('/').replace('/', '_').replace('-', '_').replace('_', 'a')
    if plain.isidentifier():
        typo = one_edit(value)
        if typo:
            yield f'{value!r} -> {typo!r}', typo


def _self_dropped(cell: Cell) -> Iterator[Mutant]:
    attributes = [n for n in cell.nodes(ast.Attribute) if isinstance(n.value, ast.Name)
                  and n.value.id == 'self' and isinstance(n.ctx, ast.Load)]
    for node in _first_each(attributes, lambda n: n.attr):
        yield _replaced(cell, node, ast.Name(node.attr, ast.Load()), 'self. dropped',
                        f'self.{node.attr} -> {node.attr}')


def _self_added(cell: Cell) -> Iterator[Mutant]:
    constants = [n for n in cell.nodes(ast.Name) if isinstance(n.ctx, ast.Load)
                 and n.id.isupper() and len(n.id) > 2]
    for node in _first_each(constants, lambda n: n.id):
        yield _replaced(cell, node, ast.Attribute(ast.Name('self', ast.Load()), node.id,
                                                  ast.Load()), 'self. added',
                        f'{node.id} -> self.{node.id}')


def _swapped(cell: Cell) -> Iterator[Mutant]:
    """Neighbouring positional arguments of a call, or items of a list (a command line)."""
    for node in cell.nodes((ast.Call, ast.List)):
        items = node.args if isinstance(node, ast.Call) else node.elts
        for i in range(min(len(items), 3) - 1):
            a, b = items[i], items[i + 1]
            if isinstance(a, ast.Starred) or isinstance(b, ast.Starred) or \
                    ast.unparse(a) == ast.unparse(b):
                continue
            new = copy.copy(node)
            swapped = [*items[:i], b, a, *items[i + 2:]]
            if isinstance(node, ast.Call):
                new.args = swapped
                shown = ast.unparse(node.func)
            else:
                new.elts = swapped
                shown = ''
            yield _replaced(cell, node, new, 'arguments swapped',
                            f'{shown}({ast.unparse(a)} <-> {ast.unparse(b)})')


def changed_value(value: float) -> float:
    """A constant a learner got wrong: a small number doubled (a period of 2 s), a
    temperature one degree off, a unit's factor a thousand times too small (ms for ns), a
    whole number halved (a queue of 10 keeps 5)."""
    if isinstance(value, int):
        return 1 if value == 0 else 2 if value == 1 else value // 2
    if abs(value) >= 1000:
        return value / 1000
    return value * 2 if abs(value) < 2 else value + 1.0


def _constants_of(answer: Answer, kind: type | tuple[type, ...] = (int, float)) -> dict:
    """The notebook's named constants of ``kind`` that the given cells define
    (``PUBLISH_PERIOD_S = 1.0``, ``TOPIC = 'temperature'``)."""
    found: dict = {}
    for text in given_cells(answer.notebook).values():
        body = text.split('\n', 1)[1] if text.startswith('%%') else text
        try:
            tree = ast.parse(textwrap.dedent(body))
        except SyntaxError:
            continue
        for statement in tree.body:
            if isinstance(statement, ast.Assign) and isinstance(statement.value, ast.Constant) \
                    and isinstance(statement.value.value, kind) \
                    and not isinstance(statement.value.value, bool):
                for target in statement.targets:
                    if isinstance(target, ast.Name):
                        found[target.id] = statement.value.value
    return found


def _constants(cell: Cell) -> Iterator[Mutant]:
    numbers = [n for n in cell.nodes(ast.Constant) if isinstance(n.value, (int, float))
               and not isinstance(n.value, bool)]
    for node in numbers:
        new = changed_value(node.value)
        yield _replaced(cell, node, ast.Constant(new), 'constant changed', f'{node.value} -> {new}')
    named = _constants_of(cell.answer)
    uses = [n for n in cell.nodes(ast.Name) if n.id in named and isinstance(n.ctx, ast.Load)]
    for node in _first_each(uses, lambda n: n.id):
        new = changed_value(named[node.id])
        yield _replaced(cell, node, ast.Constant(new), 'constant changed', f'{node.id} -> {new}')


FLIPPED = {ast.Gt: ast.Lt, ast.Lt: ast.Gt, ast.GtE: ast.LtE, ast.LtE: ast.GtE,
           ast.Eq: ast.NotEq, ast.NotEq: ast.Eq}
LOOSENED = {ast.Gt: ast.GtE, ast.Lt: ast.LtE, ast.GtE: ast.Gt, ast.LtE: ast.Lt}


def _comparisons(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes(ast.Compare):
        if len(node.ops) != 1:
            continue
        for operator, table in (('comparison flipped', FLIPPED), ('comparison loosened', LOOSENED)):
            op = table.get(type(node.ops[0]))
            if op is not None:
                new = ast.Compare(node.left, [op()], node.comparators)
                yield _replaced(cell, node, new, operator,
                                f'{ast.unparse(node)} -> {ast.unparse(new)}')


def _blocks(tree: ast.AST) -> Iterator[list[ast.stmt]]:
    for node in ast.walk(tree):
        for name in ('body', 'orelse', 'finalbody'):
            block = getattr(node, name, None)
            if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
                yield block
        if isinstance(node, ast.Try):
            for handler in node.handlers:
                yield handler.body


def _deleted(cell: Cell) -> Iterator[Mutant]:
    for block in _blocks(cell.tree):
        for statement in block:
            if not cell.written(statement) or isinstance(statement, ast.Pass) or (
                    isinstance(statement, ast.Expr) and isinstance(statement.value, ast.Constant)):
                continue
            first, col, last, _end = cell.span(statement)
            if len(block) == 1:  # the block keeps a statement
                indent = cell.lines[first][:col]
                text = apply(cell.lines, [(first, 0, last, len(cell.lines[last]),
                                           indent + 'pass')])
            else:
                text = '\n'.join(cell.lines[:first] + cell.lines[last + 1:])
            shown = ast.unparse(statement).split('\n')[0][:60]
            returned = {'return'} if isinstance(statement, ast.Return) else set()
            yield make(cell.answer, 'statement deleted', f'{shown} (line {first + 1})', text,
                       affected=frozenset(names_in(statement) | returned))


def _returns(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes(ast.Return):
        if node.value is not None:
            found = _replaced(cell, node, ast.Expr(node.value), 'return removed',
                              f'return {ast.unparse(node.value)[:40]}')
            yield dataclasses.replace(found, affected=found.affected | {'return'})


def _locals(cell: Cell) -> Iterator[Mutant]:
    for node in cell.nodes((ast.Assign, ast.AugAssign, ast.AnnAssign)):
        target = node.targets[0] if isinstance(node, ast.Assign) else node.target
        if isinstance(target, ast.Attribute) and isinstance(target.value, ast.Name) \
                and target.value.id == 'self':
            yield _replaced(cell, target, ast.Name(target.attr, ast.Store()),
                            'local, not attribute', f'self.{target.attr} = -> {target.attr} =')


def _methods_of(answer: Answer) -> set[str]:
    """Functions and methods the notebook's code defines (given cells and its answers)."""
    found = set()
    for text in [*given_cells(answer.notebook).values(),
                 *(a.source for a in answers(answer.notebook))]:
        body = text.split('\n', 1)[1] if text.startswith('%%') else text
        try:
            tree = ast.parse(textwrap.dedent(body))
        except SyntaxError:
            continue
        found.update(n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef))
    return found


def _called(cell: Cell) -> Iterator[Mutant]:
    methods = _methods_of(cell.answer)
    for call in cell.nodes(ast.Call):
        for argument in [*call.args, *(k.value for k in call.keywords)]:
            name = argument.attr if isinstance(argument, ast.Attribute) else \
                argument.id if isinstance(argument, ast.Name) else None
            if name in methods:
                yield _replaced(cell, argument, ast.Call(argument, [], []),
                                'method called, not passed',
                                f'{ast.unparse(argument)} -> {ast.unparse(argument)}()')


def _imports(cell: Cell) -> Iterator[Mutant]:
    op = 'import removed'
    for node in ast.walk(cell.tree):  # the cell's own imports, written or given
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            first, _col, last, _end = cell.span(node)
            text = '\n'.join(cell.lines[:first] + cell.lines[last + 1:])
            yield make(cell.answer, op, f'{ast.unparse(node)} (line {first + 1})', text,
                       affected=frozenset(names_in(node)))
    if not cell.answer.is_part:
        return
    used = {n.id for n in cell.nodes(ast.Name)}
    target = cell.lines[0].split()[1]
    for index, text in given_cells(cell.answer.notebook).items():
        if text.split('\n')[0].split()[1] != target:
            continue
        given = Cell(_given_answer(cell.answer, text))
        for node in ast.walk(given.tree):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            for alias in node.names:
                name = (alias.asname or alias.name).split('.')[0]
                if name not in used:
                    continue
                kept = [a for a in node.names if a is not alias]
                new = copy.copy(node)
                new.names = kept
                first, col, last, end = given.span(node)
                replaced = apply(given.lines, [(first, col, last, end,
                                                ast.unparse(new) if kept else '')])
                yield make(cell.answer, op, f'{name} no longer imported in part '
                           f'{text.split()[2]}', cell.answer.source, {index: replaced},
                           frozenset({name}))


def _given_answer(answer: Answer, text: str) -> Answer:
    """A given cell dressed as an answer, every line of it written (for :class:`Cell`)."""
    return Answer(answer.notebook, -1, '', text, ((0, len(text.split('\n'))),), -1, '', '')


def _wrong_types(cell: Cell) -> Iterator[Mutant]:
    """A message type swapped for another, imported where the learner imports: in the file's
    first part (a ``%%part`` answer), else at the top of the cell."""
    for node in cell.nodes(ast.Name):
        wrong = WRONG_TYPE.get(node.id)
        if wrong is None or not isinstance(node.ctx, ast.Load):
            continue
        what = f'{node.id} -> {wrong} (line {cell.line(node) + 1})'
        changed = apply(cell.lines, [_node_edit(cell, node, ast.Name(wrong, ast.Load()))])
        affected = frozenset({node.id, wrong})
        if not cell.answer.is_part:
            line = f'from {MESSAGE_MODULE} import {wrong}'
            yield make(cell.answer, 'wrong message type', what, f'{line}\n{changed}',
                       affected=affected)
            continue
        given = _imported_in_part_one(cell.answer, wrong)
        if given is not None:
            yield make(cell.answer, 'wrong message type', what, changed, given, affected)


def _imported_in_part_one(answer: Answer, name: str) -> Optional[dict]:
    """The given cell that holds the imports of the answer's file, with ``name`` imported
    from std_msgs.msg too (``{index: text}``; {} when it imports it already), or None when
    there is none."""
    target = answer.source.split('\n')[0].split()[1]
    for index, text in given_cells(answer.notebook).items():
        if text.split('\n')[0].split()[1] != target:
            continue
        given = Cell(_given_answer(answer, text))
        for node in ast.walk(given.tree):
            if isinstance(node, ast.ImportFrom) and node.module == MESSAGE_MODULE:
                if any(alias.name == name for alias in node.names):
                    return {}
                new = copy.copy(node)
                new.names = [*node.names, ast.alias(name)]
                return {index: apply(given.lines, [_node_edit(given, node, new)])}
    return None


def _messages_for_values(cell: Cell) -> Iterator[Mutant]:
    """``msg`` where ``msg.data`` is meant: the message used as the number it carries."""
    fields = [n for n in cell.nodes(ast.Attribute) if n.attr == 'data'
              and isinstance(n.ctx, ast.Load) and isinstance(n.value, (ast.Name, ast.Call))]
    for node in fields:
        yield _replaced(cell, node, node.value, 'message for its value',
                        f'{ast.unparse(node)} -> {ast.unparse(node.value)}')


def _left_out(cell: Cell) -> Iterator[Mutant]:
    """A call given fewer arguments: its last left out, or all but its first."""
    for node in cell.nodes(ast.Call):
        if len(node.args) < 2 or any(isinstance(a, ast.Starred) for a in node.args):
            continue
        for kept in sorted({len(node.args) - 1, 1}, reverse=True):
            new = copy.copy(node)
            new.args = node.args[:kept]
            new.keywords = node.keywords if kept > 1 else []
            yield _replaced(cell, node, new, 'argument left out',
                            f'{ast.unparse(node.func)}: {len(node.args)} arguments -> {kept}')


PYTHON_OPERATORS: tuple[Callable[[Cell], Iterator[Mutant]], ...] = (
    _typos, _self_dropped, _self_added, _swapped, _constants, _comparisons, _deleted,
    _returns, _locals, _called, _imports, _wrong_types, _messages_for_values, _left_out)


# ------------------------------------------------------------------ 05's setup.cfg
def _ini_text(parser: configparser.ConfigParser) -> str:
    lines = []
    for section in parser.sections():
        lines.append(f'[{section}]')
        lines.extend(f'{key}={value}' for key, value in parser[section].items())
    return '\n'.join(lines)


def _ini_mutants(answer: Answer) -> Iterator[Mutant]:
    first, *body = answer.source.split('\n')
    parser = configparser.ConfigParser(interpolation=None, delimiters=('=',))
    parser.optionxform = str
    parser.read_string('\n'.join(body))

    def variant(change: Callable[[configparser.ConfigParser], None]) -> str:
        copied = configparser.ConfigParser(interpolation=None, delimiters=('=',))
        copied.optionxform = str
        copied.read_dict(parser)
        change(copied)
        return first + '\n' + _ini_text(copied)

    def renamed_section(old: str, new: str) -> Callable[[configparser.ConfigParser], None]:
        def change(p: configparser.ConfigParser) -> None:
            items = dict(p[old])
            p.remove_section(old)
            p[new] = items
        return change

    def renamed_key(section: str, old: str, new: str) -> Callable[..., None]:
        def change(p: configparser.ConfigParser) -> None:
            value = p[section].pop(old)
            p[section][new] = value
        return change

    def set_value(section: str, key: str, value: str) -> Callable[..., None]:
        return lambda p: p[section].__setitem__(key, value)

    for section in parser.sections():
        typo = one_edit(section)
        yield make(answer, 'name one edit away', f'[{section}] -> [{typo}]',
                   variant(renamed_section(section, typo)))
        yield make(answer, 'statement deleted', f'[{section}] and its line',
                   variant(lambda p, s=section: p.remove_section(s)))
        for key, value in parser[section].items():
            yield make(answer, 'name one edit away', f'{key} -> {one_edit(key)}',
                       variant(renamed_key(section, key, one_edit(key))))
            yield make(answer, 'statement deleted', f'{key}={value}',
                       variant(lambda p, s=section, k=key: p.remove_option(s, k)))
            folder = value.rsplit('/', 1)
            yield make(answer, 'name one edit away', f'{value} -> .../{one_edit(folder[1])}',
                       variant(set_value(section, key, f'{folder[0]}/{one_edit(folder[1])}')))
            yield make(answer, 'constant changed', f'{key}: $base/lib -> $base/bin',
                       variant(set_value(section, key, value.replace('/lib/', '/bin/'))))
            yield make(answer, 'tutorial mistake', f'{key} with dashes (the older template)',
                       variant(renamed_key(section, key, key.replace('_', '-'))))
