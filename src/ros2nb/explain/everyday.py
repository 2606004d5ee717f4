"""One line for Python's everyday errors in the learner's code: the name they meant, the
attribute never set on the node, the argument a class does not take.

Part of :mod:`ros2nb.explain`; what a check says when the learner's code raised an error no
other explanation knows (:func:`~ros2nb.explain.exceptions.describe_error`): the error,
what it means here and what to do, where a traceback would have shown the learner's frames.
Runs wherever a check runs learner code: the kernel (a check of the learner's objects) and a
judge's subject.  Introduced in ``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import ast
import inspect
import textwrap
import linecache
import re
from types import FrameType
from typing import Any, Optional

from ..errors import Ros2nbError, UsageError
from .branches import unset_on_path
from .frames import frames_of, learner_frame
from .names import (builtin_meant, declared, import_of, learners_functions, one_edit_apart,
                    place, raising_text, set_at_top, similar, stored, stored_near,
                    unread_parameter, written_more)
from .values import filled_wrongly, wrong_kind

_CONSTRUCTOR_ARGUMENTS = re.compile(r'Invalid arguments passed to constructor: '
                                    r'(?:dict_keys\(\[(?P<keys>[^\]]*)\]\)|(?P<names>.+))')


def _first_line(exc: BaseException) -> str:
    return (str(exc).splitlines() or [''])[0][:200]


def _unset_attribute(obj: Any, name: str, owner: str) -> Optional[str]:
    """``self.name`` read on the learner's node, where no method of theirs keeps it: a local
    of that name (``temperature = ...``), an attribute of a name a typo away, one set only
    later, or none at all."""
    methods = list(learners_functions(type(obj)))
    if not methods:
        return None
    for code in methods:
        line = stored(code, name, 'STORE_FAST')
        if line is not None and linecache.getline(code.co_filename, line).lstrip().startswith(
                ('def ', 'async def ')):
            return (f'{owner} has no method {name}: it is written inside {code.co_name} '
                    f'({place(code, line)}), indented one level too deep: indent its def as '
                    f'{code.co_name}\'s is, so that it belongs to the class.')
        if line is not None:
            return (f'{owner} has no attribute {name}: {code.co_name} sets a local name '
                    f'{name} ({place(code, line)}), which is gone when it returns: write '
                    f'self.{name} = ... there, so that the node keeps it.')
    kept = similar(name, [key for key in vars(obj) if not key.startswith('_')])
    if kept:
        return (f'{owner} has no attribute {name}, but it has {kept}: names must match '
                f'exactly where they are set and where they are used (self.{name}).')
    if any(stored(code, name, 'STORE_ATTR') for code in methods):
        return (f'{owner} has no attribute {name} yet: it is read before any method sets it: '
                f'set self.{name} in __init__.')
    meant = similar(name, dir(obj))
    if meant:
        return (f'{owner} has no attribute {name}: did you mean self.{meant}? Names must '
                'match exactly.')
    return (f'{owner} has no attribute {name}: no method of the class sets self.{name}, and '
            f'none is called {name}: set self.{name} in __init__ (or write the method).')


_NO_SUCH_ATTRIBUTE = re.compile(r"^'(\w+)' object has no attribute '(\w+)'")


def _field_set(exc: AttributeError) -> Optional[str]:
    """``msg.dta = ...``: a message's field set under a name it does not have (Python names
    no object for a failed assignment: the message is found among the frame's values)."""
    found = _NO_SUCH_ATTRIBUTE.match(_first_line(exc))
    frame = learner_frame(exc)
    if found is None or frame is None:
        return None
    owner, name = found.groups()
    for value in frame.f_locals.values():
        if type(value).__name__ == owner:
            return _message_field(type(value), name)
    return None


def _message_field(cls: type, name: str) -> Optional[str]:
    """The line for a field a message of ``cls`` does not have, or None for no message."""
    fields = getattr(cls, 'get_fields_and_field_types', None)
    if fields is None:
        return None
    has = list(fields())
    meant = similar(name, has) or (has[0] if len(has) == 1 else None)
    hint = f': write {meant}' if meant else ''
    return f'a {cls.__name__} message has no field {name} (its fields: {", ".join(has)}){hint}.'


