"""One line for the ROS settings beginners get wrong: QoS settings, parameters, ``-r``/``-p`` rules.

Part of :mod:`ros2nb.explain` (:func:`~ros2nb.explain.exceptions.explain_exception` asks
here first); runs wherever learner code does: the kernel and the judge's subjects.  rclpy
and rcl answer these with a bare ``assert``, a tuple printed as text or lexeme numbers; each
function here returns the line that says what is wrong and what to write, or None.
"""

from __future__ import annotations

import contextlib
import os
import re
import warnings
from typing import Any, Iterator, Optional


#: The policy class of each QoSProfile setting that takes one.
_QOS_POLICIES = {'history': 'QoSHistoryPolicy', 'reliability': 'QoSReliabilityPolicy',
                 'durability': 'QoSDurabilityPolicy', 'liveliness': 'QoSLivelinessPolicy'}
_QOS_DURATIONS = ('lifespan', 'deadline', 'liveliness_lease_duration')


def qos_setting(exc: AssertionError, frames: list[Any]) -> Optional[str]:
    """A QoSProfile setting given a value of the wrong type (a policy as a string, say):
    rclpy's bare ``assert`` says nothing, so the line names the setting and what it takes.

    :param frames: the exception's frames, outermost first (rclpy's setter last).
    Introduced in ``09-qos.ipynb``.
    """
    last = frames[-1] if frames else None
    if last is None or not last.f_code.co_filename.endswith(os.path.join('rclpy', 'qos.py')):
        return None
    setting, value = last.f_code.co_name, last.f_locals.get('value')
    got = f'not {type(value).__name__} {value!r}'
    if setting in _QOS_POLICIES:
        policy = _QOS_POLICIES[setting]
        member = str(value).upper() if isinstance(value, str) and str(value).isidentifier() \
            else 'NAME'
        return (f"QoSProfile's {setting} takes a {policy}, {got}: from rclpy.qos import "
                f'{policy}, then {setting}={policy}.{member}.')
    if setting == 'depth':
        return f"QoSProfile's depth takes a whole number, {got}: write depth=10, no quotes."
    if setting in _QOS_DURATIONS:
        return (f"QoSProfile's {setting} takes a Duration, {got}: from rclpy.duration import "
                f'Duration, then {setting}=Duration(seconds=...).')
    return None


#: The start of rclpy's warning for ``depth=0`` with KEEP_LAST (it then uses the system default).
_ZERO_DEPTH = "A zero depth with KEEP_LAST doesn't make sense"


@contextlib.contextmanager
def zero_depth_refused() -> Iterator[None]:
    """Inside, rclpy's warning for ``depth=0`` with KEEP_LAST is raised as an error at the
    learner's line (:func:`zero_depth` explains it) instead of printed under a passing check.

    Used wherever a check calls the learner's profile function, in the kernel and in a
    subject; introduced in ``09-qos.ipynb``.
    """
    with warnings.catch_warnings():
        warnings.filterwarnings('error', message=re.escape(_ZERO_DEPTH), category=UserWarning)
        yield


def zero_depth(exc: BaseException, text: str) -> Optional[str]:
    """The line for a KEEP_LAST depth of 0 refused by :func:`zero_depth_refused`, or None."""
    if not (isinstance(exc, UserWarning) and text.startswith(_ZERO_DEPTH)):
        return None
    return ("depth=0 with KEEP_LAST does not mean 'keep none': rclpy leaves the depth to the DDS "
            "vendor's default, so the profile no longer says what it keeps: write the number of "
            'messages to keep, e.g. depth=1 for the newest only.')


#: rclpy's refusal of ``declare_parameter(name, None, descriptor)``.
_NO_DEFAULT = ('Cannot declare a statically typed parameter with default value of type '
               'PARAMETER_NOT_SET')


def without_c_location(text: str) -> str:
    """rcl's message without the C source location it ends with (``, at /.../x.c:384``)."""
    return re.sub(r',? at /\S+\.c:\d+\s*$', '', text.strip())


