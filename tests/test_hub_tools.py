"""The classroom server's two small tools: the learner's launcher and the collector for grading."""

from __future__ import annotations

import os
import re
import shutil
import stat
import sys
from pathlib import Path

import pytest

from ros2nb_instructor.hub import collect as collector
from ros2nb_instructor.hub import hand_in_store, release
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


# ---------------------------------------------------------------- hand-ins on the hub
NOTEBOOK_BYTES = (ROOT / 'notebooks' / SHIPPED[3]).read_bytes()


def test_the_store_keeps_each_hand_in_with_its_own_time_and_refuses_the_rest(tmp_path):
    """Each notebook its own time; handing one in again replaces that copy and time alone;
    a name that is no course notebook, a file that is no notebook, and a user name the
    grader cannot take as a folder are refused, one line each; root's alone."""
    store = hand_in_store.Store(tmp_path / 'store')
    first = store.hand_in('ada', SHIPPED[3][:-6], NOTEBOOK_BYTES)
    other = store.hand_in('ada', SHIPPED[4][:-6], NOTEBOOK_BYTES)
    again = store.hand_in('ada', SHIPPED[3][:-6], NOTEBOOK_BYTES + b' ')
    times = store.handed_in('ada')
    assert times == {SHIPPED[3][:-6]: again.at, SHIPPED[4][:-6]: other.at}
    assert first.at <= other.at <= again.at and again.at.utcoffset().total_seconds() == 0
    assert (tmp_path / 'store').stat().st_mode & 0o777 == 0o700
    for learner, notebook, data, said in (
            ('ada', '99-nothing', NOTEBOOK_BYTES, "'99-nothing' is no notebook of the course"),
            ('ada', SHIPPED[3][:-6], b'not json', 'that is not a notebook'),
            ('../eve', SHIPPED[3][:-6], NOTEBOOK_BYTES, 'is not a user name the store keeps')):
        with pytest.raises(hand_in_store.Refused, match=re.escape(said)):
            store.hand_in(learner, notebook, data)
    log = (tmp_path / 'store' / 'hand-ins.log').read_text().splitlines()
    assert len(log) == 3 and log[-1].endswith(f'ada {SHIPPED[3][:-6]} {len(NOTEBOOK_BYTES) + 1} '
                                              'bytes')


def test_collect_carries_each_notebooks_time_to_the_grader(tmp_path):
    """make hub-collect copies what was handed in and handed-in.json beside it; the grader
    reads each notebook's own time from there (as the server recorded it)."""
    from ros2nb_instructor.grading.intake.submissions import find_learners
    store = hand_in_store.Store(tmp_path / 'store')
    stored = store.hand_in('grace', SHIPPED[3][:-6], NOTEBOOK_BYTES)
    results = collector.collect_handed_in(store, tmp_path / 'class')
    assert results['grace'].copied == [SHIPPED[3]]
    (learner,), refused = find_learners(tmp_path / 'class', [p[:-6] for p in SHIPPED])
    assert refused == [] and learner.handed_in == {SHIPPED[3][:-6]: (stored.at, 'handed-in.json')}
    assert (tmp_path / 'class' / 'grace' / SHIPPED[3]).read_bytes() == NOTEBOOK_BYTES


def test_feedback_is_released_to_each_learner_alone(tmp_path):
    """Each learner's pages go to their own folder of the store; a page is found by the
    course's notebook names only, never by a path the request makes."""
    grading = tmp_path / 'grading' / 'feedback'
    for learner in ('ada', 'grace'):
        (grading / learner).mkdir(parents=True)
        (grading / learner / f'{SHIPPED[3][:-6]}.html').write_text(f'<p>{learner}</p>')
    (grading / 'bad name').mkdir()
    (grading / 'bad name' / f'{SHIPPED[3][:-6]}.html').write_text('x')
    store = hand_in_store.Store(tmp_path / 'store')
    said = release.release(tmp_path / 'grading', store)
    assert said[::2] == ['ada: 1 page(s) released', 'grace: 1 page(s) released']
    assert said[1].startswith("bad name: not released ('bad name' is not a user name")
    assert store.page('ada', SHIPPED[3][:-6]) == b'<p>ada</p>'
    assert store.page('grace', SHIPPED[3][:-6]) == b'<p>grace</p>'
    assert store.feedback('ada') == [SHIPPED[3][:-6]]
    assert store.page('ada', f'../grace/feedback/{SHIPPED[3][:-6]}') is None


