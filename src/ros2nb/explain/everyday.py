"""One line for Python's everyday errors in the learner's code: the name they meant, the
attribute never set on the node, the argument a class does not take.

Part of :mod:`ros2nb.explain`; what a check says when the learner's code raised an error no
other explanation knows (:func:`~ros2nb.explain.exceptions.describe_error`): the error,
what it means here and what to do, where a traceback would have shown the learner's frames.
Runs wherever a check runs learner code: the kernel (a check of the learner's objects) and a
judge's subject.  Introduced in ``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import builtins
import difflib
import dis
import linecache
import re
from pathlib import Path
from types import CodeType, FrameType
from typing import Any, Iterator, Optional

from .frames import frames_of, is_library_file, learner_frame

#: Names a learner uses without importing them, by the import that brings each.
IMPORTS = {name: f'from std_msgs.msg import {name}' for name in
           ('Float32', 'Float64', 'Bool', 'String', 'Int32', 'Int64')}
IMPORTS.update({'Node': 'from rclpy.node import Node', 'rclpy': 'import rclpy',
                'random': 'import random', 'Path': 'from pathlib import Path',
                'ExternalShutdownException':
                    'from rclpy.executors import ExternalShutdownException'})
_CONSTRUCTOR_ARGUMENTS = re.compile(r'Invalid arguments passed to constructor: '
                                    r'dict_keys\(\[(?P<names>[^\]]*)\]\)')


def _similar(name: str, candidates: Any) -> Optional[str]:
    """The candidate ``name`` was most likely meant to be (a typo away), or None."""
    names = sorted({c for c in candidates if isinstance(c, str) and not c.startswith('__')})
    found = difflib.get_close_matches(name, names, n=1, cutoff=0.75)
    return found[0] if found else None


def _first_line(exc: BaseException) -> str:
    return (str(exc).splitlines() or [''])[0][:200]


def _place(code: CodeType, line: int) -> str:
    """``FILE line N: source`` of a line of the learner's (``cell line N`` for a cell)."""
    name = Path(code.co_filename)
    place = name.name if name.is_file() and 'ipykernel' not in code.co_filename else 'cell'
    return f'{place} line {line}: {linecache.getline(code.co_filename, line).strip()}'


def _learners_functions(cls: type) -> Iterator[CodeType]:
    """The code of every method the learner wrote in ``cls`` and its bases (not ROS's)."""
    for klass in cls.__mro__:
        for value in vars(klass).values():
            code = getattr(getattr(value, '__func__', value), '__code__', None)
            if isinstance(code, CodeType) and not is_library_file(code.co_filename):
                yield code


def _stored(code: CodeType, name: str, opname: str) -> Optional[int]:
    """The line where ``code`` stores ``name`` with ``opname`` (STORE_FAST: a local;
    STORE_ATTR: an attribute), or None."""
    line = None
    for instruction in dis.get_instructions(code):
        if instruction.starts_line is not None:
            line = instruction.starts_line
        if instruction.opname == opname and instruction.argval == name:
            return line
    return None


def made_where(exc: BaseException, obj: Any) -> str:
    """`` (FILE line N: name = ...)``: where the learner's code put ``obj`` in the local name
    it goes by where ``exc`` was raised (a message made of the wrong type), or ''."""
    frame = learner_frame(exc)
    if frame is None:
        return ''
    for name, value in frame.f_locals.items():
        line = _stored(frame.f_code, name, 'STORE_FAST') if value is obj else None
        if line is not None:
            return f' ({_place(frame.f_code, line)})'
    return ''


