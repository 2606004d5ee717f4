"""The learner's work stays theirs: ``make lab``'s working folder across a course update.

The course's learner notebooks are copied into a working folder; the learner answers a
part; the course then changes that notebook and adds a new one. The update adds the new
notebook, keeps the learner's answer as it is and offers the changed notebook beside it.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import nbformat

from ros2nb_instructor import lab

ROOT = Path(__file__).resolve().parent.parent
ANSWER = "%%part {PUBLISHER_FILE} 1\n# my answer, kept\nPUBLISH_PERIOD_S = 1.0\n"


def answer_cell(notebook: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The first answer cell nbgrader marks in a learner notebook."""
    return next(c for c in notebook.cells if c.metadata.get('nbgrader', {}).get('solution'))


def test_a_course_update_keeps_the_learners_answers_and_offers_the_new_version(tmp_path):
    course, work = tmp_path / 'notebooks', tmp_path / 'work'
    shutil.copytree(ROOT / 'notebooks', course)
    shipped = sorted(p.name for p in course.glob('*.ipynb'))
    first = lab.update_work_folder(course, work)
    assert first == [f'{work / name}: new notebook from the course.' for name in shipped]
    assert lab.update_work_folder(course, work) == []  # nothing changed, nothing said

    mine = work / '03-write-the-publisher.ipynb'
    notebook = nbformat.read(mine, as_version=4)
    answer_cell(notebook).source = ANSWER
    nbformat.write(notebook, mine)
    learner_bytes = mine.read_bytes()

    fixed = nbformat.read(course / mine.name, as_version=4)
    fixed.cells[0].source += '\n\nA course fix.'
    nbformat.write(fixed, course / mine.name)
    untouched = nbformat.read(course / '01-create-a-workspace.ipynb', as_version=4)
    untouched.cells[0].source += '\n\nAnother fix.'
    nbformat.write(untouched, course / '01-create-a-workspace.ipynb')
    shutil.copyfile(course / shipped[0], course / '99-a-new-lesson.ipynb')

    beside = work / '03-write-the-publisher (course update).ipynb'
    assert lab.update_work_folder(course, work) == [
        f'{work / "01-create-a-workspace.ipynb"}: updated from the course (you had not '
        'changed it).',
        f'{beside}: the course changed 03-write-the-publisher.ipynb; yours is kept as it is, '
        'the new version is beside it (copy what you need across).',
        f'{work / "99-a-new-lesson.ipynb"}: new notebook from the course.']
    assert mine.read_bytes() == learner_bytes
    assert answer_cell(nbformat.read(mine, as_version=4)).source == ANSWER
    assert nbformat.read(beside, as_version=4).cells[0].source.endswith('A course fix.')
    assert nbformat.read(work / '01-create-a-workspace.ipynb',
                         as_version=4).cells[0].source.endswith('Another fix.')
    assert lab.update_work_folder(course, work) == []


def test_the_learners_lab_turns_off_the_instructor_tools_and_the_news():
    page = json.loads((lab.LEARNER_CONFIG / 'labconfig' / 'page_config.json').read_text())
    off = {name for name, disabled in page['disabledExtensions'].items() if disabled}
    for plugin in ('create-assignment', 'formgrader', 'course-list', 'assignment-list',
                   'validate-assignment'):
        assert f'@jupyter/nbgrader:{plugin}' in off
    assert '@jupyterlab/apputils-extension:announcements' in off
    server = json.loads((lab.LEARNER_CONFIG / 'jupyter_server_config.json').read_text())
    assert not any(server['ServerApp']['jpserver_extensions'].values())
    assert server['LabApp']['news_url'] is None