def settings_mistake(exc: BaseException, text: str, frames: list[Any]) -> Optional[str]:
    """The line for any mistake of this module's kinds (parameters, ``-r``/``-p`` rules, a
    depth of 0), or None.

    :param frames: the exception's frames, outermost first.
    """
    kind = type(exc).__name__
    return (parameter_mistake(kind, text) or ros_arguments_mistake(kind, text)
            or zero_depth(exc, text) or unset_parameter(exc, text, frames))


def unset_parameter(exc: BaseException, text: str, frames: list[Any]) -> Optional[str]:
    """A parameter declared without a default holds None (rclpy's PARAMETER_NOT_SET): the
    TypeError of using it as a number, explained.  Introduced in ``08-parameters.ipynb``.

    :param frames: the exception's frames, outermost first.
    """
    if isinstance(exc, ValueError) and text.startswith(_NO_DEFAULT):
        return ('declare_parameter got no default (None): rclpy cannot give a parameter with '
                'a descriptor a type without one (PARAMETER_NOT_SET): pass its default value '
                'as the second argument, before the descriptor.')
    if isinstance(exc, (TypeError, ValueError)) and "'str'" in text:
        for frame in reversed(frames):
            parameters = getattr(frame.f_locals.get('self'), '_parameters', None)
            texts = sorted((name, parameter.value) for name, parameter in (
                parameters or {}).items() if isinstance(getattr(parameter, 'value', None), str)
                and re.fullmatch(r'-?\d+(?:\.\d+)?', parameter.value))
            if texts:
                return (f"the parameter '{texts[0][0]}' holds the text {texts[0][1]!r}, not a "
                        'number: declare it with its default as a number, without quotes.')
    if not isinstance(exc, TypeError) or 'NoneType' not in text:
        return None
    for frame in reversed(frames):
        parameters = getattr(frame.f_locals.get('self'), '_parameters', None)
        if isinstance(parameters, dict):
            unset = sorted(name for name, parameter in parameters.items()
                           if getattr(getattr(parameter, 'type_', None), 'name', '') == 'NOT_SET')
            if unset:
                return (f"the parameter '{unset[0]}' holds None: it was declared without a "
                        'default, so rclpy gives it the type PARAMETER_NOT_SET; pass its '
                        'default value to declare_parameter as the second argument.')
    return None


_OUT_OF_RANGE = re.compile(r'Parameter (\w+) out of range Min: ([-\d.e+]+), Max: ([-\d.e+]+), '
                           r'value: ([-\d.e+]+)')
_WRONG_PARAMETER_TYPE = re.compile(r"Trying to set parameter '(\w+)' to '([^']*)' of type "
                                   r"'(\w+)', expecting type '(\w+)'")


def parameter_mistake(kind: str, text: str) -> Optional[str]:
    """The classic parameter mistakes, each with its fix: read before declared, the wrong type
    given with ``-p``, the on-set callback called instead of passed.  None for any other error.

    Introduced in ``08-parameters.ipynb``.

    :param kind: the exception's class name (``InvalidParameterTypeException``): these are
        told apart by name and message alone, also from the last line a process printed.
    :param text: its message.
    """
    if kind == 'ParameterAlreadyDeclaredException':
        twice = re.findall(r"'(\w+)'", text)
        return (f"the parameter '{twice[0] if twice else '?'}' is declared twice: declare each "
                'parameter once, in __init__.')
    ranged = _OUT_OF_RANGE.search(text) if kind == 'InvalidParameterValueException' else None
    if ranged:
        name, low, high, value = ranged.groups()
        return (f"the value {value} of '{name}' is outside the range its descriptor allows, "
                f'{low} to {high}: its floating_point_range must run from MIN_THRESHOLD_C '
                '(from_value=) to MAX_THRESHOLD_C (to_value=).')
    if kind == 'ParameterNotDeclaredException':
        name = text.rsplit(': ', 1)[-1]
        return (f"the parameter '{name}' was read (or set) before it was declared: call "
                f"self.declare_parameter('{name}', default) first, in __init__, then "
                'get_parameter.')
    found = _WRONG_PARAMETER_TYPE.search(text) if kind == 'InvalidParameterTypeException' \
        else None
    if found:
        name, value, given, wanted = found.groups()
        fix = (f'{value}.0, e.g. -p {name}:={value}.0' if (given, wanted) == ('INTEGER', 'DOUBLE')
               else f'a {wanted.lower()} value')
        return (f"the parameter '{name}' holds a {wanted.lower()} (its default decides), and "
                f"'{value}' is {'an' if given[0] in 'AEIOU' else 'a'} {given.lower()}: give it "
                f'{fix}.')
    if kind == 'TypeError' and text.startswith("('Callback must be callable"):
        return ('add_on_set_parameters_callback takes the callback itself, and was given what '
                'calling it returned: pass self.on_parameters_set, without ().')
    return None


