"""What the mutation run calls a good answer (``tests/mutation_verdicts.py``), held to cases.

Each case is one mutant's outcome as ``mutation_runs`` keeps it (the lab's line and the
grader's), written out by hand: the answers the issue's audit and walks found (a made-up
line, the course's own wrapper named, a number the code never produced, a "did you mean" of
a builtin, lines at unchanged code, the lab and the grader apart), each judged bad, beside
answers that are good.  Pure logic: no kernel, no judge.
"""

from __future__ import annotations

import copy
from types import SimpleNamespace

import pytest

from ros2nb.judge.subjects import SubjectProcess
from ros2nb.subject_interface import Call

from mutation_cells import answers
from mutation_mistakes import mutants
from mutation_runs import RETURNED, Produced, _returns_kept
from mutation_verdicts import (EXCUSES, MOST_EXCUSES, equivalent, names_change, stated_numbers,
                               verdict)

SENSOR_CALLBACK = next(a for a in answers('03') if a.key == '03-sensor-callback')
SENSOR_CONSTRUCTOR = next(a for a in answers('03') if a.key == '03-sensor-constructor')
MONITOR_CALLBACK = next(a for a in answers('04') if a.key == '04-monitor-callback')
ROOM_ARGUMENTS = next(a for a in answers('06') if a.key == '06-room-arguments')


def shown(*error: str, produced: tuple[float, ...] = ()) -> dict:
    return {'lines': [], 'error': list(error), 'ename': 'CheckFailed' if error else '',
            'hung': False, 'produced': list(produced), 'seconds': 1.0}


def outcome(answer, operator: str, old: str, new: str, lab: dict, grading=None, *,
            affected: tuple[str, ...] = ()) -> dict:
    """The outcome of the mutant of ``answer`` that writes ``new`` for ``old`` (a line of
    the answer, or the empty string to delete it)."""
    lines = answer.source.split('\n')
    index = next(i for i, line in enumerate(lines) if line.strip() == old)
    source = lines[:index] + ([lines[index].replace(old, new)] if new else []) + lines[index + 1:]
    return {'ident': f'{answer.key} | {operator} | {old} -> {new}', 'notebook': answer.notebook,
            'answer': answer.key, 'operator': operator, 'what': f'{old} -> {new}',
            'source': '\n'.join(source), 'changed': [index] if new else [],
            'affected': list(affected), 'written': [list(r) for r in answer.regions],
            'cell': shown(), 'lab': lab, 'grading': copy.deepcopy(lab) if grading is None
            else grading}


TIMER = ('self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)',
         'self.timer = self.create_timer(0.5, self.publish_temperature)')


def test_a_good_line_is_killed_well():
    line = ('CheckFailed: 12 readings in 6 s of the grader\'s clock, one every 0.5 s; the '
            'sensor publishes one every 1.0 s: give the timer PUBLISH_PERIOD_S.')
    assert verdict(outcome(SENSOR_CONSTRUCTOR, 'constant changed', *TIMER, shown(
        line, produced=(12.0,)), affected=('PUBLISH_PERIOD_S',))) == ('killed well', [])


@pytest.mark.parametrize('line, reason', [
    ('Something is wrong with your code.', 'tells nothing'),
    ('The publisher on /temperature never reached the grader\'s subscription (is the machine '
     'very busy?): run this check again.', 'tells nothing'),
    ('Readings came 0.001 s apart on the grader\'s clock; the sensor publishes every 1.0 s: '
     'give the timer PUBLISH_PERIOD_S.', "states 0.001, a number the learner's code never "
     'produced'),
    ('The timer is wrong: ' + 'x' * 2000, 'characters'),
])
def test_a_line_that_says_nothing_true_is_bad(line, reason):
    kind, why = verdict(outcome(SENSOR_CONSTRUCTOR, 'constant changed', *TIMER,
                                shown(f'CheckFailed: {line}', produced=(12.0,)),
                                affected=('PUBLISH_PERIOD_S',)))
    assert kind == 'bad' and any(reason in w for w in why), why


def test_the_lab_and_the_grader_must_say_the_same():
    """A raw NameError in the lab beside the grader's explained line: both fail, yet the
    learner reads one thing in the lab and another in the feedback."""
    old = 'msg.data = self.temperature'
    grader = shown("CheckFailed: publish_temperature raised: name 'mgs' is not defined: did you "
                   'mean msg? Names must match exactly. (temperature_publisher.py line 32: '
                   'mgs.data = self.temperature)')
    lab = shown("NameError: name 'mgs' is not defined")
    kind, why = verdict(outcome(SENSOR_CALLBACK, 'name one edit away', old,
                                'mgs.data = self.temperature', lab, grader,
                                affected=('msg', 'mgs')))
    assert kind == 'bad' and why == ["lab: Python's own error, neither explained nor placed",
                                     'the lab and the grader say different things'], why


