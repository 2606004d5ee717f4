"""The checks of notebook 08 (parameters) against the mistakes learners make: one line each.

As tests/test_checks.py: this process is the judge, the learner's monitor runs in real
subject processes, and the verdicts come from the judge's own parameter client talking to
the monitor's real parameter services. The monitor is the solution notebook's (its
``%%part`` cells), so it never goes stale; it passes both checks, so every failure below is
the planted mistake's.
"""

import os
import re

import nbformat
import pytest

from ros2nb import checks, course
from ros2nb.errors import CheckFailed

from judging import run_check

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]

SOLUTION = os.path.join(os.path.dirname(__file__), '..', 'solutions', '08-parameters.ipynb')
SUB = course.SUBSCRIBER_FILE


def solution_monitor() -> str:
    """The monitor file that notebook 08's %%part cells write (parts 1 to 4)."""
    parts = {}
    for cell in nbformat.read(SOLUTION, as_version=4).cells:
        first, _, body = cell.source.partition('\n')
        if cell.cell_type == 'code' and first.startswith('%%part {SUBSCRIBER}'):
            lines = [line for line in body.splitlines() if not line.strip().startswith('###')]
            parts[int(first.split()[-1])] = '\n'.join(lines).rstrip('\n')
    return '\n\n'.join(parts[n] for n in sorted(parts)) + '\n'


REFERENCE = solution_monitor()


def write_monitor(session, text: str) -> None:
    (session.workspace / SUB).write_text(text)


def test_the_solution_passes_both_checks(session, capsys):
    write_monitor(session, REFERENCE)
    run_check(session, checks.check_monitor_parameters)
    run_check(session, checks.check_threshold_callback)
    out = capsys.readouterr().out
    assert out.count('Check passed:') == 2, out


DECLARE = ("        self.declare_parameter('low_below_c', LOW_BELOW_C, ParameterDescriptor(\n"
           "            description='Readings strictly below this are Low (°C)',\n"
           "            floating_point_range=in_clamp_range))\n")
REFUSE = ('low_c >= high_c', "reason=f'low_below_c ({low_c}) must stay below high_above_c "
          "({high_c})')")
