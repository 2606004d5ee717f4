"""The notebooks' structure: names, Carpentries sections, challenges, learner copies in sync."""

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
SOLUTIONS = sorted((ROOT / 'solutions').glob('*.ipynb'))
LEARNER = sorted((ROOT / 'notebooks').glob('*.ipynb'))
NAME = re.compile(r'^(\d\d)-[a-z0-9]+(-[a-z0-9]+)*\.ipynb$')
#: Each mistake of the tutorial and a phrase that must appear where the course fixes it.
TUTORIAL_FIXES = {
    'TemperaturSensor class-name typo': 'TemperaturSensor',
    '10.2 °C floor': '10.2',
    '/Documents without ~': '/Documents',
    'subscriber main() without destroy/shutdown': 'destroy_node',
    'rclpy.shutdown() after Ctrl+C': 'try_shutdown',
    'setup.cfg that ros2 run needs': 'setup.cfg',
}


def load(path: Path) -> dict:
    return json.loads(path.read_text())


def text(cell: dict) -> str:
    source = cell['source']
    return source if isinstance(source, str) else ''.join(source)


def test_names_are_numbered_kebab_case_and_consecutive():
    names = [p.name for p in SOLUTIONS]
    assert len(names) >= 8
    assert all(NAME.match(n) for n in names), names
    assert [int(n[:2]) for n in names] == list(range(len(names)))
    assert [p.name for p in LEARNER] == names
    assert not list(ROOT.rglob('Untitled*.ipynb'))


@pytest.mark.parametrize('path', SOLUTIONS, ids=lambda p: p.name)
def test_carpentries_structure(path):
    cells = load(path)['cells']
    first, last = text(cells[0]), text(cells[-1])
    assert cells[0]['cell_type'] == 'markdown'
    for heading in ('Questions', 'Objectives', 'Time:'):
        assert heading in first, f'{path.name}: first cell lacks {heading}'
    assert 'Keypoints' in last, f'{path.name}: last cell must be the Keypoints'


def nbgrader(cell: dict) -> dict:
    return cell['metadata'].get('nbgrader', {})


@pytest.mark.parametrize('path', SOLUTIONS, ids=lambda p: p.name)
def test_every_answer_has_explanation_hint_points_and_check(path):
    """Explanation (with a hint and its points) first, then the learner's cell, then its check."""
    cells = load(path)['cells']
    answers = [i for i, c in enumerate(cells) if nbgrader(c).get('solution')]
    assert answers, f'{path.name} has nothing for the learner to write'
    for index in answers:
        before = text(cells[index - 1])
        assert cells[index - 1]['cell_type'] == 'markdown' and 'Hint' in before, (path.name, index)
        points = re.search(r'\((\d) points?\)', before)
        assert points, f'{path.name} cell {index}: the explanation does not say the points'
        check = next(c for c in cells[index + 1:] if c['cell_type'] == 'code')
        assert 'learner-check' in check['metadata'].get('tags', []), (path.name, index)
        assert 'raises-exception' in check['metadata']['tags']
        assert nbgrader(check).get('grade') and nbgrader(check)['points'] == int(points.group(1))


@pytest.mark.parametrize('path', SOLUTIONS, ids=lambda p: p.name)
def test_the_points_the_notebook_states_are_the_points_it_gives(path):
    cells = load(path)['cells']
    stated = re.search(r'\*\*Points:\*\* (\d+)', text(cells[0]))
    assert stated, f'{path.name} does not say its points in its first cell'
    given = sum(nbgrader(c).get('points', 0) for c in cells if nbgrader(c).get('grade'))
    assert int(stated.group(1)) == given