def _attribute(exc: AttributeError) -> Optional[str]:
    name, obj = getattr(exc, 'name', None), getattr(exc, 'obj', None)
    if not name or obj is None:
        return _field_set(exc)
    field = None if isinstance(obj, type) else _message_field(type(obj), name)
    if field:
        return field
    if inspect.ismethod(obj) or inspect.isfunction(obj) or inspect.isbuiltin(obj):
        called = f'self.{obj.__name__}' if inspect.ismethod(obj) else obj.__name__
        return (f'{called} is a method, not what it returns: call it, '
                f'{called}().{name}, with the parentheses.')
    owner = obj.__name__ if isinstance(obj, type) or hasattr(obj, '__file__') and hasattr(
        obj, '__name__') else type(obj).__name__
    if not isinstance(obj, type) and not hasattr(obj, '__file__'):
        unset = _unset_attribute(obj, name, owner)
        if unset:
            return unset
    meant = similar(name, dir(obj))
    if meant:
        return f"{owner} has no attribute {name}: did you mean {meant}? Names must match exactly."
    held = [a for a in dir(obj) if not a.startswith('_')
            and not callable(getattr(obj, a, None))][:8]  # what it holds, by name
    if held and not isinstance(obj, type):
        return f'{owner} has no attribute {name}: a {owner} holds {", ".join(held)}.'
    return f'{owner} has no attribute {name}: check the name against what {owner} offers.'


def _name(exc: NameError, frame: FrameType) -> str:
    name = getattr(exc, 'name', None)
    if not name:
        quoted = re.match(r"name '(\w+)'", _first_line(exc))
        name = quoted.group(1) if quoted else '?'
    if name == 'self':  # self.NAME in a plain function: the notebook's own names are plain
        used = re.search(r'\bself\.(\w+)', linecache.getline(frame.f_code.co_filename,
                                                             frame.f_lineno))
        plain = used.group(1) if used else 'the name'
        return (f"name 'self' is not defined: {frame.f_code.co_name}() is a function, not a "
                f'method of a node, so there is no self: write {plain}, not self.{plain}.')
    spelt = stored_near(frame.f_code, name)
    if spelt is None and frame.f_code.co_name != '<module>':
        top = set_at_top(frame.f_code, name)
        if top is not None and top[0] in frame.f_globals:
            if written_more(frame.f_code, top[0], name):  # the file spells it so: this use slipped
                return _did_you_mean(name, top[0])
            spelt = top
    if spelt is not None:
        other, line = spelt
        return (f"name '{name}' is not defined, but {other} is ({place(frame.f_code, line)}): "
                'spell a name the same where it is set and where it is used.')
    unread = unread_parameter(frame.f_code, name) if name not in frame.f_globals else None
    if unread is not None and not (one_edit_apart(unread, name)  # this use slipped, not the def
                                   and written_more(frame.f_code, unread, name)):
        function = frame.f_code.co_name
        return (f"name '{name}' is not defined: {function} calls its parameter {unread}, "
                f'which it never reads ({place(frame.f_code, frame.f_code.co_firstlineno)}): '
                f'name the parameter {name}, or read {unread}.')
    own = similar(name, {*frame.f_locals, *frame.f_globals})
    imported = import_of(name)
    if imported and not own:
        return (f"name '{name}' is not defined: import it at the top of the file (or cell), "
                f'{imported}.')
    meant = own or builtin_meant(name)
    if meant:
        return _did_you_mean(name, meant)
    return (f"name '{name}' is not defined where this line runs: no line before it sets "
            f'{name}: set it first, or check its spelling.')


def _did_you_mean(name: str, meant: str) -> str:
    return f"name '{name}' is not defined: did you mean {meant}? Names must match exactly."


def _constructor_arguments(exc: AssertionError) -> Optional[str]:
    """rclpy's and the messages' ``Invalid arguments passed to constructor``: which argument
    the class does not take, and the one meant."""
    found = _CONSTRUCTOR_ARGUMENTS.search(str(exc))
    frames = list(frames_of(exc))
    made = frames[-1].f_locals.get('self') if frames else None
    if not found or made is None:
        return None
    takes = [slot.lstrip('_') for slot in getattr(type(made), '__slots__', ())]
    given = [name.strip(" '") for name in (found['keys'] or found['names']).split(',')]
    unknown = [name for name in given if name not in takes]
    if not unknown:
        return None
    cls = type(made).__name__
    meant = similar(unknown[0], takes)
    hint = f': did you mean {meant}?' if meant else ''
    return (f'{cls}() takes no argument {unknown[0]}{hint} (it takes '
            f'{", ".join(t for t in takes if not t.startswith("check"))}).')


