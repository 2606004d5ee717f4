"""What a node file of the learner's leaves unwritten, read (never run) with Python's ``ast``.

Notebooks 04 to 10 import, build or run the sensor and the monitor the learner wrote in 03,
04 and 08.  :func:`missing` reads such a file and finds the parts a later notebook uses
that are not there yet: the course's class, a method its class uses
(``self.on_set_thresholds``), a parameter it reads but never declares, ``main()``, or one of
them still nbgrader's placeholder.  Only names the caller knows count (the course's
table of where each part is written, :data:`ros2nb.course.WRITTEN_IN`): a helper of the
learner's own is never called missing.  The one line that says where to write each part
is :func:`ros2nb.course.unfinished_line`.

Introduced in ``04-write-the-subscriber.ipynb`` (the first notebook that uses an earlier one's
file).  No ROS import, no import of ros2nb.
"""

from __future__ import annotations

import ast
from typing import Collection, Iterator, Optional

_PLACEHOLDER = 'NotImplementedError'


def _self_uses(cls: ast.ClassDef) -> tuple[set[str], set[str]]:
    """The ``self.NAME`` a class reads, and those it assigns, anywhere in its methods."""
    read: set[str] = set()
    assigned: set[str] = set()
    for node in ast.walk(cls):
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id == 'self':
            (assigned if isinstance(node.ctx, ast.Store) else read).add(node.attr)
    return read, assigned


def _parameters(cls: ast.ClassDef, method: str) -> Optional[set[str]]:
    """The parameter names a class passes as a string to ``.<method>(...)``; None when one
    call names its parameter otherwise (a variable, ``declare_parameters``, parameters
    declared from the command line): then nothing is known for sure."""
    found: set[str] = set()
    for node in ast.walk(cls):
        if isinstance(node, ast.keyword) and node.arg and node.arg.startswith('automatically'):
            return None
        if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
            continue
        if node.func.attr == method + 's':
            return None
        if node.func.attr == method:
            first = node.args[0] if node.args else None
            if not (isinstance(first, ast.Constant) and isinstance(first.value, str)):
                return None
            found.add(first.value)
    return found


def _placeholder(function: ast.AST) -> bool:
    """Whether a function's body raises nbgrader's placeholder ``NotImplementedError``."""
    for node in ast.walk(function):
        if isinstance(node, ast.Raise) and node.exc is not None:
            raised = node.exc.func if isinstance(node.exc, ast.Call) else node.exc
            if isinstance(raised, ast.Name) and raised.id == _PLACEHOLDER:
                return True
    return False


def missing(text: str, class_name: str, known: Collection[str], programs: bool = False
            ) -> list[tuple[tuple[str, ...], str]]:
    """Each part of a node file that a later notebook uses and that is not written yet.

    :param text: the file's text.
    :param class_name: the course's node class in it (``TemperatureMonitor``).
    :param known: the names of its parts (methods, ``main``, parameters): only these count.
    :param programs: whether ``main()`` is used (the file runs as a program).
    :return: (the parts' names, how they are missing: ``'on_set_thresholds, which
        TemperatureMonitor uses'``), one item per way of missing; empty when nothing is.
    :raises SyntaxError: when the file cannot be read as Python.
    """
    return list(_missing(ast.parse(text), class_name, set(known), programs))


def _missing(tree: ast.Module, class_name: str, where: set[str], programs: bool
             ) -> Iterator[tuple[tuple[str, ...], str]]:
    functions = {n.name: n for n in tree.body if isinstance(n, ast.FunctionDef)}
    classes = {n.name: n for n in tree.body if isinstance(n, ast.ClassDef)}
    cls = classes.get(class_name)
    if cls is None:
        yield (class_name,), f'the class {class_name}'
    else:
        methods = {n.name: n for n in cls.body if isinstance(n, ast.FunctionDef)}
        read, assigned = _self_uses(cls)
        used = [name for name in sorted(read - assigned - set(methods)) if name in where]
        if used:
            yield tuple(used), f'{" and ".join(used)}, which {cls.name} uses'
        held = [name for name, method in methods.items() if name in where and _placeholder(method)]
        if held:
            yield tuple(held), f'{" and ".join(held)}, still the placeholder'
        declared = _parameters(cls, 'declare_parameter')
        read_ones = _parameters(cls, 'get_parameter') if declared is not None else None
        undeclared = [n for n in sorted((read_ones or set()) - (declared or set())) if n in where]
        if undeclared:
            yield tuple(undeclared), (f'the declaration of {" and ".join(undeclared)}, which '
                                      f'{cls.name} reads')
    if programs and 'main' not in functions:
        yield ('main',), 'main()'
    elif programs and _placeholder(functions['main']):
        yield ('main',), 'main(), still the placeholder'