def test_the_service_says_each_learner_their_own_due_date(tmp_path):
    """The class's due date, a learner's extension beside it, and how late a hand-in was,
    from course.toml and extensions.toml as they are at the request."""
    from ros2nb_instructor.hub import schedule
    notebook = SHIPPED[3][:-6]
    (tmp_path / 'course.toml').write_text(f'[late]\ntime_zone = "Europe/Berlin"\n'
                                          f'[notebooks.{notebook}]\ndue = 2020-10-05T23:59:00\n')
    when = schedule.Schedule(tmp_path / 'course.toml', tmp_path / 'extensions.toml')
    store = hand_in_store.Store(tmp_path / 'store')
    store.hand_in('ada', notebook, NOTEBOOK_BYTES)
    said = schedule.status(store, when, 'ada', notebook)
    assert said.due == '2020-10-05T23:59:00+02:00' and said.class_due is None
    assert said.late_by and said.handed_in  # handed in years after the due date
    (tmp_path / 'extensions.toml').write_text(f'[ada]\n"{notebook[:2]}" = 2099-10-05T23:59:00\n')
    said = schedule.status(store, when, 'ada', notebook)
    assert said.class_due == '2020-10-05T23:59:00+02:00' and said.due == '2099-10-05T23:59:00+02:00'
    assert said.late_by == ''
    assert schedule.status(store, when, 'grace', notebook).class_due is None


def test_the_service_counts_the_grace_as_the_grader_does(tmp_path):
    """A hand-in within the policy's grace is on time for the grader: the service said
    "late by" for it.  Past the grace it says how late."""
    import datetime
    from ros2nb_instructor.hub import schedule
    notebook = SHIPPED[3][:-6]
    store = hand_in_store.Store(tmp_path / 'store')
    store.hand_in('ada', notebook, NOTEBOOK_BYTES)
    handed_in = store.handed_in('ada')[notebook]
    for grace, after_s, late in ((15, 5 * 60, False), (15, 20 * 60, True)):
        due = (handed_in - datetime.timedelta(seconds=after_s)).astimezone(datetime.timezone.utc)
        (tmp_path / 'course.toml').write_text(
            f'[late]\ngrace_minutes = {grace}\n'
            f'[notebooks.{notebook}]\ndue = {due.strftime("%Y-%m-%dT%H:%M:%SZ")}\n')
        when = schedule.Schedule(tmp_path / 'course.toml', tmp_path / 'extensions.toml')
        assert bool(schedule.status(store, when, 'ada', notebook).late_by) is late, (grace, after_s)


def test_the_hub_will_not_start_while_learners_could_read_the_extensions(tmp_path, monkeypatch):
    """Every learner can read the course folder on the hub; extensions.toml there names
    learners and their dates, so make hub's check refuses it open to others, in one line."""
    monkeypatch.setattr(launcher, 'COURSE', tmp_path)
    private = tmp_path / 'extensions.toml'
    private.write_text('[ada]\n"03" = { days = 2 }\n')
    private.chmod(0o644)
    said = launcher.check_learners_can_use_course(Path(sys.executable))
    assert said == (f'Learners can read {private} (every learner\'s extensions): make it yours '
                    f'alone, chmod 600 {private}, then start the hub again.')
    private.chmod(0o600)
    assert launcher.extensions_open_to_learners(tmp_path) is None


def test_hand_in_outside_the_hub_or_of_no_notebook_is_one_line(monkeypatch, tmp_path):
    from ros2nb.hand_ins import HandInError, hand_in
    monkeypatch.delenv('ROS2NB_HAND_IN_URL', raising=False)
    monkeypatch.setenv('ROS2NB_WORK', str(tmp_path))
    shutil.copyfile(ROOT / 'notebooks' / SHIPPED[3], tmp_path / SHIPPED[3])
    with pytest.raises(HandInError) as outside:
        hand_in(SHIPPED[3][:2])
    assert str(outside.value) == ("This lab is not on the course's hub, so there is no hand-in "
                                  "server here: hand your notebook in through your course's "
                                  "platform")
    with pytest.raises(HandInError, match=r"^'99' is no notebook of the course: write its "):
        hand_in('99')
    monkeypatch.setenv('ROS2NB_HAND_IN_URL', 'http://127.0.0.1:9/services/hand-in/')
    monkeypatch.setenv('JUPYTERHUB_API_TOKEN', 'x')
    with pytest.raises(HandInError, match=r' is not there: open and save 04-'):
        hand_in(4)
