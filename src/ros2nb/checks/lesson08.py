"""Checks of notebook 08, parameters: the monitor's declared thresholds and its on-set callback.

Part of :mod:`ros2nb.checks`.  The judge creates the learner's ``TemperatureMonitor`` in a
subject that spins it in the background, and talks to the node's real parameter services
from its own node with rclpy's ``AsyncParameterClient`` (what ``ros2 param`` does): it lists,
gets and describes the parameters, and sets values.  A parameter counts by its effect: after
each change the judge publishes a reading from its own node and reads, on ``/rosout``, the
status the monitor gives it, so a threshold that was declared but is not used, or a change
answered but not made, shows.  Each part is graded on its own: the course's stand-in takes
the place of the other part (:mod:`ros2nb.subject.stand_ins`) when needed.
"""

from __future__ import annotations

from rcl_interfaces.msg import ParameterType
from rclpy.parameter import parameter_value_to_python

from .. import course
from ..errors import CheckFailed
from ..judge_interface import Judge
from .base import judged
from .drawn import chooser
from .parameter_monitor import CALLBACK, INVALID_RETURN, THRESHOLDS, ParameterMonitor


def _status_verdict(node: ParameterMonitor, reading: float, thresholds: dict[str, float],
                    after: str) -> None:
    """The status the monitor gives ``reading`` must follow ``thresholds`` (the effect)."""
    high, low = thresholds[course.HIGH_PARAMETER], thresholds[course.LOW_PARAMETER]
    want = 'High' if reading > high else 'Low' if reading < low else 'Normal'
    got = node.status(reading)
    if got != want:
        raise CheckFailed(f'{after}, {node.name} called {reading} °C {got or "nothing"}; with '
                          f'{course.HIGH_PARAMETER} = {high} and {course.LOW_PARAMETER} = {low} '
                          f'it is {want}: read both thresholds with self.get_parameter(...).value '
                          'in the callback, at every message, and keep the given callback.')


def _declared_verdict(node: ParameterMonitor) -> None:
    names = node.names()
    for name in THRESHOLDS:
        if name not in names:
            mine = ', '.join(n for n in names if n not in ('use_sim_time',
                                                           'start_type_description_service'))
            raise CheckFailed(f'{node.name} declares no parameter {name} (it has: '
                              f'{mine or "none of its own"}): declare it in __init__ with '
                              'self.declare_parameter().')
    for name, value in zip(THRESHOLDS, node.values(list(THRESHOLDS))):
        default = course.THRESHOLD_DEFAULTS_C[name]
        python = parameter_value_to_python(value)
        if value.type == ParameterType.PARAMETER_INTEGER:
            raise CheckFailed(f'{name} is an integer parameter ({python}): give it the float '
                              f'default {default}, or 25.5 can never be set.')
        if value.type != ParameterType.PARAMETER_DOUBLE:
            raise CheckFailed(f'{name} is not a number ({python!r}): its default is the '
                              f'constant {default}.')
        if python != default:
            raise CheckFailed(f'{name} starts at {python}; its default is {default}, the '
                              'constant of part 2.')


def _descriptor_verdict(node: ParameterMonitor) -> None:
    low, high = course.MIN_TEMPERATURE_C, course.MAX_TEMPERATURE_C
    for descriptor in node.descriptors(list(THRESHOLDS)):
        name = descriptor.name
        if not descriptor.description.strip():
            raise CheckFailed(f'{name} has no description: give its ParameterDescriptor a '
                              'description (ros2 param describe shows it).')
        if descriptor.read_only:
            raise CheckFailed(f'{name} is read-only, so nobody can change it while the node runs: '
                              'leave read_only out for the thresholds.')
        ranges = list(descriptor.floating_point_range)
        if not ranges:
            raise CheckFailed(f'{name} has no floating-point range: give its descriptor '
                              f'floating_point_range=[FloatingPointRange(...)] from {low} to '
                              f'{high} °C.')
        found = (ranges[0].from_value, ranges[0].to_value)
        if found != (low, high):
            raise CheckFailed(f'The range of {name} is [{found[0]}, {found[1]}] °C; thresholds '
                              f'may go from {low} to {high} °C, the sensor\'s clamp range.')


