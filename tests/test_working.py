"""Long work says what it does while it works, as one updating line (issue 65, item 4).

A judge writes marked lines on its stderr (ros2nb.working); the kernel shows the latest as
one display it updates, created empty and emptied at the end, so that a cell's outputs, as
nbval reads them and as ``make solutions`` stores them, are the same however long it took.
The last two tests are the walk's long checks in a real kernel: 05's entry points (a colcon
build) and 10's part 1 (an hour of simulated time).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import nbformat
import pytest
from kernels import Kernel, solution_cells

from ros2nb import working
from ros2nb_instructor.authoring.solutions import drop_empty_displays

JUDGE_LIKE = f'''
import os, subprocess, sys, time
from ros2nb import working
working.say('before it was asked')  # a process nobody asked: nothing
working.tell_on_stderr()
working.say('running colcon build')
working.say('running colcon build')  # the same line again: written once
began = time.monotonic()
for second in range(200):  # a count said many times a second
    working.say(f'{{second}} simulated s', often=True)
print(time.monotonic() - began)
working.say('reading the bag')  # a new step: written at once
print(repr(os.environ.get({working.ENV!r})))  # taken out of the environment
child = 'import os; print(os.environ.get(' + repr({working.ENV!r}) + '))'
print(subprocess.run([sys.executable, '-c', child], capture_output=True, text=True).stdout.strip())
'''


def test_a_judge_says_what_it_does_on_stderr_only_when_asked_and_its_children_never():
    env = {**os.environ, working.ENV: '1'}
    done = subprocess.run([sys.executable, '-c', JUDGE_LIKE], env=env, capture_output=True,
                          text=True, timeout=60)
    said = [line for line in map(working.said, done.stderr.splitlines()) if line is not None]
    counting_s, judge_env, child_env = done.stdout.split()
    assert said[0] == 'running colcon build' and said[-1] == 'reading the bag', done.stderr
    assert len(said[1:-1]) <= float(counting_s) / working.EVERY_S + 1, said
    assert all(line.endswith(' simulated s') for line in said[1:-1])
    assert (judge_env, child_env) == ('None', 'None')  # neither the judge's env nor a child's


def test_nobody_asked_nothing_is_said(capsys):
    working.say('running colcon build')
    assert capsys.readouterr() == ('', '')
    assert working.said('Traceback (most recent call last):') is None


def test_outside_a_kernel_the_shown_line_is_nowhere():
    with working.shown('check_x') as work:
        work.began -= 10  # long past the time it would show
        working.say('running colcon build')
        assert work.text(time.monotonic()).startswith('check_x: running colcon build (1')
        with working.shown('spinning the nodes'):
            working.say('5 of 60 simulated s')
            assert work.text(time.monotonic()).startswith(
                'check_x: spinning the nodes: 5 of 60 simulated s (')
        assert work.title == 'check_x'
    assert working._current == []


def test_make_solutions_drops_only_the_emptied_displays():
    nb = nbformat.v4.new_notebook()
    cell = nbformat.v4.new_code_cell('ros2nb.checks.check_entry_points()')
    cell.outputs = [nbformat.v4.new_output('display_data', data={}),
                    nbformat.v4.new_output('stream', name='stdout', text='Check passed: x\n'),
                    nbformat.v4.new_output('display_data', data={'text/plain': 'a plot'})]
    nb.cells.append(cell)
    drop_empty_displays(nb)
    assert [o.output_type for o in nb.cells[0].outputs] == ['stream', 'display_data']


# ------------------------------------------------------------------ in a real kernel
def shown_lines(messages: list[tuple[str, dict]]) -> list[str]:
    """What the cell's one updating line said, in order; and the display's life checked:
    sent empty, emptied at the end, before the check's own answer."""
    displays = [(kind, content) for kind, content in messages
                if kind in ('display_data', 'update_display_data')]
    if not displays:
        return []
    assert displays[0] == ('display_data', displays[0][1]) and displays[0][1]['data'] == {}
    assert len([d for d in displays if d[0] == 'display_data']) == 1  # one line, updated
    assert displays[-1][1]['data'] == {}  # emptied: nbval and make solutions see no progress
    last = max(i for i, m in enumerate(messages) if m[0] == 'update_display_data')
    assert any(kind == 'stream' and 'Check passed' in content['text']
               for kind, content in messages[last:]), messages  # the answer comes after
    return [content['data']['text/plain'] for _kind, content in displays[1:-1]]


def stored(messages: list[tuple[str, dict]]) -> list[dict]:
    """The cell's outputs as nbclient keeps them (a display updated in place), then as
    ``make solutions`` stores them."""
    outputs, by_id = [], {}
    for kind, content in messages:
        if kind == 'update_display_data':
            by_id[content['transient']['display_id']]['data'] = content['data']
            continue
        output = nbformat.v4.output_from_msg({'msg_type': kind, 'content': content,
                                              'header': {'msg_type': kind}})
        if kind == 'display_data':
            by_id[content['transient']['display_id']] = output
        outputs.append(output)
    nb = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(outputs=outputs)])
    drop_empty_displays(nb)
    return nb.cells[0].outputs


@pytest.mark.kernel
@pytest.mark.judge
@pytest.mark.ros
@pytest.mark.timeout(900)
def test_05s_entry_point_check_says_it_builds_then_answers(tmp_path):
    cells = solution_cells('05-entry-points-and-run')
    kernel = Kernel(tmp_path / 'ws')
    try:
        kernel.run(cells['b9930eef'] + '\nws = ros2nb.course.catch_up(5)\n' + cells['c0838a32'])
        kernel.run(cells['74a671f4'])  # the entry points, written
        check = kernel.run(cells['dd03a93b'])  # check_entry_points()
    finally:
        kernel.close()
    said = shown_lines(check.messages)
    assert check.seconds < 2 or any(line.startswith('check_entry_points: running colcon build (')
                                    for line in said), (check.seconds, said)
    assert {o.output_type for o in stored(check.messages)} == {'stream'}  # as make solutions keeps


@pytest.mark.kernel
@pytest.mark.ros
@pytest.mark.timeout(900)
def test_10s_recording_check_says_how_far_the_hour_is(tmp_path):
    cells = solution_cells('10-record-and-replay')
    kernel = Kernel(tmp_path / 'ws')
    try:
        for cell in ('b61bfe20', '5d79509a', '1266d1a4'):  # set-up, context, record_hour
            kernel.run(cells[cell])
        check = kernel.run(cells['fededecd'])  # check_recording(record_hour)
    finally:
        kernel.close()
    said = shown_lines(check.messages)
    counted = [line for line in said if line.startswith('check_recording: spinning the nodes: ')
               and ' of 3600 simulated s (' in line]
    assert check.seconds < 2 or counted, (check.seconds, said)
    assert {o.output_type for o in stored(check.messages)} == {'stream'}
