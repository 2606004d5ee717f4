"""Where a learner's name came from: the name meant, the import left out, the line that set it.

Part of :mod:`ros2nb.explain`, for :mod:`.everyday`: what a learner's error needs looked up
besides its message: the names visible where it was raised (a typo away, but not a mere
change of case), the module that defines a name they did not import, and, through
:mod:`dis`, the line of theirs that stored a name or declared a parameter.
"""

from __future__ import annotations

import builtins
import difflib
import dis
import linecache
import re
import sys
from pathlib import Path
from types import CodeType
from typing import Any, Iterator, Optional

from .frames import is_library_file, learner_entry, learner_frame

#: Names a learner uses without importing them, by the import that brings each.
IMPORTS = {name: f'from std_msgs.msg import {name}' for name in
           ('Float32', 'Float64', 'Bool', 'String', 'Int32', 'Int64')}
IMPORTS.update({'Node': 'from rclpy.node import Node', 'rclpy': 'import rclpy',
                'random': 'import random', 'Path': 'from pathlib import Path',
                'ExternalShutdownException':
                    'from rclpy.executors import ExternalShutdownException'})


def similar(name: str, candidates: Any) -> Optional[str]:
    """The candidate ``name`` was most likely meant to be (a typo away), or None; never one
    that differs only in case (``node`` is no typo of ``Node``, ``Bool`` none of ``bool``),
    nor one IPython keeps in a kernel's namespace for itself (``Out``, ``_i3``, ``exit``):
    a grader's run of the same code has none of those."""
    hidden = _kernels_own()
    names = sorted({c for c in candidates if isinstance(c, str) and not c.startswith('__')
                    and c.lower() != name.lower() and c not in hidden
                    and (not c.startswith('_') or name.startswith('_'))})
    near = [c for c in names if len(name) > 2 and one_edit_apart(name, c)]  # msg, mgs
    found = near or difflib.get_close_matches(name, names, n=1, cutoff=0.75)
    return found[0] if found else None


def _kernels_own() -> Any:
    """The names IPython put into its kernel's namespace (none outside IPython)."""
    shell = getattr(sys.modules.get('IPython'), 'get_ipython', lambda: None)()
    return getattr(shell, 'user_ns_hidden', {})


#: Shortest name a builtin is offered for: one letter off a shorter name (``ags``) is as
#: near to ``abs`` as to anything the learner meant.
_BUILTIN_SLIP_LETTERS = 4


def builtin_meant(name: str) -> Optional[str]:
    """The one builtin ``name`` is a slip of (``KeyboardIntrrupt``, ``supr``), or None: a
    name of four letters or more, one edit from exactly one builtin.  A name further off
    (``args`` from ``vars``) or shorter gets none: no suggestion is better than one the
    learner never meant, and that the course does not use."""
    if len(name) < _BUILTIN_SLIP_LETTERS:
        return None
    found = [b for b in vars(builtins) if not b.startswith('_')
             and b.lower() != name.lower() and one_edit_apart(name, b)]
    return found[0] if len(found) == 1 else None


def one_edit_apart(a: str, b: str) -> bool:
    """Whether ``b`` is ``a`` with one letter left out, added, changed, or two swapped."""
    if a == b or abs(len(a) - len(b)) > 1:
        return False
    if len(a) == len(b):
        differ = [i for i in range(len(a)) if a[i] != b[i]]
        return len(differ) == 1 or (len(differ) == 2 and differ[1] == differ[0] + 1
                                    and a[differ[0]] == b[differ[1]]
                                    and a[differ[1]] == b[differ[0]])
    short, long_ = sorted((a, b), key=len)
    return any(long_[:i] + long_[i + 1:] == short for i in range(len(long_)))


#: Where an import the learner left out is looked for, in this order (what the course uses).
_PACKAGES = ('std_msgs.msg', 'rclpy', 'rcl_interfaces.msg', 'pathlib', 'random')


def import_of(name: str) -> Optional[str]:
    """``from MODULE import name`` for a name a module of the course's packages defines
    (the shortest public module among those loaded), or None."""
    if name in IMPORTS:
        return IMPORTS[name]
    found = sorted((module_name for module_name, module in list(sys.modules.items())
                    if module_name.startswith(_PACKAGES) and '._' not in module_name
                    and isinstance(getattr(module, name, None), type)), key=len)
    if not found:
        return None
    defined = getattr(sys.modules[found[0]], name).__module__  # where the class is written
    return f'from {defined if defined in found else found[0]} import {name}'


def place(code: CodeType, line: int) -> str:
    """``FILE line N: source`` of a line of the learner's (``cell line N`` for a cell)."""
    name = Path(code.co_filename)
    place = name.name if name.is_file() and 'ipykernel' not in code.co_filename else 'cell'
    return f'{place} line {line}: {linecache.getline(code.co_filename, line).strip()}'