def test_the_courses_own_wrapper_is_never_named():
    """00: create_subscription with one argument left out named the course's wrapper of it
    (and counted the arguments wrong)."""
    answer = answers('00')[0]
    line = ("CheckFailed: LoudListener() raised: guard_endpoint_types.<locals>.guarded() missing "
            "1 required positional argument: 'topic' (cell line 6: self.subscription = "
            'self.create_subscription()')
    case = outcome(answer, 'argument left out', 'String, CHATTER_TOPIC, self.shout, QUEUE_DEPTH)',
                   'String)', shown(line), affected=('CHATTER_TOPIC',))
    kind, why = verdict(case)
    assert kind == 'bad' and "shows '<locals>'" in ' '.join(why), why


@pytest.mark.parametrize('old, new, meant', [
    ('rclpy.init(args=args)', 'rclpy.init(args=ags)', 'abs'),   # a builtin
])
def test_did_you_mean_names_only_what_the_course_defines(old, new, meant):
    answer = next(a for a in answers('06') if a.key == '06-fan-main')
    line = (f"CheckFailed: fan_controller.py crashed before Ctrl+C: name 'ags' is not defined: "
            f'did you mean {meant}? Names must match exactly. (fan_controller.py line 22: {new})')
    kind, why = verdict(outcome(answer, 'name one edit away', old, new, shown(line),
                                affected=('args', 'ags')))
    assert kind == 'bad' and f'suggests {meant}, which the course does not define' in why[0], why


def test_did_you_mean_the_learners_own_typo_is_bad():
    """02: root -> rot, told "did you mean rot?": a name the course never defines."""
    answer = answers('02')[0]
    old = 'root = ET.parse(package_xml).getroot()'
    line = ("CheckFailed: package_dependencies() raised: name 'root' is not defined: did you mean "
            "rot? Names must match exactly. (cell line 8: return [element.text.strip() for "
            "element in root.findall('depend') if element.text])")
    kind, why = verdict(outcome(answer, 'name one edit away', old,
                                'rot = ET.parse(package_xml).getroot()', shown(line),
                                affected=('root', 'rot')))
    assert kind == 'bad' and any('suggests rot' in w for w in why), why


def test_did_you_mean_a_top_level_slip_back_is_bad():
    """04: TOPIC set as TOIC in the file's constants, read as TOPIC in the constructor: "did
    you mean TOIC?" suggests the slip back; the line that names where TOIC is set is good."""
    answer = next(a for a in answers('04') if a.key == '04-monitor-constructor')
    old = 'Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)'
    place = f'(temperature_subscriber.py line 24: {old})'
    before = ("CheckFailed: TemperatureMonitor() raised: name 'TOPIC' is not defined: did you mean "
              f'TOIC? Names must match exactly. {place}')
    case = outcome(answer, 'hand-made', old, old, shown(before), affected=('TOPIC', 'TOIC'))
    case['changed'] = []  # the mutant changed the given constants, not the answer
    kind, why = verdict(case)
    assert kind == 'bad' and 'lab: suggests TOIC, which the course does not define' in why, why
    after = ("CheckFailed: TemperatureMonitor() raised: name 'TOPIC' is not defined, but TOIC is "
             "(temperature_subscriber.py line 9: TOIC = 'temperature'): spell a name the same "
             f'where it is set and where it is used. {place}')
    case['lab'] = case['grading'] = shown(after)
    assert verdict(case) == ('killed well', [])


def test_a_line_at_code_the_mutant_left_alone_is_bad():
    """04: status = 'High' deleted, told about the log line, which it did not change, in
    words that fit an import."""
    line = ("CheckFailed: temperature_callback raised: status is used before temperature_callback "
            'sets it (temperature_subscriber.py line 35: status = \'Low\'): a name the function '
            'sets is its own local name everywhere in it; set it first, or, for an import, '
            'import it at the top of the file. (temperature_subscriber.py line 39: '
            "self.get_logger().info(f'Temperature: {temperature_c:.2f}C - Status: {status}'))")
    case = outcome(MONITOR_CALLBACK, 'statement deleted', "status = 'High'", '', shown(line),
                   affected=('status', 'High'))
    case['changed'] = []
    kind, why = verdict(case)
    assert kind == 'bad' and 'lab: it tells to import a name, where the mutant touched no ' \
        'import' in why, why


def test_the_walk_kept_in_a_local_must_be_named():
    """03: self.temperature = ... written as temperature = ...: "Reading 4 jumps -0.63 °C"
    states true numbers but names neither the line nor self.temperature."""
    old = 'self.temperature = max(MIN_TEMPERATURE_C,'
    line = ('CheckFailed: Reading 4 jumps -0.63 °C (22.13 to 21.50); one step is at most ±0.5 °C '
            '(MAX_STEP_C).')
    case = outcome(SENSOR_CALLBACK, 'local, not attribute', old,
                   'temperature = max(MIN_TEMPERATURE_C,',
                   shown(line, produced=(4.0, 22.13, 21.5, -0.63)), affected=('temperature',))
    case['affected'] = ['self.temperature']
    kind, why = verdict(case)
    assert kind == 'bad' and 'it names neither the changed line nor a name it changed' in ' '.join(
        why), why
    named = ('CheckFailed: publish_temperature sets a local name temperature '
             '(temperature_publisher.py line 29: temperature = max(MIN_TEMPERATURE_C,), so '
             'self.temperature stays 22.00 °C: write self.temperature = ... there.')
    case['lab'] = case['grading'] = shown(named, produced=(22.0,))
    assert verdict(case) == ('killed well', [])