_ROS_RULE = re.compile(r"Couldn't parse (remap|parameter override) rule: '(-[rp]) ([^']*)'")


def ros_arguments_mistake(kind: str, text: str) -> Optional[str]:
    """rcl's refusal of a ``-r`` or ``-p`` rule (``Expected lexeme type 19...``), as the
    rule, what is wrong with it, and how it is written; None for any other error.

    Introduced in ``06-five-promises.ipynb`` (a room's namespace) and ``08-parameters.ipynb``.

    :param kind: the exception's class name: ``RCLInvalidROSArgsError`` for a node's
        arguments, ``RCLError`` for ``rclpy.init``'s (a program's command line).
    :param text: its message.
    """
    if kind == 'UnknownROSArgsError':  # rules ROS found outside any flag
        return (f'ROS did not read {text.strip()}: every rule goes right after its flag, '
                "after '--ros-args': ['--ros-args', '-r', '__ns:=/kitchen'].")
    trailing = re.search(r"trailing (-[rp]) flag", text)
    if trailing and kind in ('RCLInvalidROSArgsError', 'RCLError'):
        return (f'the {trailing.group(1)} at the end of the arguments has no rule after it: '
                "write each rule right after its flag: ['--ros-args', '-r', '__ns:=/kitchen'].")
    found = _ROS_RULE.search(text) if kind in ('RCLInvalidROSArgsError', 'RCLError') else None
    if found is None:
        return None
    kind, flag, rule = found.groups()
    name, _, value = rule.partition(':=') if ':=' in rule else rule.partition('=')
    if kind == 'remap' and ':=' not in rule:
        why = 'a remap is written FROM:=TO, with :='
    elif kind == 'remap' and name == '__ns' and not value.startswith('/'):
        why = f'a namespace starts with a slash: __ns:=/{value}'
    elif kind == 'remap':
        why = 'a remap is FROM:=TO, each a valid name (letters, digits, _ and /)'
    elif name.startswith('__'):
        why = (f'{name} is not a parameter but a remap: -r {rule}'
               + ('' if value.startswith('/') or name != '__ns' else f' (with a slash: /{value})'))
    else:
        why = 'a parameter is written -p NAME:=VALUE, the name in letters, digits and _'
    return f"ROS could not read the {kind} rule '{flag} {rule}': {why}."


#: The last line of a Python traceback: the exception's (dotted) class and its message.
_ERROR_LINE = re.compile(r'^(?:\[[^\]]*\] )?(?:[A-Za-z_]\w*\.)*'  # ros2_run's [label-N]
                         r'(?P<kind>[A-Za-z_]\w*(?:Error|Exception)): (?P<text>.*)$')


def output_mistake(lines: list[str]) -> Optional[str]:
    """The line for a known mistake behind the error a process printed last (the last line of
    its traceback), or None: what a node that ``ros2 run`` started says is told apart by the
    exception's name and message alone.

    Introduced in ``08-parameters.ipynb`` (``-p high_above_c:=25`` for a double).

    :param lines: the process's output, in order.
    """
    for line in reversed(lines):
        found = _ERROR_LINE.match(line.strip())
        if found:
            kind, text = found['kind'], found['text']
            return parameter_mistake(kind, text) or ros_arguments_mistake(kind, text)
    return None