def learners_functions(cls: type) -> Iterator[CodeType]:
    """The code of every method the learner wrote in ``cls`` and its bases (not ROS's)."""
    for klass in cls.__mro__:
        for value in vars(klass).values():
            code = getattr(getattr(value, '__func__', value), '__code__', None)
            if isinstance(code, CodeType) and not is_library_file(code.co_filename):
                yield code


def stored_near(code: CodeType, name: str) -> Optional[tuple[str, int]]:
    """``(other, line)``: a name one edit from ``name`` that ``code`` sets (a local, or a
    name of the cell or file), and the line that sets it, or None: the learner's own
    spelling of the name where it is set."""
    line = None
    for instruction in dis.get_instructions(code):
        if instruction.starts_line is not None:
            line = instruction.starts_line
        if instruction.opname in ('STORE_FAST', 'STORE_NAME', 'STORE_GLOBAL') and \
                isinstance(instruction.argval, str) and line is not None and \
                one_edit_apart(name, instruction.argval):
            return instruction.argval, line
    return None


def _source_of(code: CodeType) -> str:
    """The text of the file or cell ``code`` was compiled from ('' when it is gone)."""
    return ''.join(linecache.getlines(code.co_filename))


def set_at_top(code: CodeType, name: str) -> Optional[tuple[str, int]]:
    """``(other, line)``: a name one edit from ``name`` that the top level of the file or
    cell ``code`` was written in sets (a constant, an import, a class), and the line that
    sets it, or None: where a name a function reads was set under another spelling."""
    source = _source_of(code)
    try:
        module = compile(source, code.co_filename, 'exec', dont_inherit=True)
    except (SyntaxError, ValueError):  # a file changed since, or no source at all
        return None
    return stored_near(module, name)


def unread_parameter(code: CodeType, name: str) -> Optional[str]:
    """The one parameter of the function ``code`` that it never reads (not ``self``), when
    it is a slip of ``name`` or shares a word with it, or None: a parameter named otherwise
    than the name its body reads (``def f(xml)``, then ``package_xml``; ``def main(ags)``,
    then ``args``).  A callback's ``msg`` it ignores is no other name's."""
    count = code.co_argcount + code.co_kwonlyargcount
    read = set(code.co_cellvars)  # read in a comprehension or a function inside
    for instruction in dis.get_instructions(code):
        if instruction.opname.startswith('LOAD_FAST'):
            value = instruction.argval
            read.update(value if isinstance(value, tuple) else (value,))
    unread = [p for p in code.co_varnames[:count] if p not in read and p not in ('self', 'cls')]
    if len(unread) != 1:
        return None
    shared = set(unread[0].split('_')) & set(name.split('_')) - {''}
    return unread[0] if shared or one_edit_apart(unread[0], name) else None


def written_more(code: CodeType, one: str, other: str) -> bool:
    """Whether the file or cell ``code`` was written in spells ``one`` more often than
    ``other`` (comments included: the course's comments name its constants)."""
    source = _source_of(code)

    def count(word: str) -> int:
        return len(re.findall(rf'(?<![\w.]){re.escape(word)}(?!\w)', source))
    return count(one) > count(other)


def stored(code: CodeType, name: str, opname: str) -> Optional[int]:
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
        line = stored(frame.f_code, name, 'STORE_FAST') if value is obj else None
        if line is not None:
            return f' ({place(frame.f_code, line)})'
    return ''


def declared(code: CodeType, name: str) -> Optional[int]:
    """The line where ``code`` calls ``declare_parameter`` with ``name``, or None."""
    line, method = None, False
    for instruction in dis.get_instructions(code):
        if instruction.starts_line is not None:
            line, method = instruction.starts_line, False
        if instruction.argval == 'declare_parameter':
            method = True
        elif method and instruction.opname == 'LOAD_CONST' and instruction.argval == name:
            return line
    return None


def raising_text(exc: BaseException) -> str:
    """The source of the learner's lines that the instruction raising ``exc`` spans (one
    line of a statement that runs over several: the f-string's line, not the call's first)."""
    entry = learner_entry(exc)
    if entry is None:
        return ''
    code = entry.tb_frame.f_code
    positions = list(code.co_positions())
    first, last = positions[entry.tb_lasti // 2][:2] if entry.tb_lasti // 2 < len(
        positions) else (entry.tb_lineno, entry.tb_lineno)
    first, last = first or entry.tb_lineno, last or first or entry.tb_lineno
    return ''.join(linecache.getline(code.co_filename, line) for line in range(first, last + 1))

