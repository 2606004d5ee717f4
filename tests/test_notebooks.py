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
    assert len(names) == 6
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


@pytest.mark.parametrize('path', SOLUTIONS, ids=lambda p: p.name)
def test_every_challenge_has_hint_solution_and_check(path):
    cells = load(path)['cells']
    challenges = [i for i, c in enumerate(cells)
                  if c['cell_type'] == 'markdown' and re.search(r'^#+ Challenge \d', text(c), re.M)]
    assert challenges, f'{path.name} has no Challenge'
    for start in challenges:
        assert 'Hint' in text(cells[start])
        following = cells[start + 1:start + 6]
        kinds = [c['metadata'].get('nbgrader', {}) for c in following]
        assert any(k.get('solution') for k in kinds), f'{path.name}: no solution cell'
        checks = [c for c in following if 'learner-check' in c['metadata'].get('tags', [])]
        assert checks and all('raises-exception' in c['metadata']['tags'] for c in checks)
        assert all(c['metadata']['nbgrader'].get('grade') for c in checks)


def test_learner_notebooks_have_no_outputs_and_no_solutions():
    for path in LEARNER:
        for cell in load(path)['cells']:
            assert not cell.get('outputs'), f'{path.name} is committed with outputs'
            assert 'BEGIN SOLUTION' not in text(cell), f'{path.name} shows a solution'


def test_learner_notebooks_in_sync_with_solutions():
    done = subprocess.run([sys.executable, str(ROOT / 'tools' / 'generate_learner_notebooks.py'),
                           '--check'], capture_output=True, text=True)
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.parametrize('mistake', sorted(TUTORIAL_FIXES))
def test_each_tutorial_mistake_is_fixed_and_said(mistake):
    phrase = TUTORIAL_FIXES[mistake]
    callouts = [text(c) for p in SOLUTIONS for c in load(p)['cells']
                if c['cell_type'] == 'markdown' and 'Fixing the tutorial' in text(c)]
    assert any(phrase in callout for callout in callouts), \
        f'no "Fixing the tutorial" callout mentions {phrase!r} ({mistake})'
