"""The learner's progress: every graded part of the 11 notebooks, passed, failed or not yet, with
its points (issue 69, item 3).

In the lab each check keeps its outcome in the learner's own record (never read by the
grader) and ends with one line; ``ros2nb.progress()`` shows the table, also after a kernel
restart, and runs no check unless asked.  After grading, the same table heads every feedback
page, made from the grader's own results.
"""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

import pytest
from kernels import Kernel, solution_cells

from ros2nb import course, graded_parts
from ros2nb.checks import base
from ros2nb.errors import CheckFailed
from ros2nb.outcomes import CHECK_FAILED, CheckOutcome
from ros2nb_instructor.grading.reports import feedback
from ros2nb_instructor.grading.reports.pages import standing_table
from ros2nb_instructor.grading.intake.submissions import Learner

ROOT = Path(__file__).resolve().parent.parent


def test_the_parts_are_the_notebooks_graded_cells_with_their_points():
    parts = graded_parts.parts()
    assert len({p.notebook for p in parts}) == 11 and len(parts) == 28
    assert sum(p.points for p in parts) == 43
    by_id = {p.grade_id: p for p in parts}
    assert by_id['03-sensor-constructor'] == graded_parts.Part(
        '03-write-the-publisher', '03-sensor-constructor', 2.0,
        'Part 3: the node class and its constructor', 'check_sensor_constructor')
    assert by_id['03-sensor-hour'].check is None  # a hidden test: the learner's copy holds none
    assert by_id['01-create-a-workspace-challenge-1-check'].label == 'Challenge 1: Where is ~?'
    solutions = {p.grade_id: p for p in graded_parts.parts(ROOT / 'solutions')}
    assert solutions['03-sensor-hour'].check == 'check_sensor_hour'  # the grader's copy has it
    assert solutions.keys() == by_id.keys()


def test_the_record_keeps_the_last_outcome_and_survives_nonsense(tmp_path):
    record = tmp_path / graded_parts.RECORD
    assert graded_parts.outcomes(record) == {}
    graded_parts.remember('check_endpoint', False, 'LoudListener has no subscription', record)
    graded_parts.remember('check_endpoint', True, 'Check passed: ...', record)
    assert graded_parts.outcomes(record)['check_endpoint']['passed'] is True
    record.write_text('{"checks": {"check_endpoint": {"passed": "yes"}, "x": 3}}')
    assert graded_parts.outcomes(record) == {}  # a hand-edited record is no outcome
    record.write_text('not json')
    assert graded_parts.outcomes(record) == {}


