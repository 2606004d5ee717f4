"""One line for each mistake beginners make with rclpy, naming their own line and the fix.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``; the whole list is in
``docs/troubleshooting.md``.

Two kinds: :func:`check_node` refuses a node with a mistake when it is handed over
(before anything runs), and :func:`explain_exception` turns an error that rclpy or a
message class raised into one line.  The kernel shows that line instead of a traceback
through rclpy (:mod:`ros2nb.kernel`); a failing callback is reported with it.
"""

from __future__ import annotations

import linecache
import os
import re
import site
import sysconfig
from pathlib import Path
from types import TracebackType
from typing import Any, Optional

from .errors import Ros2nbError
from .graph import type_name

_HERE = os.path.dirname(os.path.abspath(__file__))


def _library_dirs() -> tuple[str, ...]:
    dirs = {_HERE, *site.getsitepackages(), site.getusersitepackages()}
    for key in ('stdlib', 'platstdlib', 'purelib', 'platlib'):
        dirs.add(sysconfig.get_paths()[key])
    return tuple(sorted(os.path.abspath(d) + os.sep for d in dirs if d))


_LIBRARY_DIRS = _library_dirs()


def is_library_file(path: str) -> bool:
    """True for files of Python, installed packages (rclpy, messages, IPython) and ros2nb."""
    path = os.path.abspath(path)
    return path.startswith(_LIBRARY_DIRS) or path.startswith('<frozen')


def _learner_entry(exc: BaseException) -> Optional[TracebackType]:
    """The innermost traceback entry in the learner's own code (a cell or their file)."""
    found, tb = None, exc.__traceback__
    while tb is not None:
        if not is_library_file(tb.tb_frame.f_code.co_filename):
            found = tb
        tb = tb.tb_next
    return found


def learner_line(exc: BaseException) -> str:
    """Return ``cell line N: source`` or ``FILE line N: source`` for the learner's innermost frame."""
    entry = _learner_entry(exc)
    if entry is None:
        return ''
    filename = entry.tb_frame.f_code.co_filename
    path = Path(filename)
    place = path.name if path.is_file() and 'ipykernel' not in filename else 'cell'
    return f'{place} line {entry.tb_lineno}: {linecache.getline(filename, entry.tb_lineno).strip()}'


def _frames(exc: BaseException):
    tb = exc.__traceback__
    while tb is not None:
        yield tb.tb_frame
        tb = tb.tb_next


_FIELD_TYPE = re.compile(r"The '(\w+)' field must be of type '([\w.]+)'")
_NUMBERS = {'float': 'a decimal number such as 22.0', 'int': 'a whole number such as 10',
            'str': "text such as 'hello'", 'bool': 'True or False'}


def _field_type(exc: AssertionError) -> Optional[str]:
    match = _FIELD_TYPE.search(str(exc))
    if not match:
        return None
    field, wanted = match.groups()
    frame = list(_frames(exc))[-1]
    message = frame.f_locals.get('self')
    value = frame.f_locals.get('value')
    owner = type(message).__name__ if message is not None else 'the message'
    fix = _NUMBERS.get(wanted, f'a {wanted}')
    if wanted == 'float' and isinstance(value, int) and not isinstance(value, bool):
        fix = f'{value}.0 or float(...)'
    return (f"{owner}'s field '{field}' takes {fix}, not {type(value).__name__} {value!r}: "
            'convert the value before you put it into the message.')


def _learner_frame(exc: BaseException) -> Any:
    """The innermost frame of the learner's own code (a cell or their file), or None."""
    entry = _learner_entry(exc)
    return entry.tb_frame if entry is not None else None


_NO_ATTRIBUTE = re.compile(r"^'(\w+)' object has no attribute '(\w+)'")


def _missing_attribute(exc: AttributeError) -> Optional[str]:
    """``self.TOPIC`` for a module constant, or a method written outside its class."""
    match = _NO_ATTRIBUTE.match(str(exc))
    frame = _learner_frame(exc)
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
    frame = _learner_frame(exc)
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
    for frame in _frames(exc):
        if not frame.f_code.co_filename.endswith(os.path.join('rclpy', 'node.py')):
            continue
        obj = frame.f_locals.get('self')
        if obj is not None and not hasattr(obj, '_Node__node'):
            name = type(obj).__name__
            return (f"{name}.__init__ never calls super().__init__('node_name'): make that the "
                    f'first line of {name}.__init__, before any publisher, timer or subscription.')
    return None