def _unset_local(exc: UnboundLocalError, frame: FrameType) -> str:
    """A name the function sets (which makes it local everywhere in it) used before that:
    set in some branches of an ``if`` only, set after its use, or imported late."""
    quoted = re.search(r"'(\w+)'", _first_line(exc))
    name = quoted.group(1) if quoted else '?'
    function = frame.f_code.co_name
    line = stored(frame.f_code, name, 'STORE_FAST')
    text = linecache.getline(frame.f_code.co_filename, line).strip() if line else ''
    if line is not None and text.startswith(('import ', 'from ')):
        return (f'{name} is used before {function} imports it ({place(frame.f_code, line)}): '
                'import it at the top of the file instead.')
    branch = unset_on_path(frame, name)
    if branch is not None:  # placed at that branch by cause_place, not at the line reading it
        return branch.words
    if line is not None and line < frame.f_lineno and _in_branch(frame, line):
        return (f'{name} has no value here: {function} sets it only in some branches of an '
                'if/elif/else, not in the one this call took: set it in every branch.')
    where = f' ({place(frame.f_code, line)})' if line is not None else ''
    return (f'{name} is used before {function} sets it{where}: a name the function sets is '
            'its own local name everywhere in it: set it before this line.')


def _in_branch(frame: FrameType, line: int) -> bool:
    """Whether ``line`` of the frame's function is inside an ``if`` (or ``elif``/``else``)."""
    try:
        lines, first = inspect.getsourcelines(frame.f_code)
        tree = ast.parse(textwrap.dedent(''.join(lines)))
    except (OSError, TypeError, SyntaxError):
        return False
    return any(isinstance(node, ast.If) and node.end_lineno is not None
               and node.lineno + first - 1 < line <= node.end_lineno + first - 1
               for node in ast.walk(tree))


_MISSING = re.compile(r"^(?P<called>[\w.]+)\(\) missing \d+ required positional "
                      r"arguments?: (?P<names>.+)$")


def _class_for_instance(exc: TypeError, frame: FrameType) -> Optional[tuple[str, type]]:
    """``(name, cls)``: a local name of the frame that holds a class where an instance was
    meant (``node = TemperatureSensor``, then ``node.destroy_node()``: no self), or None."""
    found = _MISSING.match(_first_line(exc))
    if found is None or re.findall(r"'(\w+)'", found['names']) != ['self']:
        return None
    method = found['called'].rpartition('.')[2]
    for name, value in frame.f_locals.items():
        if isinstance(value, type) and callable(getattr(value, method, None)):
            return name, value
    return None


def _missing_arguments(exc: TypeError, frame: FrameType) -> Optional[str]:
    """``create_publisher(Float32)``: which arguments the call still needs, in its order."""
    found = _MISSING.match(_first_line(exc))
    if found is None:
        return None
    held = _class_for_instance(exc, frame)
    if held is not None:
        name, cls = held
        return (f'{name} holds the class {cls.__name__}, not one made from it: create it with '
                f'parentheses, {name} = {cls.__name__}().')
    called = found['called'].removesuffix('.__init__').rpartition('.')[2]
    names = ', '.join(re.findall(r"'(\w+)'", found['names']))
    return (f'{called}() was called without {names}: give it every argument it needs, in '
            f'its order.')


_UNEXPECTED_KEYWORD = re.compile(r"^(?P<called>[\w.]+)\(\) got an unexpected keyword argument "
                                 r"'(?P<name>\w+)'")