def test_each_check_ends_with_its_line_and_keeps_its_outcome(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(graded_parts.RECORD_ENV, str(tmp_path / 'progress.json'))
    with base._progress_kept('check_sensor_constructor'):
        print('Check passed: temperature_sensor publishes ...')
    with pytest.raises(CheckFailed), base._progress_kept('check_sensor_callback'):
        raise CheckFailed('Reading 3 is 28.40 °C, above the clamp ...')
    with pytest.raises(CheckFailed), base._progress_kept('check_sensor_main'):
        raise CheckFailed('Check interrupted: run the cell again to check.')
    assert capsys.readouterr().out.splitlines() == [
        'Check passed: temperature_sensor publishes ...',
        'Progress: 03 · Part 3: the node class and its constructor: passed (2 points); '
        'ros2nb.progress() shows all 11 notebooks.',
        'Progress: 03 · Part 4: the timer callback: not passed yet (2 points); '
        'ros2nb.progress() shows all 11 notebooks.']
    kept = graded_parts.outcomes()
    assert {name: value['passed'] for name, value in kept.items()} == {
        'check_sensor_constructor': True, 'check_sensor_callback': False}  # interrupted: none
    assert kept['check_sensor_callback']['line'].startswith('Reading 3 is 28.40 °C')
    monkeypatch.setenv(course.GRADING_ENV, '1')  # in a grading sandbox nothing is kept
    with base._progress_kept('check_sensor_main'):
        print('Check passed: ...')
    assert 'check_sensor_main' not in graded_parts.outcomes()
    assert capsys.readouterr().out == 'Check passed: ...\n'


def test_progress_shows_the_table_and_runs_no_check(tmp_path, monkeypatch, capsys):
    record = tmp_path / 'progress.json'
    monkeypatch.setenv(graded_parts.RECORD_ENV, str(record))
    graded_parts.remember('check_endpoint', True, 'Check passed: ...')
    graded_parts.remember('check_expanded_path', False, 'Your path ...')
    before = record.read_bytes()
    import ros2nb
    ros2nb.progress()
    text = capsys.readouterr().out
    assert text.startswith('Your progress in this lab (the grader runs every check itself). '
                           'Passed 1 of 43 points.')
    assert re.search(r'\n +passed +1 +Challenge 1: Your own listener\n', text)
    assert re.search(r'\n +failed +1 +Challenge 1: Where is ~\?\n', text)
    assert re.search(r'\n +not yet +2 +Part 3: the node class and its constructor\n', text)
    assert re.search(r'\n +when handed in +1 +Graded: your sensor over an hour\n', text)
    assert record.read_bytes() == before


def page_text(page: str) -> str:
    return ' '.join(html.unescape(re.sub(r'<[^>]+>', ' ', page)).split())


def test_the_feedback_page_is_headed_by_the_graders_own_table():
    """From the judge's results of this grading: a part the learner's lab would call passed
    counts for nothing here, and a notebook not handed in says so."""
    learner = Learner('ada', 'ada', files={'03-write-the-publisher': Path('03.ipynb')},
                      results={'03-write-the-publisher': {
                          '03-sensor-constructor': CheckOutcome(True),
                          '03-sensor-callback': CheckOutcome(False, (), CHECK_FAILED, 'wrong'),
                          '03-sensor-hour': CheckOutcome(True)}})
    made = ('<html><head><style>p {}</style></head><body class="jp-Notebook">'
            '<p>nbgrader\'s page</p></body></html>')
    page = feedback.safe_feedback(made, '03-write-the-publisher', (),
                                  standing=feedback.standing_html(standing_table(learner)))
    text = page_text(page)
    assert text.index('Every notebook, as the grader found it: 3 of 43 points passed') \
        < text.index("nbgrader's page")
    assert '03-write-the-publisher 3 of 6 Part 3: the node class and its constructor 2 passed' \
        in text
    assert 'Part 4: the timer callback 2 failed Part 5: main() and the script guard 1 failed ' \
           'Graded: your sensor over an hour 1 passed' in text
    assert '00-setup-and-the-pubsub-idea 0 of 1 Challenge 1: Your own listener 1 not handed in' \
        in text
    assert '<table class="ros2nb-progress">' in page  # kept by the sanitiser, as a table


# ------------------------------------------------------------------ in a real kernel
def states(table: str) -> dict[str, str]:
    """Each part's state in a progress table's HTML, by its label."""
    return {html.unescape(label): state for label, state in re.findall(
        r'<td>([^<]*)</td><td>[^<]*</td>\s*<td class="[^"]*">([^<]*)</td>', table)}


@pytest.mark.kernel
@pytest.mark.judge
@pytest.mark.ros
@pytest.mark.timeout(1800)
def test_progress_in_a_kernel_after_checks_pass_and_fail_and_after_a_restart(tmp_path):
    n00 = solution_cells('00-setup-and-the-pubsub-idea')
    kernel = Kernel(tmp_path / 'ws', ROS2NB_PROGRESS='', ROS2NB_WORK=str(tmp_path))
    try:
        kernel.run('%load_ext ros2nb\nimport ros2nb\n_ = ros2nb.start(sim_time=True)')
        for cell in ('b2444720', 'ca255581'):  # the context, the learner's LoudListener
            kernel.run(n00[cell])
        passed = kernel.run(n00['aefca06a'])  # check_endpoint: passes
        assert passed.stdout.splitlines()[-1].startswith('Progress: 00 · Challenge 1'), passed
        failed = kernel.run("from pathlib import Path\nros2nb.checks.check_expanded_path("
                            "lambda: Path('/Documents/ROS2_and_RL_Tutorials'), "
                            "ends_with='Documents/ROS2_and_RL_Tutorials')")
        assert failed.error[0] == 'CheckFailed'
        assert 'not passed yet' in failed.stdout.splitlines()[-1], failed
        kinds = [kind for kind, _content in failed.messages]  # the check's line first
        assert kinds.index('error') < kinds.index('stream'), failed.messages
        shown = kernel.run('ros2nb.progress()')
        assert (tmp_path / graded_parts.RECORD).is_file()  # kept in the work folder
        kernel.restart()
        again = kernel.run('import ros2nb\nros2nb.progress()')
        for table in (shown.html, again.html):
            assert len(table) == 1 and 'Your progress in this lab' in table[0]
            found = states(table[0])
            assert found['Challenge 1: Your own listener'] == 'passed'
            assert found['Challenge 1: Where is ~?'] == 'failed'
            assert found['Challenge 1: Read the dependencies'] == 'not yet'
            assert found['Graded: your sensor over an hour'] == 'when handed in'
            assert '1 of 43 points passed' in table[0]
        # Asked, it runs the quick checks of the files again: 03's constructor is written.
        kernel.run('%load_ext ros2nb\nws = ros2nb.course.catch_up(3)\n'
                   'PUBLISHER = ros2nb.course.PUBLISHER_FILE')
        n03 = solution_cells('03-write-the-publisher')
        for cell in ('e26c89f9', '156a7e26', '6eb7ef07'):  # parts 1 to 3
            kernel.run(n03[cell])
        checked = states(kernel.run('ros2nb.progress(check=True)').html[0])
        assert checked['Part 3: the node class and its constructor'] == 'passed'
        assert checked['Part 4: the timer callback'] == 'failed'
        assert checked['Your turn: the entry points'] == 'not yet'  # builds: not a quick one
        assert checked['Challenge 1: Where is ~?'] == 'failed'  # takes a function: kept
    finally:
        kernel.close()


def test_a_pass_goes_stale_when_its_file_or_its_code_changes(tmp_path, monkeypatch, capsys):
    """A pass keeps what it ran on: 03's file, 01's function.  Once the file changes, or the
    notebook as saved holds other code for the function, progress() says so (before, it
    said "passed" whatever the learner changed since)."""
    from ros2nb.checks import evidence
    from ros2nb.terminal import workspace
    work, ws = tmp_path / 'work', tmp_path / 'ws'
    (ws / course.PUBLISHER_FILE).parent.mkdir(parents=True)
    (ws / course.PUBLISHER_FILE).write_text('class TemperatureSensor: pass\n')
    work.mkdir()
    monkeypatch.setenv(graded_parts.RECORD_ENV, str(work / graded_parts.RECORD))
    monkeypatch.setattr(workspace, '_current', ws)
    namespace: dict = {}
    exec(compile('def where():\n    return 1\n', str(tmp_path / 'cell.py'), 'exec'), namespace)
    (tmp_path / 'cell.py').write_text('def where():\n    return 1\n')  # its source, for inspect
    notebook = {'cells': [{'cell_type': 'code', 'source': 'def where():\n    return 1\n',
                           'metadata': {}, 'outputs': [], 'execution_count': None}],
                'metadata': {}, 'nbformat': 4, 'nbformat_minor': 5}
    (work / '01-create-a-workspace.ipynb').write_text(json.dumps(notebook))
    with base._progress_kept('check_sensor_constructor', 3):
        print('Check passed: ...')
    with base._progress_kept('check_expanded_path', 1, (namespace['where'],)):
        print('Check passed: ...')
    parts = {p.check: p for p in graded_parts.parts()}
    kept = graded_parts.outcomes()
    assert evidence.changed(parts['check_sensor_constructor'], kept['check_sensor_constructor'],
                            work) is None
    assert evidence.changed(parts['check_expanded_path'], kept['check_expanded_path'], work) \
        is None
    (ws / course.PUBLISHER_FILE).write_text('class TemperatureSensor: pass  # changed\n')
    notebook['cells'][0]['source'] = 'def where():\n    return 2\n'
    (work / '01-create-a-workspace.ipynb').write_text(json.dumps(notebook))
    assert evidence.changed(parts['check_sensor_constructor'], kept['check_sensor_constructor'],
                            work) == 'temperature_publisher.py changed since'
    assert 'holds other code' in evidence.changed(parts['check_expanded_path'],
                                                  kept['check_expanded_path'], work)
    capsys.readouterr()
    import ros2nb
    ros2nb.progress()
    text = capsys.readouterr().out
    assert re.search(r'passed, then changed +2 +Part 3: the node class and its constructor', text)
    assert re.search(r'passed, then changed +1 +Challenge 1: Where is ~\?', text)
    assert 'Passed 0 of 43 points.' in text