def explain_exception(exc: BaseException) -> Optional[str]:
    """Return one line explaining a known beginner mistake behind ``exc``, or None.

    :param exc: an exception raised by the learner's code, through rclpy or a message.
    :return: what went wrong and what to do, or None for anything else (its normal
        traceback is then the best explanation).
    """
    from rclpy.exceptions import NotInitializedException
    text = str(exc)
    if isinstance(exc, NotInitializedException):
        from . import runtime
        if runtime._runtime is not None:
            return runtime.SHUT_DOWN_MESSAGE
        return ('ROS 2 is not up in this kernel yet: run ros2nb.start() first (in a notebook it '
                'takes the place of rclpy.init()), then create the node again.')
    if isinstance(exc, RuntimeError) and 'must only be called once' in text:
        return ('rclpy.init() was called, but ros2nb.start() already brought ROS 2 up in this '
                'kernel: remove that call; to run a node here hand it to ros2nb.add(node) '
                '(main() is for `ros2 run`, notebook 05).')
    if isinstance(exc, AssertionError):
        return _field_type(exc)
    if isinstance(exc, AttributeError):
        return _node_without_init(exc) or _missing_attribute(exc)
    if type(exc).__name__ == 'RCLError' and 'context is invalid' in text:
        from . import runtime
        return runtime.SHUT_DOWN_MESSAGE
    if isinstance(exc, TypeError) and text.startswith('Expected <class'):
        return ('publish() takes a message object, not a bare value: create the message '
                '(msg = Float32()), set msg.data, then publish(msg).')
    if isinstance(exc, TypeError) and text.startswith('Expected QoSProfile or int'):
        return ('the arguments are in the wrong order: create_subscription takes the message '
                'type, the topic, the callback and the queue depth (create_publisher: the type, '
                'the topic and the depth); something else came where the depth belongs.')
    if isinstance(exc, TypeError):
        return _message_not_a_value(exc)
    return None


# --------------------------------------------------------------- checks at add()
def _callback_name(callback: Any) -> str:
    return getattr(callback, '__qualname__', repr(callback))


def check_node(node: Any, rt: Any) -> None:
    """Refuse, with one line, a node that would fail or mislead once it runs.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.add`).

    :param node: what was handed to :func:`ros2nb.add`.
    :param rt: the kernel's runtime.
    :raises Ros2nbError: naming the mistake and the fix.
    """
    from rclpy.node import Node
    if isinstance(node, type) and issubclass(node, Node):
        raise Ros2nbError(f'ros2nb.add() takes a node, not the class {node.__name__}: create '
                          f'one first, ros2nb.add({node.__name__}()).')
    if not isinstance(node, Node):
        raise Ros2nbError(f'ros2nb.add() takes an rclpy Node, not {type(node).__name__}: create '
                          'the node first, e.g. ros2nb.add(TemperatureSensor()).')
    if not hasattr(node, '_Node__node'):
        raise Ros2nbError(f"{type(node).__name__}.__init__ never calls super().__init__('node_name'): "
                          'make that its first line.')
    name = node.get_name()
    if node.context is not rt.context or not node.context.ok():
        raise Ros2nbError(f'{name} was created before ROS 2 was (re)started in this kernel: run '
                          'the cell that creates it again, then hand it over.')
    for timer in node.timers:
        if not callable(timer.callback):
            raise Ros2nbError(f'{name} has a timer whose callback is {timer.callback!r}, not a '
                              'function: pass the method itself (self.publish_temperature, '
                              'without the parentheses).')
        if timer.timer_period_ns == 0:
            raise Ros2nbError(f'{name} has a timer with a period of 0 s for '
                              f'{_callback_name(timer.callback)}: it would fire without pause; '
                              'give create_timer a period in seconds, e.g. 1.0.')
    for kind, entities in (('publisher', node.publishers), ('subscription', node.subscriptions)):
        for entity in entities:
            if not isinstance(entity.msg_type, type):
                cls = type(entity.msg_type).__name__
                raise Ros2nbError(f'{name} made a {kind} on {entity.topic_name} with a message '
                                  f'{cls}() instead of the message type: pass {cls} without '
                                  'the parentheses.')
            if kind == 'subscription' and not callable(entity.callback):
                raise Ros2nbError(f'{name} has a subscription on {entity.topic_name} whose '
                                  f'callback is {entity.callback!r}: pass the method itself, '
                                  'without the parentheses.')
    _check_types_agree(node, rt)


