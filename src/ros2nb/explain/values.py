"""One line for a value of the wrong kind in the learner's code: what holds it, and where.

Part of :mod:`ros2nb.explain`, for :mod:`.everyday`: Python refused two values an operator
cannot take together (a number written in quotes, ``'28.0' < 27.9``), or formatted as a
number what is none (a list of the node's filled with ``Time`` objects, or with a method
not called): the line names the value, the name that holds it and, where the learner's
code filled a list of the node's, the line that did.  Introduced in
``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import dis
import linecache
import re
from types import CodeType, FrameType
from typing import Optional

from .names import learners_functions, place, raising_text

#: Python's refusal of two values an operator cannot take together.
_OPERANDS = re.compile(r"(?:not supported between instances of|unsupported operand type\(s\) "
                       r"for \S+:) '(\w+)' and '(\w+)'")
#: Python's refusal of a value of the wrong kind where a number was formatted or counted with.
_WRONG_KIND = re.compile(r"^unsupported format string passed to (\w+)\.__format__|"
                         r"unsupported operand type\(s\) for \S+: '(\w+)' and|"
                         r"and '(\w+)'$")


def _first_line(exc: BaseException) -> str:
    return (str(exc).splitlines() or [''])[0][:200]


def operands(exc: BaseException, text: str, frame: FrameType, kinds: set[str]) -> str:
    """``low_c >= high_c`` with a str on one side: which names on the line hold what."""
    line = raising_text(exc) or linecache.getline(frame.f_code.co_filename, frame.f_lineno)
    quoted = re.search(r"""(['"])(-?\d+(?:\.\d+)?)\1""", line) if 'str' in kinds else None
    if quoted:  # a number written in quotes is text
        return (f'TypeError: {text}: {quoted.group(0)} is text, not a number: write '
                f'{quoted.group(2)} without the quotes.')
    held = [f'{name} is {value!r}' if isinstance(value, str) else
            f'{name} is a {type(value).__name__}'
            for name, value in frame.f_locals.items()
            if re.search(rf'\b{name}\b', line) and type(value).__name__ in kinds
            and len(repr(value)) <= 40]
    shown = f': here {", ".join(held)}' if held else ''
    return (f'TypeError: {text}{shown}: find where the value of the wrong kind comes from, '
            'and give the line two values it can take together.')


def filled_wrongly(exc: BaseException, frame: FrameType
                   ) -> Optional[tuple[str, int, str, str]]:
    """``(attribute, line, explanation, place)``: a list of the node's (``self.times_s``)
    whose last item is of the kind Python refused, where a number belongs (a Time, a method
    not called), with the learner's line that appends to it (``FILE line N: source``); or
    None."""
    found = _WRONG_KIND.search(_first_line(exc))
    owner = frame.f_locals.get('self')
    if found is None or owner is None:
        return None
    kind = next(k for k in found.groups() if k)
    for name, value in vars(owner).items():
        if isinstance(value, list) and value and type(value[-1]).__name__ == kind:
            appended = [(code, line) for code in learners_functions(type(owner))
                        for line in [_appends_to(code, name)] if line is not None]
            if not appended:
                continue
            code, line = appended[0]
            fix = {'Time': "append the time's seconds (its nanoseconds / 1e9), not the Time",
                   'method': 'call the method where you append (with its parentheses)',
                   'builtin_function_or_method': 'call the method where you append (with its '
                                                 'parentheses)'}.get(kind, 'append a number')
            return name, line, (f'self.{name} holds a {kind} where a number belongs: {fix}.'), \
                place(code, line)
    return None


def _appends_to(code: CodeType, name: str) -> Optional[int]:
    """The line where ``code`` calls ``self.<name>.append``, or None."""
    line, previous = None, None
    for instruction in dis.get_instructions(code):
        if instruction.starts_line is not None:
            line = instruction.starts_line
        if instruction.argval == 'append' and previous == name:
            return line
        previous = instruction.argval
    return None


def wrong_kind(exc: BaseException, frame: FrameType) -> Optional[str]:
    """The line for a TypeError of a value of the wrong kind, or None."""
    filled = filled_wrongly(exc, frame)
    if filled:
        return filled[2]
    text = _first_line(exc)
    found = _OPERANDS.search(text)
    return operands(exc, text, frame, set(found.groups())) if found else None
