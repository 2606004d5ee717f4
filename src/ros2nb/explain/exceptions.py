"""One line for each mistake a beginner's code makes through rclpy or a message class.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``; the whole list is in
``docs/troubleshooting.md``.  :func:`explain_exception` turns an error that rclpy or a
message class raised into one line naming what to do; :func:`learner_line` finds the
learner's own line in a traceback.  The kernel shows that line instead of a traceback
through rclpy (:mod:`ros2nb.kernel`); a failing callback is reported with it, in the
kernel and in a check's subject alike.
"""

from __future__ import annotations

import linecache
import os
import re
import traceback
from pathlib import Path
from typing import Any, Optional

from rclpy.exceptions import NameValidationException, NotInitializedException

from ..errors import SHUT_DOWN_MESSAGE
from .bag_reading import bag_reading_mistake
from .everyday import cause_place, everyday_explanation
from .names import made_where
from .frames import frames_of, is_library_file, learner_entry, learner_frame, raised_in
from .plain_python import python_mistake
from .plots import plot_in_callback
from .ros_calls import wrong_arguments
from .ros_settings import qos_setting, settings_mistake


def learner_line(exc: BaseException) -> str:
    """Return ``cell line N: source`` or ``FILE line N: source`` for the learner's
    innermost frame."""
    entry = learner_entry(exc)
    if entry is not None:
        filename, number = entry.tb_frame.f_code.co_filename, entry.tb_lineno
    else:  # ROS called a function of the learner's wrongly (a callback's signature)
        code = _called_code(exc)
        if code is None:
            return ''
        filename, number = code.co_filename, code.co_firstlineno
    path = Path(filename)
    place = path.name if path.is_file() and 'ipykernel' not in filename else 'cell'
    return f'{place} line {number}: {linecache.getline(filename, number).strip()}'


_SIGNATURE = re.compile(r'^(?P<name>[\w.]+)\(\) (?:takes (?P<takes>\d+) positional arguments? '
                        r'but (?P<given>\d+) (?:was|were) given|missing \d+ required positional)')


def learner_traceback(exc: BaseException) -> list[str]:
    """The traceback of ``exc`` through the learner's own frames only (a cell, their file),
    as Python prints it: empty when none of its frames is theirs."""
    frames = [f for f in traceback.extract_tb(exc.__traceback__)
              if not is_library_file(f.filename) and not f.filename.startswith('<ros2nb')]
    lines = ['Traceback (most recent call last):'] if frames else []
    for text in traceback.format_list(frames):
        lines.extend(text.rstrip('\n').splitlines())
    return lines


def describe_error(error: BaseException) -> dict[str, Any]:
    """The learner-facing facts of an exception: ``type``, ``message`` (at most 500
    characters), ``explanation`` (the one line of a known mistake, else of Python's error
    with what to do, :mod:`.everyday`; None when no frame is the learner's), ``traceback``
    (their own frames, :func:`learner_traceback`) and ``where`` (:func:`learner_line`).

    What a check makes of an error in the learner's code, in a subject or in the kernel
    (``ros2nb.judge_interface.learner_error``): one line at the learner's line, never a
    traceback; introduced in ``03-write-the-publisher.ipynb``.
    """
    try:
        explanation = explain_exception(error) or everyday_explanation(error)
    except Exception:  # explaining must never hide the original error
        explanation = None
    return {'type': type(error).__name__, 'message': str(error)[:500],
            'explanation': explanation, 'traceback': learner_traceback(error),
            'where': cause_place(error) or learner_line(error)}


def _called_code(exc: BaseException) -> Any:
    """The code of the learner's function that rclpy called with the wrong arguments, or None."""
    match = _SIGNATURE.match(str(exc)) if isinstance(exc, TypeError) else None
    frames = list(frames_of(exc))
    if match is None or not frames or not is_library_file(frames[-1].f_code.co_filename):
        return None
    for value in frames[-1].f_locals.values():
        function = getattr(value, '__func__', value)
        code = getattr(function, '__code__', None)
        if code is not None and getattr(function, '__qualname__', '') == match['name'] \
                and not is_library_file(code.co_filename):
            return code
    return None