def _check_types_agree(node: Any, rt: Any) -> None:
    """Refuse a node whose topic type differs from what another node of this process uses.

    Only this process's own endpoints count (by DDS participant): they are known at once,
    so the same node always gets the same sentence.  Whether a node of another process
    (``ros2 run``, a check's judge) has been discovered yet depends on timing; that kind of
    mismatch is the graph's business (:func:`ros2nb.topic_list` notes it).
    """
    name = node.get_name()
    graph = rt.node
    local = _local_prefix(rt)
    for kind, entities in (('publishes', node.publishers), ('subscribes to', node.subscriptions)):
        for entity in entities:
            topic = node.resolve_topic_name(entity.topic_name)
            mine = type_name(entity.msg_type)
            others = sorted([*graph.get_publishers_info_by_topic(topic),
                             *graph.get_subscriptions_info_by_topic(topic)],
                            key=lambda e: (e.node_name, e.topic_type))
            for info in others:  # hidden nodes (ros2nb's, a check's, not yet named) aside
                if info.node_name == name or info.node_name.startswith('_') \
                        or info.topic_type == mine or bytes(info.endpoint_gid[:12]) != local:
                    continue
                role = 'publishes' if 'PUBLISHER' in str(info.endpoint_type) else 'subscribes to'
                raise Ros2nbError(f'{name} {kind} {topic} as {mine}, but {info.node_name} {role} '
                                  f'it as {info.topic_type}: both sides of a topic must use the '
                                  'same message type.')


# --------------------------------------------------------------- checks at creation
_GUARDED = '_ros2nb_guarded'


def _local_prefix(rt: Any = None) -> Optional[bytes]:
    """The GUID prefix of this process's DDS participant (from ros2nb's own node), if ROS is up.

    :param rt: the runtime whose node to ask; ``None`` is the kernel's.
    """
    from . import runtime
    rt = rt if rt is not None else runtime._runtime
    if rt is None or not rt.alive:
        return None
    if rt.participant_prefix is None:
        for info in rt.node.get_publishers_info_by_topic('/clock'):
            if info.node_name == runtime.INTERNAL_NODE_NAME:
                rt.participant_prefix = bytes(info.endpoint_gid[:12])
    return rt.participant_prefix


def _refuse_other_type(node: Any, kind: str, msg_type: Any, topic: str) -> None:
    """Raise before rcl would fail with ``invalid allocator`` and a C error dump.

    That happens when an endpoint of this very process already uses the topic with another
    type; endpoints of other processes are the graph's business (``topic_list`` notes them).
    """
    if not isinstance(msg_type, type) or not hasattr(node, '_Node__node'):
        return  # rclpy's own error (or check_node at add()) says it better
    local = _local_prefix()
    try:
        name = node.resolve_topic_name(topic)
        endpoints = [*node.get_publishers_info_by_topic(name),
                     *node.get_subscriptions_info_by_topic(name)]
    except Exception:  # an invalid name: rclpy's own message, with its caret, is best
        return
    mine = type_name(msg_type)
    others = sorted({e.topic_type for e in endpoints if bytes(e.endpoint_gid[:12]) == local
                     and e.topic_type != mine})
    if local is not None and others:
        verb = 'publish on' if kind == 'publisher' else 'subscribe to'
        raise Ros2nbError(f'{node.get_name()} would {verb} {name} as {mine}, but {name} already '
                          f'carries {", ".join(others)} in this kernel: both sides of a topic '
                          'must use the same message type.')


def guard_endpoint_types() -> None:
    """Make ``create_publisher``/``create_subscription`` refuse a second type on a topic.

    In one process rcl refuses such an endpoint with ``invalid allocator`` after printing a
    C error dump; across processes the two sides simply never meet.  Installed by
    :func:`ros2nb.start` in a notebook, so the learner gets one line instead, at their line.
    """
    from rclpy.node import Node
    for method, kind in (('create_publisher', 'publisher'),
                         ('create_subscription', 'subscription')):
        original = getattr(Node, method)
        if getattr(original, _GUARDED, False):
            continue

        def guarded(self: Any, msg_type: Any, topic: str, *args: Any,
                    _original: Any = original, _kind: str = kind, **kwargs: Any) -> Any:
            _refuse_other_type(self, _kind, msg_type, topic)
            return _original(self, msg_type, topic, *args, **kwargs)

        guarded.__doc__, guarded.__name__ = original.__doc__, method
        setattr(guarded, _GUARDED, True)
        setattr(Node, method, guarded)