def _effect_verdict(node: ParameterMonitor) -> None:
    """Setting a threshold changes the status the monitor gives; out of range, it does not;
    an inverted pair is refused by the on-set callback the constructor registered (here the
    course's: only the registration is part 3's)."""
    current = dict(course.THRESHOLD_DEFAULTS_C)
    _status_verdict(node, 25.5, current, 'With the default thresholds')
    for name, value in ((course.HIGH_PARAMETER, 25.0), (course.LOW_PARAMETER, 21.0)):
        result = node.set(name, value)
        if not result.successful:
            why = result.reason or 'no reason'
            raise CheckFailed(f'Setting {name} to {value} was refused ({why}): a value inside '
                              'the range must be accepted.')
        current[name] = value
        _status_verdict(node, 25.5 if name == course.HIGH_PARAMETER else 20.5, current,
                        f'After ros2 param set {name} {value}')
    result = node.set(course.HIGH_PARAMETER, course.MAX_TEMPERATURE_C + 7.0)
    if result.successful:
        raise CheckFailed(f'Setting {course.HIGH_PARAMETER} to {course.MAX_TEMPERATURE_C + 7.0} '
                          f'was accepted: its floating_point_range must stop at '
                          f'{course.MAX_TEMPERATURE_C} °C.')
    _status_verdict(node, 25.5, current, 'After a refused change')
    result = node.set(course.LOW_PARAMETER, 25.5)
    if result.successful:
        raise CheckFailed(f'Setting {course.LOW_PARAMETER} to 25.5 while {course.HIGH_PARAMETER} '
                          f'is 25.0 was accepted: register the on-set callback in __init__ with '
                          f'self.add_on_set_parameters_callback(self.{CALLBACK}).')


def _monitor_parameters(judge: Judge) -> str:
    node = ParameterMonitor(judge, ('thresholds_on_set', 'thresholds_callback'))  # part 4's, given
    _declared_verdict(node)
    _descriptor_verdict(node)
    _effect_verdict(node)
    high, low = course.HIGH_PARAMETER, course.LOW_PARAMETER
    return (f'{node.name} declares {high} = {course.HIGH_ABOVE_C} and {low} = '
            f'{course.LOW_BELOW_C}, described, in [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C; setting them changes the statuses it logs.')


@judged
def check_monitor_parameters(judge: Judge) -> str:
    """Check part 3 of notebook 08: the monitor declares its two thresholds as parameters.

    Creates your ``TemperatureMonitor`` (with the course's on-set callback, so that only your
    constructor counts) and asks its parameter services, as ``ros2 param list/get/describe/
    set`` do: both thresholds declared, doubles with their defaults, each with a description
    and a floating-point range of [18.0, 28.0] °C, not read-only; then sets them and checks,
    from the statuses it logs for the grader's readings, that the node uses what was set.

    Introduced in ``08-parameters.ipynb``.

    :raises CheckFailed: naming the parameter and what its declaration lacks.
    """
    return _monitor_parameters(judge)


#: (name, value, must succeed, the reading that shows the thresholds in force afterwards) in
#: the order the check sets them.
STEPS = ((course.HIGH_PARAMETER, 25.0, True, 25.5), (course.LOW_PARAMETER, 25.5, False, 24.0),
         (course.LOW_PARAMETER, 25.0, False, 24.0), (course.LOW_PARAMETER, 21.0, True, 20.5),
         (course.HIGH_PARAMETER, 20.5, False, 24.0))




def _drawn_steps(judge: Judge) -> list[tuple[str, float, bool, float]]:
    """Four changes drawn for this run (:mod:`.drawn`), made after :data:`STEPS` (which leave
    high at 25.0 and low at 21.0): low and high moved to valid values, then a low at or
    above the new high and a high at or below the new low, each refused; every reading lies
    where only the thresholds in force give the status the check expects."""
    source = chooser(judge, '08 threshold changes')
    low = round(source.choice((source.uniform(18.5, 20.5), source.uniform(21.5, 23.0))), 2)
    high = round(source.choice((source.uniform(max(low + 1.0, 22.0), 24.5),
                                source.uniform(25.5, 27.5))), 2)
    too_low = round(source.uniform(course.MIN_TEMPERATURE_C, low), 2)
    too_high = round(source.uniform(high, course.MAX_TEMPERATURE_C), 2)
    between = round((low + high) / 2, 2)
    return [(course.LOW_PARAMETER, low, True, round((low + 21.0) / 2, 2)),
            (course.HIGH_PARAMETER, high, True, round((high + 25.0) / 2, 2)),
            (course.LOW_PARAMETER, too_high, False, between),
            (course.HIGH_PARAMETER, too_low, False, between)]


def _refusal_hint(name: str) -> str:
    if name == course.HIGH_PARAMETER:
        return (f'your callback gets only the parameters being set: compare with the current '
                f'value of {course.LOW_PARAMETER} (self.get_parameter(...).value).')
    return f'refuse unless {course.LOW_PARAMETER} stays strictly below {course.HIGH_PARAMETER}.'