_FIELD_TYPE = re.compile(r"The '(\w+)' field must be of type '([\w.]+)'")
_NUMBERS = {'float': 'a decimal number such as 22.0', 'int': 'a whole number such as 10',
            'str': "text such as 'hello'", 'bool': 'True or False'}


def _field_type(exc: AssertionError) -> Optional[str]:
    match = _FIELD_TYPE.search(str(exc))
    if not match:
        return qos_setting(exc, list(frames_of(exc)))
    field, wanted = match.groups()
    frame = list(frames_of(exc))[-1]
    message = frame.f_locals.get('self')
    value = frame.f_locals.get('value')
    owner = type(message).__name__ if message is not None else 'the message'
    fix = _NUMBERS.get(wanted, f'a {wanted}')
    if wanted == 'float' and isinstance(value, int) and not isinstance(value, bool):
        fix = f'{value}.0 or float(...)'
    if isinstance(value, bool) and wanted != 'bool':  # a yes/no: another message type meant
        return (f"{owner}'s field '{field}' takes {fix}, not bool {value!r}: True or False "
                f'goes into a Bool message; make this message a Bool, not a {owner}'
                f'{made_where(exc, message)}.')
    return (f"{owner}'s field '{field}' takes {fix}, not {type(value).__name__} {value!r}: "
            'convert the value before you put it into the message.')


_NO_ATTRIBUTE = re.compile(r"^'(\w+)' object has no attribute '(\w+)'")


def _missing_attribute(exc: AttributeError) -> Optional[str]:
    """``self.TOPIC`` for a module constant, or a method written outside its class."""
    match = _NO_ATTRIBUTE.match(str(exc))
    frame = learner_frame(exc)
    if not match or frame is None:
        return None
    owner, name = match.groups()
    found = frame.f_globals.get(name)
    if found is None:
        return None
    if name.isupper():
        return (f'{name} is a constant of the file, not of the node: write {name}, not '
                f'self.{name}.')
    if callable(found) and not isinstance(found, type):
        return (f'{name} is written outside the class {owner}: indent its part by four spaces, '
                'so that it becomes a method of the class.')
    return None


def _message_not_a_value(exc: TypeError) -> Optional[str]:
    """A message used where its number is meant: ``msg > 26`` instead of ``msg.data > 26``."""
    frame = learner_frame(exc)
    if frame is None:
        return None
    for value in frame.f_locals.values():
        cls = type(value)
        if hasattr(cls, 'get_fields_and_field_types') and \
                re.search(rf'\b{cls.__name__}\b', str(exc)):
            fields = ', '.join(cls.get_fields_and_field_types())
            return (f'a {cls.__name__} message is not its value: use its field ({fields}), e.g. '
                    'msg.data.')
    return None


def _node_without_init(exc: AttributeError) -> Optional[str]:
    for frame in frames_of(exc):
        if not frame.f_code.co_filename.endswith(os.path.join('rclpy', 'node.py')):
            continue
        obj = frame.f_locals.get('self')
        if obj is not None and not hasattr(obj, '_Node__node'):
            name = type(obj).__name__
            return (f"{name}.__init__ never calls super().__init__('node_name'): make that the "
                    f'first line of {name}.__init__, before any publisher, timer or subscription.')
    return None