@pytest.mark.parametrize('path', SOLUTIONS, ids=lambda p: p.name)
def test_the_judge_can_run_every_graded_cell(path):
    """Graded cells hold only ros2nb.checks calls, each a registered check the judge looks up
    by name (ros2nb.checks.run_check) and runs outside the kernel."""
    from ros2nb import checks
    from ros2nb.checks.base import CHECKS
    from ros2nb.judge import graded_cells
    for cell in load(path)['cells']:
        if nbgrader(cell).get('grade'):
            calls = graded_cells.graded_calls(text(cell))
            assert calls, (path.name, nbgrader(cell)['grade_id'])
            assert all(callable(getattr(checks, name, None)) and name in CHECKS
                       for name, _, _ in calls), calls


NODE_CALLS = ('create_publisher(', 'create_timer(', 'create_subscription(', '.publish(')


@pytest.mark.parametrize('path', [p for p in LEARNER if p.name[:2] in ('03', '04')],
                         ids=lambda p: p.name)
def test_learner_notebooks_leave_the_nodes_to_the_learner(path):
    code = '\n'.join(text(c) for c in load(path)['cells'] if c['cell_type'] == 'code')
    assert not [call for call in NODE_CALLS if call in code]


def _file_from_parts(path: Path, variable: str) -> str:
    from ros2nb.terminal.files import AUTHOR_MARKERS
    parts = {}
    for cell in load(path)['cells']:
        found = re.match(r'%%part \{' + variable + r'\} (\d+)\n', text(cell))
        if found:
            body = '\n'.join(line for line in text(cell)[found.end():].split('\n')
                             if line.strip() not in AUTHOR_MARKERS)
            parts[int(found.group(1))] = body.rstrip('\n')
    return '\n\n'.join(parts[n] for n in sorted(parts)) + '\n'


@pytest.mark.parametrize('notebook, variable, reference', [
    ('03-write-the-publisher.ipynb', 'PUBLISHER', 'temperature_publisher.py'),
    ('04-write-the-subscriber.ipynb', 'SUBSCRIBER', 'temperature_subscriber.py'),
    ('06-five-promises.ipynb', 'FAN', 'fan_controller.py'),
    ('06-five-promises.ipynb', 'PROMISES', 'promises.py'),
    ('07-live-plot.ipynb', 'LIVE_PLOT', 'live_plot.py'),
])
def test_solution_parts_are_the_reference_nodes(notebook, variable, reference):
    from ros2nb import course
    assert _file_from_parts(ROOT / 'solutions' / notebook, variable) == \
        course.reference_source(reference)


def test_the_node_files_carry_the_course_constants():
    """The standalone node files spell the numbers out; they must be ros2nb.course's."""
    import ast
    from ros2nb import course
    for reference in ('temperature_publisher.py', 'temperature_subscriber.py',
                      'fan_controller.py', 'promises.py'):
        tree = ast.parse(course.reference_source(reference))
        constants = {t.id: ast.literal_eval(n.value) for n in tree.body
                     if isinstance(n, ast.Assign) for t in n.targets if t.id.isupper()}
        assert constants, reference
        for name, value in constants.items():
            assert getattr(course, name) == value, (reference, name)


def test_learner_notebooks_have_no_outputs_and_no_solutions():
    for path in LEARNER:
        for cell in load(path)['cells']:
            assert not cell.get('outputs'), f'{path.name} is committed with outputs'
            assert 'BEGIN SOLUTION' not in text(cell), f'{path.name} shows a solution'


def test_learner_notebooks_in_sync_with_solutions():
    done = subprocess.run([str(Path(sys.executable).with_name('ros2nb-learner-notebooks')),
                           '--check'], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.parametrize('mistake', sorted(TUTORIAL_FIXES))
def test_each_tutorial_mistake_is_fixed_and_said(mistake):
    phrase = TUTORIAL_FIXES[mistake]
    callouts = [text(c) for p in SOLUTIONS for c in load(p)['cells']
                if c['cell_type'] == 'markdown' and 'Fixing the tutorial' in text(c)]
    assert any(phrase in callout for callout in callouts), \
        f'no "Fixing the tutorial" callout mentions {phrase!r} ({mistake})'