DECLARATION_MISTAKES = [
    ('placeholder', 'in_clamp_range = [', 'raise NotImplementedError()\n        in_clamp_range = [',
     r'TemperatureMonitor\(\) still raises NotImplementedError: write your code where it says'),
    ('one not declared', DECLARE, '',
     r'TemperatureMonitor\(\) reads the parameter low_below_c before it declares it, or never '
     r'declares it: declare it'),
    ('name typo', "declare_parameter('high_above_c'", "declare_parameter('high_above'",
     r'TemperatureMonitor\(\) reads the parameter high_above_c before it declares it, or never'),
    ('read before declared', "        self.declare_parameter('high_above_c', HIGH_ABOVE_C,",
     "        self.get_parameter('high_above_c')\n"
     "        self.declare_parameter('high_above_c', HIGH_ABOVE_C,",
     r'TemperatureMonitor\(\) reads the parameter high_above_c before it declares it'),
    # told at once, not after a long wait blamed on a busy machine
    ('no parameter services', "super().__init__('temperature_monitor')",
     "super().__init__('temperature_monitor', start_parameter_services=False)",
     r'TemperatureMonitor has no parameter services \(was it made with '
     r'start_parameter_services=False\?\)'),
    # issue 37: rclpy's "PARAMETER_NOT_SET", a None formatted as a number, a part-4 line
    ('no default', "'high_above_c', HIGH_ABOVE_C, ParameterDescriptor(",
     "'high_above_c', None, ParameterDescriptor(",
     r'TemperatureMonitor\(\) raised: declare_parameter got no default \(None\): .*pass its '
     r'default value as the second argument'),
    ('no default, no descriptor', DECLARE, "        self.declare_parameter('low_below_c')\n",
     r"TemperatureMonitor\(\) raised: the parameter 'low_below_c' holds None: it was declared "
     r'without a default'),
    ('the callback called, not passed',
     'self.add_on_set_parameters_callback(self.on_set_thresholds)',
     'self.add_on_set_parameters_callback(self.on_set_thresholds())',
     r'TemperatureMonitor\(\) raised: on_set_thresholds\(\) was called here, with nothing for its '
     r'\w+, and add_on_set_parameters_callback would get what it returned: pass the method '
     r'itself, without \(\): self\.on_set_thresholds; .*\(temperature_subscriber\.py line \d+: '
     r'self\.add_on_set_parameters_callback\(self\.on_set_thresholds\(\)\)\)$'),
    ('registration forgotten',
     '        self.add_on_set_parameters_callback(self.on_set_thresholds)\n',
     '', r'was accepted: register the on-set callback in __init__ with '
         r'self\.add_on_set_parameters_callback'),
    ('integer default', "'high_above_c', HIGH_ABOVE_C,", "'high_above_c', 26,",
     r'high_above_c is an integer parameter \(26\): give it the float default 26.0'),
    ('wrong default', "'low_below_c', LOW_BELOW_C,", "'low_below_c', 18.0,",
     r'low_below_c starts at 18.0; its default is 20.0'),
    ('no description', "description='Readings strictly above this are High (°C)',", '',
     r'high_above_c has no description: give its ParameterDescriptor a description'),
    ('read-only', "description='Readings strictly above this are High (°C)',",
     "description='Readings strictly above this are High (°C)', read_only=True,",
     r'high_above_c is read-only, so nobody can change it while the node runs'),
    ('no range', 'floating_point_range=in_clamp_range))\n        self.declare_parameter(',
     '))\n        self.declare_parameter(',
     r'high_above_c has no floating-point range: give its descriptor floating_point_range='),
    ('wrong range', "to_value=MAX_THRESHOLD_C)]\n        self.declare_parameter('high",
     "to_value=30.0)]\n        self.declare_parameter('high",
     r'The range of high_above_c is \[18.0, 30.0\] °C; thresholds may go from 18.0 to 28.0 °C'),
]
CALLBACK_MISTAKES = [
    ('placeholder', 'new = {parameter.name',
     'raise NotImplementedError()\n        new = {parameter.name',
     r'still raises NotImplementedError: write your code where it says YOUR CODE HERE'),
    ('only the parameters being set', "self.get_parameter('high_above_c').value)\n        low_c",
     "HIGH_ABOVE_C)\n        low_c",
     r'Setting low_below_c to 25.5 while high_above_c is 25.0 was accepted: refuse unless'),
    ('the other one forgotten', "new.get('low_below_c', self.get_parameter('low_below_c').value)",
     "new.get('low_below_c', LOW_BELOW_C)",
     r'Setting high_above_c to 20.5 while low_below_c is 21.0 was accepted: your callback gets '
     r'only the parameters being set'),
    ('indexed by a name not set',
     "high_c = new.get('high_above_c', self.get_parameter('high_above_c').value)",
     "high_c = new['high_above_c']",
     r"on_set_thresholds raised KeyError: 'high_above_c' for ros2 param set low_below_c 25\.5: it "
     r'gets only the parameters being set'),
    ('equal allowed', 'low_c >= high_c', 'low_c > high_c',
     r'Setting low_below_c to 25.0 while high_above_c is 25.0 was accepted'),
    ('no reason', REFUSE[1], "reason='')",
     r'Setting low_below_c to 25.5 was refused without a reason'),
    ('refuses everything', 'return SetParametersResult(successful=True)',
     "return SetParametersResult(successful=False, reason='no')",
     r'Setting high_above_c to 25.0 while low_below_c is 20.0 was refused \(no\): that pair is '
     r'valid'),
    ('returns a bool', 'return SetParametersResult(successful=True)', 'return True',
     r'on_set_thresholds returned something else than a SetParametersResult'),
]
MISTAKES = ([(checks.check_monitor_parameters, *m) for m in DECLARATION_MISTAKES]
            + [(checks.check_threshold_callback, *m) for m in CALLBACK_MISTAKES])


def test_a_forgotten_registration_costs_its_own_part_only(session, capsys):
    """Part 3 registers the callback; part 4's callback, right, is graded with the course's
    registration (before: part 4 blamed the correct callback for accepting everything)."""
    write_monitor(session, REFERENCE.replace(
        '        self.add_on_set_parameters_callback(self.on_set_thresholds)\n', '', 1))
    capsys.readouterr()
    run_check(session, checks.check_threshold_callback)
    assert 'Check passed: on_set_thresholds accepts valid thresholds' in capsys.readouterr().out


@pytest.mark.parametrize('check, label, old, new, pattern', MISTAKES,
                         ids=[f'{m[0].__name__}: {m[1]}' for m in MISTAKES])
def test_a_mistake_gets_one_line(session, check, label, old, new, pattern):
    assert old in REFERENCE, old
    write_monitor(session, REFERENCE.replace(old, new, 1))
    with pytest.raises(CheckFailed) as caught:
        run_check(session, check)
    message = str(caught.value).splitlines()[0] if type(caught.value) is not CheckFailed \
        else str(caught.value)
    assert re.search(pattern, message), message
    assert '\n' not in message
    said = re.sub(r' \([\w.]+ line \d+: .*\)\.?$', '', message)  # the learner's own line aside
    assert "declare_parameter('" not in said and 'SetParametersResult(successful=False' \
        not in said