def explain_exception(exc: BaseException, *, ros_started: bool = False) -> Optional[str]:
    """Return one line explaining a known beginner mistake behind ``exc``, or None.

    :param exc: an exception raised by the learner's code, through rclpy or a message.
    :param ros_started: True where ros2nb brought ROS up in this process (a kernel after
        ``ros2nb.start()``): then "not initialised" means it was shut down since.
    :return: what went wrong and what to do, or None for anything else (its normal
        traceback is then the best explanation).
    """
    text = str(exc)
    found = wrong_arguments(exc)  # an rclpy call given its arguments out of order
    if found:
        return found
    if isinstance(exc, NameValidationException):
        return _invalid_name(exc)
    if _called_code(exc) is not None:
        return _callback_signature(exc)
    if isinstance(exc, RuntimeError) and 'callback should be either be callable with one' in text:
        return _subscription_callback(exc)
    if type(exc).__name__ == 'RCLError' and 'timer period must be non-negative' in text:
        return ('create_timer got a negative period: give the period in seconds as a positive '
                'number, e.g. self.create_timer(1.0, self.publish_temperature).')
    if isinstance(exc, (TypeError, ValueError)) and _is_qos_mistake(exc):
        return _qos_advice(exc)
    if isinstance(exc, FileExistsError) and raised_in(exc, 'mkdir'):
        return (f'{exc.filename} already exists, and mkdir() without exist_ok refuses an existing '
                'folder, like mkdir without -p: mkdir(parents=True, exist_ok=True) is mkdir -p.')
    if type(exc) is NotImplementedError and not text:
        return _placeholder(exc)
    if isinstance(exc, NotInitializedException):
        if ros_started:
            return SHUT_DOWN_MESSAGE
        return ('ROS 2 is not up in this kernel yet: run ros2nb.start() first (in a notebook it '
                'takes the place of rclpy.init()), then create the node again.')
    if isinstance(exc, RuntimeError) and 'must only be called once' in text:
        return ('rclpy.init() was called, but ros2nb.start() already brought ROS 2 up in this '
                'kernel: remove that call; to run a node here hand it to ros2nb.add(node) '
                '(main() is for `ros2 run`, notebook 05).')
    found = (python_mistake(exc, text) or bag_reading_mistake(exc, text)
             or settings_mistake(exc, text, list(frames_of(exc))) or plot_in_callback(exc, text))
    if found:
        return found
    if type(exc).__name__ == 'InvalidQoSProfileException':
        return ('a QoSProfile needs its history depth: QoSProfile(depth=10), or pass just the '
                'depth, 10.')
    if isinstance(exc, AssertionError):
        return _field_type(exc)
    if isinstance(exc, AttributeError):
        return _node_without_init(exc) or _missing_attribute(exc)
    if type(exc).__name__ == 'RCLError' and 'context is invalid' in text:
        return SHUT_DOWN_MESSAGE
    if isinstance(exc, TypeError) and text.startswith('Expected <class'):
        return _wrong_message_published(text)
    if isinstance(exc, TypeError) and text.startswith('Expected QoSProfile or int'):
        return ('the arguments are in the wrong order: create_subscription takes the message '
                'type, the topic, the callback and the queue depth (create_publisher: the type, '
                'the topic and the depth); something else came where the depth belongs.')
    if isinstance(exc, TypeError):
        return _message_not_a_value(exc)
    return None


def _wrong_message_published(text: str) -> str:
    """publish() given something other than its publisher's message type: the advice names
    that type (a ``Bool`` publisher gets ``Bool`` advice), and a message of another type is
    told apart from a bare value."""
    found = re.match(r"Expected <class '([\w.]+)'>, got <class '([\w.]+)'>", text)
    wanted, got = (found.group(1).rsplit('.', 1)[-1], found.group(2)) if found else ('Float32', '')
    if '.msg.' in got:  # another message type
        return (f'this publisher was created for {wanted} messages and was handed a '
                f'{got.rsplit(".", 1)[-1]}: create a {wanted} (msg = {wanted}()), set its '
                'fields, then publish(msg); or create the publisher with the type you publish.')
    bare = f' ({got})' if got else ''
    return (f'publish() takes a {wanted} message, not a bare value{bare}: create the message '
            f'(msg = {wanted}()), set msg.data, then publish(msg).')