def _declared(judge: Judge) -> ParameterMonitor:
    """The learner's monitor with its own constructor, or the course's when theirs does not
    declare and describe both thresholds as part 3 asks (a mistake in part 3 costs part 3
    only: parameter services that answer from a table of their own describe no range)."""
    try:
        node = ParameterMonitor(judge, ())
        _declared_verdict(node)
        _descriptor_verdict(node)
        return node
    except CheckFailed:
        return ParameterMonitor(judge, ('thresholds_init',))


class _AcceptedInvalid(CheckFailed):
    """A change that leaves ``low_below_c`` at or above ``high_above_c`` was accepted."""


def _threshold_callback(judge: Judge) -> str:
    node = _declared(judge)
    try:
        return _threshold_steps(node)
    except _AcceptedInvalid:
        if node.stand_ins or not _never_registered(judge):
            raise
    # The constructor never registers the callback (part 3's mistake, costing part 3 only):
    # the course's constructor registers the learner's callback.
    return _threshold_steps(ParameterMonitor(judge, ('thresholds_init',)))


def _never_registered(judge: Judge) -> bool:
    """True when the learner's constructor registers no on-set callback: with the course's
    callback in the learner's class, an inverted pair is still accepted."""
    try:
        probe = ParameterMonitor(judge, ('thresholds_on_set',))
        result = probe.set(course.LOW_PARAMETER,
                           course.THRESHOLD_DEFAULTS_C[course.HIGH_PARAMETER] + 1)
    except CheckFailed:
        return False
    return bool(getattr(result, 'successful', False))


def _threshold_steps(node: ParameterMonitor) -> str:
    """Part 4 on ``node``: each change of :data:`STEPS` and of :func:`_drawn_steps`, its
    answer and the statuses after."""
    current = dict(course.THRESHOLD_DEFAULTS_C)
    steps = [*STEPS, *_drawn_steps(node.judge)]
    for name, value, valid, reading in steps:
        other = course.LOW_PARAMETER if name == course.HIGH_PARAMETER else course.HIGH_PARAMETER
        result = node.set(name, value)
        if result is None or not hasattr(result, 'successful'):
            raise CheckFailed(f'Setting {name} got no answer: {CALLBACK} must return a '
                              'SetParametersResult.')
        if not result.successful and result.reason == INVALID_RETURN:
            raise CheckFailed(f'{CALLBACK} returned something else than a SetParametersResult '
                              f'(rclpy: "{INVALID_RETURN}"): return '
                              'SetParametersResult(successful=..., reason=...).')
        if valid and not result.successful:
            raise CheckFailed(f'Setting {name} to {value} while {other} is {current[other]} was '
                              f'refused ({result.reason or "no reason"}): that pair is valid, '
                              'return SetParametersResult(successful=True) for it.')
        if not valid and result.successful:
            raise _AcceptedInvalid(f'Setting {name} to {value} while {other} is '
                                   f'{current[other]} was accepted: {_refusal_hint(name)}')
        if not valid and not result.reason.strip():
            raise CheckFailed(f'Setting {name} to {value} was refused without a reason: give the '
                              'SetParametersResult a reason that says why (ros2 param set shows '
                              'it).')
        if valid:
            current[name] = value
        said = 'accepted' if valid else 'refused'
        _status_verdict(node, reading, current, f'After {name} = {value} was {said}')
    got = [parameter_value_to_python(v) for v in node.values([course.HIGH_PARAMETER,
                                                                course.LOW_PARAMETER])]
    if got != [current[course.HIGH_PARAMETER], current[course.LOW_PARAMETER]]:
        raise CheckFailed(f'After the accepted changes the thresholds are {got}, expected '
                          f'{[current[course.HIGH_PARAMETER], current[course.LOW_PARAMETER]]}: '
                          'do not change parameters inside the callback.')
    return (f'{CALLBACK} accepts valid thresholds and refuses, with a reason, '
            f'{len([s for s in steps if not s[2]])} changes that would put '
            f'{course.LOW_PARAMETER} at or above {course.HIGH_PARAMETER}; the statuses follow.')


@judged
def check_threshold_callback(judge: Judge) -> str:
    """Check part 4 of notebook 08: the on-set callback refuses inverted thresholds.

    Sets the thresholds of your running monitor through its ``set_parameters`` service, as
    ``ros2 param set`` does: valid pairs must be accepted, and every change that leaves
    ``low_below_c`` at or above ``high_above_c`` refused with a reason (five changes, two of
    them drawn for this run); after each change the statuses the monitor logs for the
    grader's readings follow the thresholds in force.

    Introduced in ``08-parameters.ipynb``.

    :raises CheckFailed: naming the change and what the node answered.
    """
    return _threshold_callback(judge)
