"""The judge's drawn inputs and their one seed (:mod:`ros2nb.checks.drawn`).

A grading's seed goes from ``ros2nb-grade`` into ``notes.json`` and onto each judge's command
line, and the same seed draws the same inputs again; a check in the lab takes no seed from
the learner's kernel and draws new inputs each time.  The lookup-table answers these inputs
defeat are graded beside their twins in ``test_corpora.py`` (``corpus_tables.py``).
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

from ros2nb import course, rules
from ros2nb.checks import drawn, lesson03, lesson04, lesson06, lesson07, lesson08
from ros2nb.errors import Ros2nbError
from ros2nb.judge.__main__ import arguments
from ros2nb.judge.session import Session
from ros2nb_instructor.grading import cli
from ros2nb_instructor.grading.judging.judges import judge_argv
from ros2nb_instructor.grading.judging.settings import Settings


def inputs_of(judge) -> dict:
    """Every input the checks draw, as the judge ``judge`` draws them."""
    return {'03 probes': drawn.clamp_probes_c(judge),
            '03 seed': drawn.sensor_seed(judge, '03 sensor hour', course.START_TEMPERATURE_C,
                                         lesson03.HOUR_S),
            '04': lesson04.drawn_readings_c(judge, '04 monitor readings', 10),
            '06 fan': lesson06._fan_readings(judge),
            '06 room': lesson06._drawn_room(judge),
            '07': (lesson07._gaps_s(judge), lesson07.readings_c(judge)),
            '08': lesson08._drawn_steps(judge)}


def judge_of_grading(tmp_path: Path, seed: int) -> Session:
    """The session a judge opens for one notebook of a grading run with ``seed``: its
    command as the grader writes it, read as the judge reads it."""
    argv = judge_argv(tmp_path / 'source.ipynb', tmp_path / 'submission.ipynb',
                      Settings(120, 600, True, seed))
    assert argv[1:3] == ['-m', 'ros2nb.judge']
    command, given = arguments(argv[3:])
    assert command[0] == 'grade'
    tmp_path.mkdir()
    return Session(tmp_path, given)


def test_a_grading_seed_lands_in_notes_json_and_draws_the_same_inputs_again(tmp_path):
    """The seed ros2nb-grade keeps in notes.json, given back (make grade SEED=N), draws the
    same inputs in every check; another seed draws others."""
    seed = cli._options([str(tmp_path), '--seed', '8675309']).seed
    cli._report(tmp_path, [], [], [], seed)
    kept = json.loads((tmp_path / 'notes.json').read_text())['seed']
    assert kept == 8675309
    first, again, other = (judge_of_grading(tmp_path / name, value) for name, value in
                           (('first', kept), ('again', kept), ('other', kept + 1)))
    try:
        assert inputs_of(first) == inputs_of(again)
        assert all(inputs_of(first)[k] != inputs_of(other)[k] for k in inputs_of(first)
                   if k != '06 room')  # a room is one of 900 names
    finally:
        for session in (first, again, other):
            session.close()


def test_a_check_in_the_lab_draws_new_inputs_and_takes_no_seed(tmp_path):
    """The kernel asks for a check by name only: the judge draws a seed of its own each time
    and refuses one on a check's command line."""
    sessions = [Session(tmp_path), Session(tmp_path)]
    try:
        assert sessions[0].seed != sessions[1].seed
        assert inputs_of(sessions[0])['04'] != inputs_of(sessions[1])['04']
    finally:
        for session in sessions:
            session.close()
    with pytest.raises(Ros2nbError, match='Usage'):
        arguments(['check', 'check_monitor_readings', '--seed', '1'])
    assert inputs_of(None)['04'] != inputs_of(None)['04']  # the kernel's @direct checks


def test_drawn_inputs_keep_their_boundaries_and_their_purpose():
    """Drawn readings fall in every status, away from the thresholds; each drawn clamp probe
    starts inside a limit, and a walk without a clamp from it leaves the limits; 08's drawn
    changes are valid or refused as the rule says; 07's first reading never comes at 1 s."""
    for seed in range(20):
        judge = type('Graded', (), {'seed': seed})()
        readings = lesson04.drawn_readings_c(judge, '04 monitor callback', 2)
        assert sorted(rules.monitor_status(v) for v in readings) == ['High'] * 2 + \
            ['Low'] * 2 + ['Normal'] * 2
        assert not {course.LOW_BELOW_C, course.HIGH_ABOVE_C} & set(readings)
        for number, start_c in enumerate(drawn.clamp_probes_c(judge)):
            assert course.MIN_TEMPERATURE_C < start_c < course.MAX_TEMPERATURE_C
            probe = drawn.sensor_seed(judge, f'03 clamp probe {number}', start_c,
                                      lesson03.CLAMP_RUN_S)
            assert drawn.walk_leaves(probe, start_c, lesson03.CLAMP_RUN_S - 1)
        high, low = 25.0, 21.0  # what lesson08.STEPS leave
        for name, value, valid, _reading in lesson08._drawn_steps(judge):
            after = {'high': high, 'low': low, name.split('_')[0]: value}
            assert valid == (after['low'] < after['high'])
            if valid:
                high, low = after['high'], after['low']
        assert lesson07._gaps_s(judge)[0] > 1


def test_a_bad_seed_gets_one_line():
    for bad in ('-1', 'seven', ''):
        with pytest.raises(Ros2nbError, match='is not a seed: give a whole number'):
            drawn.parse_seed(bad)
    done = subprocess.run([sys.executable, '-m', 'ros2nb.judge', 'grade', 'a', 'b', '--seed',
                           'seven'], capture_output=True, text=True, timeout=120)
    assert done.returncode == 2 and done.stderr.count('\n') == 1, done.stderr
    assert "--seed 'seven' is not a seed" in done.stderr