def test_a_call_without_self_at_the_learners_given_line_is_bad():
    """03: node = TemperatureSensor (no parentheses), told that the given
    node.destroy_node() was called without self."""
    answer = next(a for a in answers('03') if a.key == '03-sensor-main')
    line = ('CheckFailed: temperature_publisher.py crashed before Ctrl+C: destroy_node() was '
            'called without self: give it every argument it needs, in its order. '
            '(temperature_publisher.py line 52: node.destroy_node())')
    kind, why = verdict(outcome(answer, 'method called, not passed', 'node = TemperatureSensor()',
                                'node = TemperatureSensor', shown(line),
                                affected=('TemperatureSensor',)))
    assert kind == 'bad' and any('did not change' in w for w in why), why


def test_numbers_stated_are_read_apart_from_what_they_quote():
    stated = stated_numbers(['Reading 4 jumps -0.63 °C (cell line 12: x = 1.5): "Publishing: '
                             '22.31C"'])
    assert stated == [(-0.63, pytest.approx(0.005))]


def test_a_line_names_the_change_by_a_word_of_a_changed_name():
    case = outcome(SENSOR_CONSTRUCTOR, 'constant changed', *TIMER, shown(),
                   affected=('PUBLISH_PERIOD_S',))
    assert names_change(case, 'the timer fires every 0.5 s')       # the number it wrote
    assert names_change(case, 'give the timer PUBLISH_PERIOD_S')   # the name it changed
    assert not names_change(case, 'No reading arrived on /temperature')


def test_a_line_names_a_flag_the_mutant_changed_as_it_was_written():
    """A flag is no word of a line: the line that shows the learner's '--ro-args' names the
    change; '-r' is not named by a line that says only '--ros-args', which holds it."""
    old = "return ['--ros-args', '-r', f'__ns:=/{room}']"
    line = ("CheckFailed: room_arguments('kitchen') returned ['--ro-args', '-r', "
            "'__ns:=/kitchen']: a node reads only the arguments after '--ros-args'; start "
            'the list with it.')
    typo = outcome(ROOM_ARGUMENTS, 'name one edit away', old,
                   old.replace('--ros-args', '--ro-args'), shown(line),
                   affected=('--ro-args', '--ros-args'))
    assert verdict(typo) == ('killed well', [])
    swapped = outcome(ROOM_ARGUMENTS, 'arguments swapped', old,
                      "return ['-r', '--ros-args', f'__ns:=/{room}']", shown(),
                      affected=('-r',))
    assert not names_change(swapped, "start the list with '--ros-args'")
    assert names_change(swapped, "a rule after -r, not '--ros-args'")


def test_what_a_learners_function_returned_is_what_their_code_produced():
    """10's read_temperatures with 1e6 for 1e9 returns times [0.0, 1000.0, 2000.0, ...],
    and the check quotes them: numbers of the learner's code that no topic or log carried,
    kept from the subject's reply while the run keeps them."""
    times = {'type': 'list', 'value': [{'type': 'float', 'value': t} for t in (0.0, 1e3, 2e3)]}
    data = {'ok': True, 'outputs': [{'result': {'type': 'tuple', 'value': [
        times, {'type': 'str', 'value': 'at 22.5 C'}]}}]}
    session = SimpleNamespace(observer=SimpleNamespace(heard={}, logs=[]))  # nothing heard
    with _returns_kept():
        produced = Produced(session)
        SubjectProcess.reply_to(Call(name='read_temperatures', inputs=[[]]), data)
        assert {0.0, 1000.0, 2000.0, 22.5} <= produced.numbers()
    assert RETURNED == []  # and nothing is kept after the run
    SubjectProcess.reply_to(Call(name='read_temperatures', inputs=[[]]), data)
    assert RETURNED == []


def test_each_excuse_names_its_reason_and_a_witness_the_run_makes():
    """At most fifteen excuses; each says why and names a mutant ``make mistakes`` makes,
    which it covers (``tests/test_mutants.py`` runs each witness: it must still survive)."""
    made = {m.ident for a in answers() for m in mutants(a)}
    assert len(EXCUSES) <= MOST_EXCUSES
    for excuse in EXCUSES:
        assert excuse.why and excuse.witness in made, excuse
        assert equivalent(excuse.witness) == excuse.why, excuse
