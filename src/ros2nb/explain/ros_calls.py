"""One line for a call to rclpy whose arguments came in the wrong order or of the wrong kind.

Part of :mod:`ros2nb.explain` (:func:`~ros2nb.explain.exceptions.explain_exception` asks
here first); runs wherever learner code does.  ``create_publisher(TOPIC, Float32, 10)``
fails deep inside rclpy, in its C++ binding ("rclpy_resolve_name(): incompatible function
arguments ... Invoked with: <rclpy._rclpy_pybind11.Node ...>"), or as a ``float()`` of a
method; whatever rclpy raised, the line here names the call the learner wrote, what went
where, and the order the call takes.  Introduced in ``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

from types import FrameType
from typing import Any, Callable, Optional

from .frames import frames_of, is_library_file


def _message_type(value: Any) -> bool:
    return isinstance(value, type) and hasattr(value, 'get_fields_and_field_types')


def _depth(value: Any) -> bool:
    return (isinstance(value, int) and not isinstance(value, bool)) or \
        type(value).__name__ == 'QoSProfile'


def _seconds(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _callback(value: Any) -> bool:
    return callable(value) and not isinstance(value, type)


def _descriptor(value: Any) -> bool:
    return value is None or type(value).__name__ == 'ParameterDescriptor'


#: What each parameter takes: its test, and how the line names it.
KINDS: dict[str, tuple[Callable[[Any], bool], str]] = {
    'name': (lambda value: isinstance(value, str), "the parameter's name ('high_above_c')"),
    'value': (lambda value: not _descriptor(value) or value is None,
              'its default value (26.0)'),
    'descriptor': (_descriptor, 'its ParameterDescriptor(...)'),
    'rawdata': (lambda value: isinstance(value, (bytes, bytearray, memoryview)),
                "the message's raw bytes (raw)"),
    'typ': (lambda value: isinstance(value, str), 'its type (connection.msgtype)'),
    'msg_type': (_message_type, 'the message type (Float32)'),
    'topic': (lambda value: isinstance(value, str), "the topic ('temperature')"),
    'qos_profile': (_depth, 'the queue depth (10)'),
    'callback': (_callback, 'the callback (a method, without ())'),
    'timer_period_sec': (_seconds, 'the period in seconds (1.0)'),
}
#: What to give for a parameter given a value of the wrong kind.
GIVE = {'qos_profile': 'a whole number, without quotes (QUEUE_DEPTH, 10)',
        'timer_period_sec': 'a number of seconds, without quotes (PUBLISH_PERIOD_S, 1.0)',
        'msg_type': 'the message type itself, without parentheses (Float32)',
        'topic': "the topic's name as text (TOPIC, 'temperature')",
        'callback': 'the method itself, without parentheses (self.publish_temperature)'}
#: The rclpy calls a beginner writes, with their parameters in order.
CALLS = {'declare_parameter': ('name', 'value', 'descriptor'),
         'deserialize': ('rawdata', 'typ'),  # rosbags' reader (notebook 10)
         'create_publisher': ('msg_type', 'topic', 'qos_profile'),
         'create_subscription': ('msg_type', 'topic', 'callback', 'qos_profile'),
         'create_timer': ('timer_period_sec', 'callback')}


def shown(value: Any) -> str:
    """A value as the learner wrote it, near enough: a class by name, a method as self.name."""
    if isinstance(value, type):
        return value.__name__
    if hasattr(value, '__self__') and hasattr(value, '__name__'):
        return f'self.{value.__name__}'
    if value is None:
        return 'None'
    text = repr(value)
    return text if len(text) <= 40 else f'a {type(value).__name__}'


def _called(exc: BaseException) -> Optional[FrameType]:
    """The frame of the rclpy call the learner's own code made, where the error went through
    one of :data:`CALLS`: the first library frame of one after their innermost frame."""
    frames = list(frames_of(exc))
    learner = [i for i, f in enumerate(frames) if not is_library_file(f.f_code.co_filename)]
    if not learner:
        return None
    for entered in frames[learner[-1] + 1:]:  # past a wrapper (the kernel's guards)
        names = CALLS.get(entered.f_code.co_name, ())
        if names and all(name in entered.f_locals for name in names):
            return entered
    return None


def wrong_arguments(exc: BaseException) -> Optional[str]:
    """The line for a call of :data:`CALLS` with an argument of the wrong kind (in the wrong
    place), whatever rclpy raised for it; None when every argument is of its kind."""
    frame = _called(exc)
    if frame is None:
        return None
    call = frame.f_code.co_name
    values = {name: frame.f_locals.get(name) for name in CALLS[call]}
    wrong = [name for name in CALLS[call] if not KINDS[name][0](values[name])]
    if not wrong:
        return None
    got = ' and '.join(f'{shown(values[name])} {"came " if i == 0 else ""}where '
                       f'{KINDS[name][1].split(" (")[0]} belongs' for i, name in enumerate(wrong))
    kinds = [KINDS[name][1].split(' (')[0] for name in CALLS[call]]
    order = f'{", ".join(kinds[:-1])} and {kinds[-1]}'
    belongs = any(KINDS[other][0](values[name]) for name in wrong for other in CALLS[call]
                  if other != name)
    if not belongs:  # a value of the wrong kind in its place: what that place takes
        name = wrong[0]
        return (f'{call} got {shown(values[name])} where {KINDS[name][1].split(" (")[0]} '
                f'belongs: give {GIVE.get(name, KINDS[name][1])}.')
    return f'{call} got its arguments in the wrong order: {got}; it takes {order}, in that order.'
