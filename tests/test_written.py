"""What a graded copy of the workspace holds (``ros2nb.judge.written``), as plain Python.

A cell of the notebook that is not a ``%%part`` cell runs where the course's own code is at
hand: a module it writes into the package (the course's rule, copied) would be graded beside
the learner's answer, which imports it (tests/corpus_reaching.py, the seventh class, shows
that through the grader).  Here: which files the copy keeps, which it leaves out and flags,
and which it leaves out without a word, for an honest workspace beside a planted one.
"""

from __future__ import annotations

from pathlib import Path

from ros2nb import course
from ros2nb.judge.written import (GIVEN_FILES, MOST_STRAYS_NAMED, course_files, stray_flags,
                                  strays)
from ros2nb.terminal.files import PARTS_RECORD
from ros2nb.terminal.pkg_create import expected_files

PACKAGE = f'src/{course.PACKAGE}'


def _submission_04() -> dict:
    """Notebook 04 as handed in: its monitor's %%part cell, graded as 04's."""
    return {'cells': [
        {'cell_type': 'code', 'metadata': {},
         'source': 'SUBSCRIBER = ros2nb.course.SUBSCRIBER_FILE\n'},
        {'cell_type': 'code', 'metadata': {'nbgrader': {'grade_id': '04-monitor-callback',
                                                         'solution': True}},
         'source': '%%part {SUBSCRIBER} 1\nprint(1)\n'}]}


def _honest_workspace(root: Path) -> Path:
    """A workspace as notebooks 02-07 leave it, bytecode caches and all."""
    files = [f'{PACKAGE}/{relative}' for relative in expected_files(course.PACKAGE)]
    files += [course.PUBLISHER_FILE, course.SUBSCRIBER_FILE, course.FAN_FILE,
              course.LIVE_PLOT_FILE, PARTS_RECORD, *GIVEN_FILES,
              f'{PACKAGE}/{course.PACKAGE}/__pycache__/temperature_publisher.cpython-311.pyc',
              f'{PACKAGE}/{course.PACKAGE}.egg-info/PKG-INFO']
    for relative in files:
        (root / relative).parent.mkdir(parents=True, exist_ok=True)
        (root / relative).write_text('x\n')
    return root


def test_an_honest_workspace_flags_nothing(tmp_path):
    flagged, quiet = strays(_submission_04(), _honest_workspace(tmp_path))
    assert flagged == []
    # a later notebook's file, and what Python and setuptools left: out of the copy, unsaid
    assert course.FAN_FILE in quiet and course.LIVE_PLOT_FILE in quiet
    assert any('__pycache__' in relative for relative in quiet)
    kept = course_files(_submission_04())
    assert {course.SUBSCRIBER_FILE, course.PUBLISHER_FILE, PARTS_RECORD} <= kept
    assert course.FAN_FILE not in kept  # 04 needs no file of 06


def test_a_module_another_cell_wrote_is_left_out_and_flagged(tmp_path):
    workspace = _honest_workspace(tmp_path)
    planted = f'{PACKAGE}/{course.PACKAGE}/monitor_rules.py'
    (workspace / planted).write_text('def status(reading): ...\n')
    (workspace / 'rules.txt').write_text('the rule, to exec\n')
    (workspace / f'{PACKAGE}/{course.PACKAGE}/linked').symlink_to('/etc')
    flagged, _quiet = strays(_submission_04(), workspace)
    assert sorted(flagged) == sorted(['rules.txt', f'{PACKAGE}/{course.PACKAGE}/linked', planted])
    assert planted not in course_files(_submission_04())
    assert stray_flags([planted]) == [
        f'{planted}: a file that neither the course makes nor a %%part cell writes '
        '(another cell wrote it); graded without it']


def test_many_strays_are_named_up_to_a_limit_then_counted():
    flags = stray_flags([f'f{n}.py' for n in range(MOST_STRAYS_NAMED + 5)])
    assert len(flags) == MOST_STRAYS_NAMED + 1
    assert flags[-1].startswith('5 more files')
