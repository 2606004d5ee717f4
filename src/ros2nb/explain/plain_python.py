"""One line for Python used the way another tool (or another language) is, in a node's code.

Part of :mod:`ros2nb.explain` (:func:`~ros2nb.explain.exceptions.explain_exception` asks
here); runs wherever learner code does: the kernel and the judge's subjects.  Python's own
message names the problem; these lines add the fix in the learner's terms.
"""

from __future__ import annotations

import linecache
import re
from typing import Any, Optional

from .frames import learner_frame, raised_in

_LOGGER_ARGUMENTS = re.compile(r'^RcutilsLogger\.(\w+)\(\) takes 2 positional arguments')
_UNDEFINED = re.compile(r"^name '(\w+)' is not defined")
#: A message class given its fields in order (``Bool(x > 26)``): generated messages take
#: keywords only.
_POSITIONAL_FIELDS = re.compile(r'^(\w+)\.__init__\(\) takes 1 positional argument but \d+ '
                                r'(?:was|were) given')
#: A local name used before it is set (3.11: "cannot access local variable"; 3.10: "local
#: variable ... referenced before assignment").
_UNSET_LOCAL = re.compile(r"(?:cannot access local variable|local variable) '(\w+)'")
#: A method called with no arguments where it should have been passed as a callback.
#: A stand-in of the course's is named "the course's Class.method" (subject.commands._named).
_MISSING_ARGUMENT = re.compile(r"^(?:the course's )?(?:\w+\.)?(\w+)\(\) missing 1 required "
                               r"positional argument: '(\w+)'")
#: What takes a callback: the method is passed, and rclpy calls it later.
_TAKES_A_CALLBACK = ('add_on_set_parameters_callback', 'create_subscription', 'create_timer')


def python_mistake(exc: BaseException, text: str) -> Optional[str]:
    """The line for Python used as another tool is, or None: randint for a decimal step, a
    logger given print's values, a method named without ``self.``, a message given its
    fields in order, a counter without ``self.``, a callback called instead of passed
    (notebooks 03, 04, 06 and 08).
    """
    if isinstance(exc, ValueError) and text.startswith('non-integer arg') \
            and raised_in(exc, 'randrange'):
        return ('random.randint draws whole numbers only: for a step between -0.5 and 0.5 °C '
                'use random.uniform(-0.5, 0.5).')
    logger = _LOGGER_ARGUMENTS.match(text) if isinstance(exc, TypeError) else None
    if logger:
        return (f'get_logger().{logger.group(1)}() takes one string, not a list of values as '
                f"print does: put the values into it, get_logger().{logger.group(1)}"
                "(f'Temperature: {value:.2f}').")
    frame = learner_frame(exc)
    if frame is None:
        return None
    if isinstance(exc, NameError) and not isinstance(exc, UnboundLocalError):
        return _method_without_self(frame, text)
    if isinstance(exc, UnboundLocalError):
        return _attribute_without_self(frame, text)
    if isinstance(exc, TypeError):
        return (_fields_in_order(frame, text) or _callback_called(frame, text)
                or _one_value_to_compare(frame, text))
    return None


_NOT_ITERABLE = re.compile(r"^'(\w+)' object is not iterable")


def _one_value_to_compare(frame: Any, text: str) -> Optional[str]:
    """``max(MIN_TEMPERATURE_C)``: max or min given one number, which it takes for a list."""
    found = _NOT_ITERABLE.match(text)
    line = linecache.getline(frame.f_code.co_filename, frame.f_lineno)
    called = re.search(r'\b(max|min)\(', line)
    if found is None or called is None:
        return None
    function = called.group(1)
    return (f'{function}() was given one {found.group(1)}: with one argument it looks for the '
            f'{"largest" if function == "max" else "smallest"} item of a list; give it the '
            f'values to compare, {function}(a, b).')


def _method_without_self(frame: Any, text: str) -> Optional[str]:
    """A method or an attribute of the node named without ``self.`` inside the class."""
    undefined = _UNDEFINED.match(text)
    owner = frame.f_locals.get('self')
    if not undefined or owner is None or not hasattr(owner, undefined.group(1)):
        return None
    name = undefined.group(1)
    kind = 'a method' if callable(getattr(owner, name)) else 'kept on the node as an attribute'
    return (f'{name} is {kind} of {type(owner).__name__}: inside the class, name it '
            f'self.{name}.')


def _attribute_without_self(frame: Any, text: str) -> Optional[str]:
    """``received += 1`` in a method, where the count lives on the node (``self.received``)."""
    unset = _UNSET_LOCAL.search(text)
    owner = frame.f_locals.get('self')
    if unset is None or owner is None:
        return None
    name = unset.group(1)
    source = linecache.getline(frame.f_code.co_filename, frame.f_lineno)
    if not hasattr(owner, name) and not re.search(rf'\b{name}\s*[-+*/]=', source):
        return None  # no count: another local used before it is set (everyday.py says so)
    kept = (f'the node keeps it as self.{name}' if hasattr(owner, name) else
            f'keep it on the node: self.{name} = 0 in __init__')
    return (f'{name} here is a new local name of this method, not the node\'s count ({kept}): '
            f'write self.{name} wherever the method uses it, e.g. self.{name} += 1.')


def _fields_in_order(frame: Any, text: str) -> Optional[str]:
    """``Bool(msg.data > 26)``: a message takes its fields by name."""
    found = _POSITIONAL_FIELDS.match(text)
    if found is None:
        return None
    name = found.group(1)
    message = frame.f_locals.get(name, frame.f_globals.get(name))
    fields = list(getattr(message, 'get_fields_and_field_types', lambda: {})())
    if not fields:
        return None
    source = linecache.getline(frame.f_code.co_filename, frame.f_lineno)
    given = re.search(rf'\b{name}\(([^=()]*(?:\([^()]*\)[^=()]*)*)\)', source)
    example = (f'{name}({fields[0]}={given.group(1).strip()})' if given and len(fields) == 1
               else f'{name}({", ".join(f"{field}=..." for field in fields)})')
    return (f'a {name} message takes its fields by name, not in order: write {example} '
            f'(its fields: {", ".join(fields)}).')


def _callback_called(frame: Any, text: str) -> Optional[str]:
    """``add_on_set_parameters_callback(self.on_set())``: the method was called (with
    nothing) instead of passed, for rclpy to call later with what it needs."""
    missing = _MISSING_ARGUMENT.match(text)
    if missing is None:
        return None
    argument = missing.group(2)
    # the call may run over lines: the callback's line and the two before it
    source = ' '.join(linecache.getline(frame.f_code.co_filename, line).strip()
                      for line in range(max(1, frame.f_lineno - 2), frame.f_lineno + 1))
    taker = next((name for name in _TAKES_A_CALLBACK if f'{name}(' in source), None)
    # the method as the learner's line names it (what raised may be wrapped, or renamed)
    called = re.search(rf'{taker}\(.*?\bself\.(\w+)\(\s*\)', source) if taker else None
    if called is None:
        return None
    method = called.group(1)
    return (f'{method}() was called here, with nothing for its {argument}, and {taker} would '
            f'get what it returned: pass the method itself, without (): self.{method}; rclpy '
            f'calls it later with its {argument}.')
