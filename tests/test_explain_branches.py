"""A name set in some branches of an if and read after it: the line names the branch the
call took, never the line that read the name (which is right)."""

import importlib.util

import pytest

from ros2nb.explain.everyday import cause_place, everyday_explanation

LEARNER = '''
HIGH_ABOVE_C, LOW_BELOW_C = 26.0, 20.0


def branch_left_empty(temperature_c):
    if temperature_c > HIGH_ABOVE_C:
        pass
    elif temperature_c < LOW_BELOW_C:
        status = 'Low'
    else:
        status = 'Normal'
    return f'{temperature_c:.2f} {status}'


def no_else(temperature_c):
    if temperature_c > HIGH_ABOVE_C:
        status = 'High'
    elif temperature_c < LOW_BELOW_C:
        status = 'Low'
    return status


def called_in_condition(temperature_c):
    if str(temperature_c) == '26.5':
        print(temperature_c)
    else:
        status = 'Normal'
    return status
'''


@pytest.fixture
def learner(tmp_path):
    path = tmp_path / 'monitor.py'
    path.write_text(LEARNER)
    spec = importlib.util.spec_from_file_location('monitor', path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _told(function, reading):
    with pytest.raises(UnboundLocalError) as caught:
        function(reading)
    return everyday_explanation(caught.value), cause_place(caught.value)


@pytest.mark.parametrize('function, reading, words, where', [
    ('branch_left_empty', 26.5, 'status has no value here: branch_left_empty sets it in the '
     'other branches of its if/elif/else, but not in the branch where temperature_c > '
     'HIGH_ABOVE_C, which this call took: set status there too.', 'monitor.py line 7: pass'),
    ('no_else', 22.0, 'status has no value here: no_else sets it only when temperature_c > '
     'HIGH_ABOVE_C or temperature_c < LOW_BELOW_C, and none of these held for this call: add '
     'an else that sets status.', 'monitor.py line 18: elif temperature_c < LOW_BELOW_C:'),
    # A condition with a call is not run again: the one branch that sets nothing is named.
    ('called_in_condition', 26.5, "status has no value here: called_in_condition sets it in "
     "the other branches of its if/elif/else, but not in the branch where str(temperature_c) "
     "== '26.5', which this call took: set status there too.",
     'monitor.py line 25: print(temperature_c)'),
])
def test_the_branch_taken_is_named_not_the_line_that_reads(learner, function, reading, words,
                                                          where):
    assert _told(getattr(learner, function), reading) == (words, where)


def test_a_branch_that_sets_the_name_is_no_cause(learner):
    assert learner.branch_left_empty(22.0) == '22.00 Normal'