def _placeholder(exc: BaseException) -> Optional[str]:
    """The line for a part the learner has not written yet (its ``raise NotImplementedError()``)."""
    frame = learner_frame(exc)
    if frame is None:
        return None
    name = frame.f_code.co_qualname if hasattr(frame.f_code, 'co_qualname') \
        else frame.f_code.co_name
    called = 'this cell' if name == '<module>' else f'{name.replace(".__init__", "")}()'
    return (f'{called} is not written yet: write your code where it says YOUR CODE HERE, in '
            'place of this placeholder, run that cell, then this one again.')


def _invalid_name(exc: BaseException) -> str:
    """A node, topic or namespace name with a character ROS forbids."""
    first, _, rest = str(exc).partition('\n')
    kind, _, reason = first.partition(': ')
    kind = kind.replace('Invalid ', '')
    name_line = rest.strip().splitlines()[0] if rest.strip() else ''
    name = name_line.strip().strip("'")
    allowed = r'[^A-Za-z0-9_]' if kind == 'node name' else r'[^A-Za-z0-9_/~{}]'
    fixed = re.sub(allowed, '_', name)
    if fixed[:1].isdigit():
        fixed = '_' + fixed
    return (f"'{name}' is not a valid ROS {kind}: {reason.rstrip(':')}; write it as "
            f"'{fixed}' (letters, digits and _).")


def _callback_signature(exc: BaseException) -> str:
    """ROS called a callback with other arguments than it takes."""
    match = _SIGNATURE.match(str(exc))
    assert match is not None
    name = match['name']
    short, me = name.rpartition('.')[2], ('self, ' if '.' in name else '')
    given = list(frames_of(exc))[-1].f_locals.get('args', ())
    if given:
        return (f'ROS calls {name}() with the message it received (a subscription callback): '
                f'define it as def {short}({me}msg) and read msg.data.')
    return (f'ROS calls {name}() with no arguments (a timer callback): define it as '
            f'def {short}({me.rstrip(", ")}) and keep what it needs on self.')


def _subscription_callback(exc: BaseException) -> str:
    """rclpy refused a subscription callback that cannot take the message."""
    callback = list(frames_of(exc))[-1].f_locals.get('value')
    name = getattr(callback, '__qualname__', 'the callback')
    short, me = name.rpartition('.')[2], ('self, ' if '.' in name else '')
    return (f'the subscription\'s callback {name}() must take the message ROS hands it: define '
            f'it as def {short}({me}msg) and read msg.data.')


def _is_qos_mistake(exc: BaseException) -> bool:
    text = str(exc)
    return ("'qos_profile'" in text or 'history depth must be' in text
            or text.startswith("Node.create_publisher()")
            or text.startswith('Node.create_subscription()'))


#: What create_publisher and create_subscription take, in order.
_ENDPOINT_ORDER = {'create_publisher': 'the message type, the topic and the queue depth',
                   'create_subscription': 'the message type, the topic, the callback and the '
                                          'queue depth'}


_ARGUMENTS = {'msg_type': 'the message type', 'topic': 'the topic', 'callback': 'the callback',
              'qos_profile': 'the queue depth'}


def _qos_advice(exc: BaseException) -> str:
    """create_publisher / create_subscription given too few or too many arguments, or a
    queue depth (QoS) below 0."""
    text = str(exc)
    call = 'create_subscription' if 'create_subscription' in text else 'create_publisher'
    takes = f'{call} takes {_ENDPOINT_ORDER[call]}, in that order'
    if 'history depth must be' in text:
        return f'the queue depth must be 0 or more (10 is usual): {takes}.'
    missing = re.search(r'missing \d+ required positional arguments?: (.+)$', text)
    if missing:
        names = [_ARGUMENTS.get(n, n) for n in re.findall(r"'(\w+)'", missing.group(1))]
        named = ' and '.join([', '.join(names[:-1]), names[-1]] if len(names) > 1 else names)
        return f'{call}() was called without {named}: {takes}.'
    keyword = re.search(r"unexpected keyword argument '(\w+)'", text)
    if keyword:
        return f'{call}() takes no argument {keyword.group(1)}: {takes}.'
    return f'{call}() was given other arguments than it takes: {takes}.'

