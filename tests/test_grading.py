"""Grading a sample class with nbgrader through tools/grade.py (real kernels, real ROS)."""

import csv
import html
import re
import subprocess
import sys
from pathlib import Path

import pytest

from grading_samples import EXPECTED, ROOT, build

pytestmark = pytest.mark.timeout(900)  # grading a class takes minutes, not seconds
CELL_TIMEOUT_S = 40  # the hang case waits this long; 15 s was tight for a colcon build under load
NOTEBOOK_TIMEOUT_S = 240


def repository_files() -> dict[str, tuple[int, int]]:
    """Every file of the repository (git-ignored ones too, but not .venv/.git): mtime, size."""
    found = {}
    for path in ROOT.rglob('*'):
        parts = path.relative_to(ROOT).parts
        if parts[0] in ('.venv', '.git') or '__pycache__' in parts or not path.is_file():
            continue
        stat = path.stat()
        found[str(path.relative_to(ROOT))] = (stat.st_mtime_ns, stat.st_size)
    return found


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    root = tmp_path_factory.mktemp('grading')
    submissions = build(root / 'submissions')
    before = repository_files()
    done = subprocess.run(
        [sys.executable, str(ROOT / 'tools' / 'grade.py'), str(submissions), '--out',
         str(root / 'grading'), f'--cell-timeout={CELL_TIMEOUT_S}',
         f'--notebook-timeout={NOTEBOOK_TIMEOUT_S}'],
        capture_output=True, text=True, timeout=900)
    return root / 'grading', done, before


def test_grading_exits_0_and_leaves_repo_alone(graded):
    out, done, before = graded
    assert done.returncode == 0, done.stdout + done.stderr
    after = repository_files()
    changed = sorted(p for p in set(before) | set(after) if before.get(p) != after.get(p))
    assert changed == []  # nothing in the repository was written, not even ignored files
    # Learners' code ran only in scratch copies: the course under grading/ only scored.
    assert 'IPKernelApp' not in (out / 'nbgrader' / 'grading.log').read_text()


def test_every_score_and_csv_row(graded):
    out, done, _ = graded
    with open(out / 'grades.csv') as stream:
        rows = list(csv.DictReader(stream))
    notebooks = sorted(p.stem for p in (ROOT / 'solutions').glob('*.ipynb'))
    assert len(rows) == len(EXPECTED) * (len(notebooks) + 1)
    got = {(r['learner'], r['notebook']): float(r['score']) for r in rows}
    maxima = {r['notebook']: float(r['max_score']) for r in rows if r['learner'] == 'full'}
    for learner, (scores, _) in EXPECTED.items():
        for notebook in notebooks:
            assert got[learner, notebook] == scores.get(notebook, 0), (learner, notebook)
        assert got[learner, 'TOTAL'] == sum(scores.values())
    assert maxima == {**{n: float(p) for n, p in zip(notebooks, (1, 1, 1, 3, 3, 5))},
                      'TOTAL': 14.0}


@pytest.mark.parametrize('learner', sorted(EXPECTED))
def test_feedback_files_name_what_happened(graded, learner):
    out, _, _ = graded
    scores, phrases = EXPECTED[learner]
    for notebook in sorted(p.stem for p in (ROOT / 'solutions').glob('*.ipynb')):
        page = out / 'feedback' / learner / f'{notebook}.html'
        assert page.is_file(), page
        if notebook not in scores:
            assert 'Not submitted' in page.read_text()
    for notebook, phrase in phrases.items():
        page = (out / 'feedback' / learner / f'{notebook}.html').read_text()
        text = ' '.join(html.unescape(re.sub(r'<[^>]+>', '', page)).split())  # as displayed
        assert phrase in text, (learner, phrase)


def test_gradebook_works_with_nbgrader_export(graded):
    out, _, _ = graded
    course = out / 'nbgrader'
    done = subprocess.run([sys.executable, '-m', 'nbgrader', 'export',
                           f'--CourseDirectory.root={course}',
                           f'--CourseDirectory.db_url=sqlite:///{course / "gradebook.db"}',
                           f'--to={out / "export.csv"}'],
                          cwd=course, capture_output=True, text=True,
                          env={**__import__('os').environ,
                               'PATH': f'{Path(sys.executable).parent}:'
                                       f'{__import__("os").environ["PATH"]}'})
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(open(out / 'export.csv')))
    assert {r['student_id'] for r in rows} >= {'full', 'partial'}
    assert float(next(r for r in rows if r['student_id'] == 'full')['score']) == 14.0


def test_zip_from_a_learning_platform(tmp_path):
    """The zip route goes through nbgrader's zip_collect; learners are the folder names."""
    import zipfile
    notebook = sorted((ROOT / 'solutions').glob('*.ipynb'))[0]
    archive = tmp_path / 'class.zip'
    with zipfile.ZipFile(archive, 'w') as zipped:
        zipped.write(notebook, f'course-export/ada/{notebook.name}')
        zipped.write(ROOT / 'notebooks' / notebook.name, f'course-export/bo/{notebook.name}')
    done = subprocess.run([sys.executable, str(ROOT / 'tools' / 'grade.py'), str(archive),
                           '--out', str(tmp_path / 'grading'), '--cell-timeout=60'],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    rows = {(r['learner'], r['notebook']): r['score']
            for r in csv.DictReader(open(tmp_path / 'grading' / 'grades.csv'))}
    assert rows['ada', notebook.stem] == '1' and rows['ada', 'TOTAL'] == '1'
    assert rows['bo', notebook.stem] == '0'


def test_bad_input_gets_one_line(tmp_path):
    def grade(*args):
        return subprocess.run([sys.executable, str(ROOT / 'tools' / 'grade.py'), *args],
                              capture_output=True, text=True)
    missing = grade(str(tmp_path / 'nope'), '--out', str(tmp_path / 'g1'))
    assert missing.returncode == 2 and 'does not exist' in missing.stdout
    (tmp_path / 'g2').mkdir()
    (tmp_path / 'g2' / 'grades.csv').write_text('manual work\n')
    (tmp_path / 'class').mkdir()
    again = grade(str(tmp_path / 'class'), '--out', str(tmp_path / 'g2'))
    assert again.returncode == 2 and 'FORCE=1' in again.stdout
    assert (tmp_path / 'g2' / 'grades.csv').read_text() == 'manual work\n'  # untouched