def _unexpected_keyword(exc: TypeError, frame: FrameType) -> Optional[str]:
    """``Worker(heartbat_group=...)``: the keyword the callable takes that was meant."""
    found = _UNEXPECTED_KEYWORD.match(_first_line(exc))
    if found is None:
        return None
    called = found['called'].removesuffix('.__init__')
    line = linecache.getline(frame.f_code.co_filename, frame.f_lineno)
    written = re.search(rf'([\w.]*\b{re.escape(called.split(".")[-1])})\(', line)
    path = written.group(1) if written else called  # ros2nb.spin, as the line calls it
    target = {**frame.f_globals, **frame.f_locals}.get(path.split('.')[0])
    for part in path.split('.')[1:]:
        target = getattr(target, part, None)
    if not callable(target):  # what inspect.signature refuses first, with a TypeError
        return None
    try:
        takes = [p for p in inspect.signature(target).parameters if p not in ('self', 'args',
                                                                               'kwargs')]
    except (TypeError, ValueError):
        return None
    meant = similar(found['name'], takes)
    hint = f': did you mean {meant}?' if meant else ''
    return (f'{called}() takes no argument {found["name"]}{hint} (it takes '
            f'{", ".join(takes) or "none"}).')


def cause_place(exc: BaseException) -> Optional[str]:
    """``FILE line N: source`` of the learner's line that caused ``exc`` where that is not
    the line that raised it, or None.  A parameter's value of the wrong kind (None: declared
    without a default) fails where it is used, perhaps in a line the course gave: the cause
    is the learner's ``declare_parameter`` of it.  A name read after an ``if`` whose branch
    taken set no value for it fails at the read, which is right: the cause is that branch."""
    frame = learner_frame(exc)
    if frame is not None and isinstance(exc, UnboundLocalError):  # the branch that set nothing
        quoted = re.search(r"'(\w+)'", _first_line(exc))
        branch = unset_on_path(frame, quoted.group(1)) if quoted else None
        return place(frame.f_code, branch.line) if branch is not None else None
    if frame is None or not isinstance(exc, (TypeError, ValueError)):
        return None
    filled = filled_wrongly(exc, frame) if isinstance(exc, TypeError) else None
    if filled is not None:  # the line that filled the list, not the one that read it
        return filled[3]
    held = _class_for_instance(exc, frame) if isinstance(exc, TypeError) else None
    if held is not None:  # where the name was given the class
        line = stored(frame.f_code, held[0], 'STORE_FAST')
        return place(frame.f_code, line) if line is not None else None
    used = re.findall(r"get_parameter\(\s*'(\w+)'", raising_text(exc))
    owner = frame.f_locals.get('self')
    if not used or owner is None:
        return None
    parameters = getattr(owner, '_parameters', {})
    wrong = [name for name in used if not isinstance(  # the one holding no number, if known
        getattr(parameters.get(name), 'value', 0.0), (int, float))] or used
    for code in learners_functions(type(owner)):
        line = declared(code, wrong[0])
        if line is not None:
            return place(code, line)
    return None


def everyday_explanation(exc: BaseException) -> Optional[str]:
    """The line for an error of Python's own that the learner's code raised, with what to do,
    or None when it is not theirs to fix: no frame of the error is the learner's, and it is
    no attribute missing on an object of a class of theirs (the course's code standing in
    for a part reads what their constructor should have set)."""
    frame = learner_frame(exc)
    if isinstance(exc, (Ros2nbError, UsageError)):
        return str(exc)  # ros2nb's own line, which says what to do
    if isinstance(exc, AttributeError):
        obj = getattr(exc, 'obj', None)
        if frame is not None or any(True for _ in learners_functions(type(obj))):
            found = _attribute(exc)
            if found:
                return found
    if frame is None:
        return None
    text = _first_line(exc)
    if isinstance(exc, UnboundLocalError):
        return _unset_local(exc, frame)
    if isinstance(exc, NameError):
        return _name(exc, frame)
    if isinstance(exc, AssertionError):
        found = _constructor_arguments(exc)
        if found:
            return found
    if isinstance(exc, TypeError):
        found = _unexpected_keyword(exc, frame) or _missing_arguments(exc, frame)
        if found:
            return found
    if isinstance(exc, TypeError):
        found = wrong_kind(exc, frame)
        if found:
            return found
    if isinstance(exc, KeyError):
        return (f'KeyError: {text}: the line reads a key that is not there: check its '
                'spelling, or read it with .get(key, default).')
    return f'{type(exc).__name__}: {text}: this line of yours raised it; fix it, then check again.'