def _unset_attribute(obj: Any, name: str, owner: str) -> Optional[str]:
    """``self.name`` read on the learner's node, where no method of theirs sets it as an
    attribute: a local of that name (``temperature = ...``), or nothing at all."""
    methods = list(_learners_functions(type(obj)))
    if not methods:
        return None
    for code in methods:
        line = _stored(code, name, 'STORE_FAST')
        if line is not None:
            return (f'{owner} has no attribute {name}: {code.co_name} sets a local name '
                    f'{name} ({_place(code, line)}), which is gone when it returns: write '
                    f'self.{name} = ... there, so that the node keeps it.')
    if any(_stored(code, name, 'STORE_ATTR') for code in methods):
        return (f'{owner} has no attribute {name} yet: it is read before any method sets it: '
                f'set self.{name} in __init__.')
    meant = _similar(name, dir(obj))
    if meant:
        return (f'{owner} has no attribute {name}: did you mean self.{meant}? Names must '
                'match exactly where they are set and where they are used.')
    return (f'{owner} has no attribute {name}: the class neither defines a method {name} nor '
            f'sets self.{name} in __init__: write it, or use the name the class has.')


def _attribute(exc: AttributeError) -> Optional[str]:
    name, obj = getattr(exc, 'name', None), getattr(exc, 'obj', None)
    if not name or obj is None:
        return None
    owner = obj.__name__ if isinstance(obj, type) or hasattr(obj, '__file__') and hasattr(
        obj, '__name__') else type(obj).__name__
    if not isinstance(obj, type) and not hasattr(obj, '__file__'):
        unset = _unset_attribute(obj, name, owner)
        if unset:
            return unset
    meant = _similar(name, dir(obj))
    if meant:
        return f"{owner} has no attribute {name}: did you mean {meant}? Names must match exactly."
    return f'{owner} has no attribute {name}: check the name against what {owner} offers.'


def _name(exc: NameError, frame: FrameType) -> str:
    name = getattr(exc, 'name', None)
    if not name:
        quoted = re.match(r"name '(\w+)'", _first_line(exc))
        name = quoted.group(1) if quoted else '?'
    visible = {*frame.f_locals, *frame.f_globals, *vars(builtins)}
    meant = _similar(name, visible)
    if meant:
        return (f"name '{name}' is not defined: did you mean {meant}? Names must match "
                'exactly.')
    if name in IMPORTS:
        return (f"name '{name}' is not defined: import it at the top of the file (or cell), "
                f'{IMPORTS[name]}.')
    return (f"name '{name}' is not defined where this line runs: define it (or import it) "
            'before, or check its spelling.')


def _constructor_arguments(exc: AssertionError) -> Optional[str]:
    """rclpy's and the messages' ``Invalid arguments passed to constructor``: which argument
    the class does not take, and the one meant."""
    found = _CONSTRUCTOR_ARGUMENTS.search(str(exc))
    frames = list(frames_of(exc))
    made = frames[-1].f_locals.get('self') if frames else None
    if not found or made is None:
        return None
    takes = [slot.lstrip('_') for slot in getattr(type(made), '__slots__', ())]
    given = [name.strip(" '") for name in found['names'].split(',')]
    unknown = [name for name in given if name not in takes]
    if not unknown:
        return None
    cls = type(made).__name__
    meant = _similar(unknown[0], takes)
    hint = f': did you mean {meant}?' if meant else ''
    return (f'{cls}() takes no argument {unknown[0]}{hint} (it takes '
            f'{", ".join(t for t in takes if not t.startswith("check"))}).')


def everyday_explanation(exc: BaseException) -> Optional[str]:
    """The line for an error of Python's own that the learner's code raised, with what to do,
    or None when it is not theirs to fix: no frame of the error is the learner's, and it is
    no attribute missing on an object of a class of theirs (the course's code standing in
    for a part reads what their constructor should have set)."""
    frame = learner_frame(exc)
    if isinstance(exc, AttributeError):
        obj = getattr(exc, 'obj', None)
        if frame is not None or any(True for _ in _learners_functions(type(obj))):
            found = _attribute(exc)
            if found:
                return found
    if frame is None:
        return None
    text = _first_line(exc)
    if isinstance(exc, NameError) and not isinstance(exc, UnboundLocalError):
        return _name(exc, frame)
    if isinstance(exc, AssertionError):
        found = _constructor_arguments(exc)
        if found:
            return found
    if isinstance(exc, KeyError):
        return (f'KeyError: {text}: the line reads a key that is not there: check its '
                'spelling, or read it with .get(key, default).')
    return f'{type(exc).__name__}: {text}: this line of yours raised it; fix it, then check again.'
