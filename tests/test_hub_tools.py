"""The classroom server's two small tools: the learner's launcher and the collector for grading."""

from __future__ import annotations

import os
import shutil
import stat
from pathlib import Path

import pytest

from ros2nb_instructor.hub import collect as collector
from ros2nb_instructor.hub import singleuser as launcher
from ros2nb.temporary import owned_folder

ROOT = Path(__file__).resolve().parent.parent


SHIPPED = sorted(p.name for p in (ROOT / 'notebooks').glob('*.ipynb'))


def test_launcher_copies_missing_notebooks_and_never_replaces_work(tmp_path):
    folder = tmp_path / 'ros2-course'
    copied = launcher.copy_missing_notebooks(ROOT / 'notebooks', folder)
    assert [Path(line.split(':')[0]).name for line in copied] == SHIPPED
    assert (folder.stat().st_mode & 0o777) == 0o700
    work = folder / 'notebooks' / SHIPPED[3]
    work.write_text('my own work')
    (folder / 'notebooks' / SHIPPED[0]).unlink()
    assert launcher.copy_missing_notebooks(ROOT / 'notebooks', folder) == [
        f'{folder / "notebooks" / SHIPPED[0]}: new notebook from the course.']
    assert work.read_text() == 'my own work'


def test_launcher_gives_each_learner_a_workspace_in_their_folder(tmp_path):
    env = {'PATH': '/usr/bin'}
    launcher.learner_environment(env, tmp_path / 'ros2-course', Path('/course/.venv/bin'))
    assert env['ROS2NB_WORKSPACE'] == str(tmp_path / 'ros2-course' / 'workspace' /
                                          'ROS2_and_RL_Tutorials')
    assert env['ROS2NB_WORK'] == str(tmp_path / 'ros2-course' / 'notebooks')  # their progress
    assert env['PATH'].split(os.pathsep) == ['/course/.venv/bin', '/usr/bin']
    assert 'ROS_DOMAIN_ID' not in env
    assert env['JUPYTER_CONFIG_PATH'] == str(ROOT / 'environment' / 'jupyter-learner')
    assert launcher.learner_folder({'HOME': str(tmp_path)}) == Path('~/ros2-course').expanduser()


def learner(tmp_path: Path, name: str, uid: int = os.getuid()) -> 'collector.Learner':
    home = tmp_path / 'home' / name
    (home / 'ros2-course' / 'notebooks').mkdir(parents=True)
    return collector.Learner(name, home, uid)


def test_collect_copies_course_notebooks_into_the_grading_layout(tmp_path):
    ada = learner(tmp_path, 'ada')
    notebooks = ada.home / 'ros2-course' / 'notebooks'
    (notebooks / SHIPPED[0]).write_text('{"ada": 0}')
    (notebooks / SHIPPED[4]).write_text('{"ada": 4}')
    (notebooks / 'Untitled.ipynb').write_text('{}')
    results = collector.collect([ada], tmp_path / 'class')
    assert results['ada'].copied == [SHIPPED[0], SHIPPED[4]] and not results['ada'].refused
    assert (sorted(p.name for p in (tmp_path / 'class' / 'ada').iterdir())
            == [SHIPPED[0], SHIPPED[4]])
    assert (tmp_path / 'class' / 'ada' / SHIPPED[4]).read_text() == '{"ada": 4}'


def test_collect_refuses_links_other_owners_and_huge_files(tmp_path, monkeypatch):
    grace, eve = learner(tmp_path, 'grace'), learner(tmp_path, 'eve')
    (grace.home / 'ros2-course' / 'notebooks' / SHIPPED[1]).write_text('{"grace": 1}')
    eve_notebooks = eve.home / 'ros2-course' / 'notebooks'
    (eve_notebooks / SHIPPED[1]).symlink_to(grace.home / 'ros2-course' / 'notebooks' / SHIPPED[1])
    (eve_notebooks / SHIPPED[2]).write_text('x' * 200)
    monkeypatch.setattr(collector, 'MAX_NOTEBOOK_BYTES', 100)
    mallory = learner(tmp_path, 'mallory', uid=os.getuid() + 1)
    (mallory.home / 'ros2-course' / 'notebooks' / SHIPPED[0]).write_text('{}')
    results = collector.collect([grace, eve, mallory], tmp_path / 'class')
    assert results['grace'].copied == [SHIPPED[1]]
    assert results['eve'].copied == []
    assert results['eve'].refused == [f'{SHIPPED[1]}: a symbolic link',
                                      f'{SHIPPED[2]}: too large (200 bytes; at most 100)']
    assert results['mallory'].refused == [f'{SHIPPED[0]}: not owned by the learner']
    assert not (tmp_path / 'class' / 'eve').exists()


def test_collect_never_mixes_into_an_earlier_collection(tmp_path):
    (tmp_path / 'class' / 'old').mkdir(parents=True)
    with pytest.raises(collector.CollectError, match='not empty'):
        collector.collect([], tmp_path / 'class')


def test_collect_needs_the_hub_group():
    with pytest.raises(collector.CollectError, match='ROS2_COURSE_HUB_GROUP'):
        collector.group_learners('no-such-group-ros2-course-test')


def test_hub_check_finds_the_folder_that_keeps_learners_out():
    top = owned_folder('ros2nb-hub-check-')
    try:
        top.chmod(0o755)
        python = top / 'closed' / 'bin' / 'python'
        python.parent.mkdir(parents=True)
        python.write_text('')
        python.chmod(0o755)
        (top / 'closed').chmod(0o700)
        assert launcher.closed_to_others(python, need=stat.S_IXOTH) == top / 'closed'
        (top / 'closed').chmod(0o755)
        assert launcher.closed_to_others(python, need=stat.S_IXOTH) is None
        python.chmod(0o700)
        assert launcher.closed_to_others(python, need=stat.S_IXOTH) == python
    finally:
        shutil.rmtree(top)
