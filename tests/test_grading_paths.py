"""The grader's own handling of what a learner's code left: links, odd files, full disks.

Fast checks of the pieces ``tests/test_grading.py`` shows working on a whole class: each
plants the learner's move and shows what the grader makes of it (root, as when grading).
"""

import dataclasses
import json
import os
import subprocess
import sys

import nbformat
import pytest

from grading_samples import NB01, NB02, NB05, SOLUTION

from ros2nb import course
from ros2nb.terminal import workspace as ws_module
from ros2nb.terminal.workspace import WORKSPACE_NAME
from ros2nb_instructor.grading.judging import notebooks
from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.judging.judges import judge_notebook
from ros2nb_instructor.grading.sandbox.paths_of_learners import NotARegularFile, read_regular
from ros2nb_instructor.grading.judging.runs import NotebookRun, _read_back, checked_status, run_note
from ros2nb_instructor.grading.sandboxed.runner import RunStatus
from ros2nb_instructor.grading.sandbox.scratch import HOME_BYTES, Scratch, sweep_left_behind
from ros2nb_instructor.grading.judging.settings import Settings
from ros2nb_instructor.grading.intake.submissions import Learner


@pytest.fixture
def scratch(tmp_path):
    made = Scratch(tmp_path, Learner('ada', 'ada'))
    yield made
    made.remove()


@pytest.fixture
def host(tmp_path):
    """A folder of the host's that holds a workspace of someone else's, with a secret."""
    folder = tmp_path / 'host'
    (folder / WORKSPACE_NAME / 'src').mkdir(parents=True)
    (folder / WORKSPACE_NAME / 'src' / 'secret.txt').write_text('the hidden tests\n')
    return folder


def test_a_linked_workspace_is_never_copied_for_the_judge(scratch, host):
    """home/workspace replaced by a link to a host folder: the judge gets an empty workspace.

    Before, the snapshot checked only the workspace's last part and copied the host's
    folder through the link (so the judge, and the learner's code it runs, saw it).
    """
    (scratch.home / 'workspace').symlink_to(host)
    snapshot = scratch.snapshot(NB01)
    assert list(snapshot.iterdir()) == []
    (scratch.home / 'workspace').unlink()
    (scratch.home / 'workspace').mkdir()
    (scratch.home / 'workspace' / WORKSPACE_NAME).symlink_to(host / WORKSPACE_NAME)
    assert list(scratch.snapshot('again').iterdir()) == []


def test_a_real_workspace_is_copied_with_its_links_as_links(scratch, host):
    """The honest twin: a real workspace is copied; a link inside stays a link, unfollowed."""
    workspace = scratch.home / 'workspace' / WORKSPACE_NAME
    (workspace / 'src').mkdir(parents=True)
    (workspace / 'src' / 'setup.py').write_text('# mine\n')
    (workspace / 'src' / 'elsewhere').symlink_to(host)
    snapshot = scratch.snapshot(NB01)
    assert (snapshot / 'src' / 'setup.py').read_text() == '# mine\n'
    assert (snapshot / 'src' / 'elsewhere').is_symlink()


def test_results_are_read_without_following_a_link(tmp_path, host):
    (tmp_path / 'out').mkdir()
    (tmp_path / 'out' / 'nb.run.ipynb').symlink_to(host / WORKSPACE_NAME / 'src' / 'secret.txt')
    with pytest.raises(NotARegularFile):
        read_regular(tmp_path / 'out', 'nb.run.ipynb', 1000)
    (tmp_path / 'out' / 'big').write_bytes(b'x' * 2000)
    with pytest.raises(NotARegularFile):
        read_regular(tmp_path / 'out', 'big', 1000)
    (tmp_path / 'out' / 'fine').write_bytes(b'{}')
    assert read_regular(tmp_path / 'out', 'fine', 1000) == b'{}'


@pytest.mark.sandbox
@pytest.mark.skipif(os.geteuid() != 0, reason='a size-capped scratch needs root (the grader is)')
def test_a_learners_home_holds_a_bounded_total(scratch):
    """Files each under the size limit still stop at the home's total: the learner's own
    disk is full, nobody else's (a learner's loop can write gigabytes in seconds)."""
    chunk = b'x' * (64 << 20)
    with pytest.raises(OSError, match='No space left'):
        for number in range(HOME_BYTES // len(chunk) + 2):
            (scratch.home / f'filler-{number}').write_bytes(chunk)
    assert scratch.home_full()


def mounts_below(folder):
    """The mount points below ``folder``, as /proc lists them."""
    with open('/proc/self/mounts') as mounts:
        return [line.split()[1] for line in mounts if line.split()[1].startswith(f'{folder}/')]


@pytest.mark.sandbox
@pytest.mark.skipif(os.geteuid() != 0, reason='a size-capped scratch needs root (the grader is)')
def test_what_a_killed_grader_left_is_swept_by_the_next(tmp_path):
    """A grader killed mid-class (a Dask worker's SIGKILL) cannot unmount its learners'
    tmpfs: the next grader on the machine removes its folder and mounts, never a running
    grader's."""
    ended = subprocess.run([sys.executable, '-c', 'import os; print(os.getpid())'],
                           capture_output=True, text=True, check=True)
    left = tmp_path / f'ros2nb-grading-{ended.stdout.strip()}-abc'
    running = tmp_path / f'ros2nb-grading-{os.getpid()}-def'
    unnamed = tmp_path / 'ros2nb-grading-xyz'
    for folder in (left, running, unnamed):
        folder.mkdir()
    Scratch(left, Learner('ada', 'ada')).snapshot('03-write-the-publisher')  # never removed
    assert len(mounts_below(left)) == 2  # the home and the snapshot: what a kill leaves
    assert sweep_left_behind('ros2nb-grading-', tmp_path) == [left]
    assert mounts_below(left) == [] and not left.exists()
    assert running.is_dir() and unnamed.is_dir()


def test_a_rewritten_status_is_not_trusted():
    good = {'ran': 3, 'cells': 9, 'timed_out': [1], 'output_cut': [], 'kernel_died_at': None,
            'finished': False}
    assert checked_status(good) == RunStatus(ran=3, cells=9, timed_out=(1,), output_cut=(),
                                             kernel_died_at=None, finished=False)
    forged = {'ran': 'all', 'cells': None, 'timed_out': 7, 'output_cut': {'a': 1},
              'kernel_died_at': [1], 'finished': 'yes'}
    assert checked_status(forged) is None
    assert checked_status({**good, 'timed_out': [True]}) is None
    assert checked_status([good]) is None


def test_a_status_with_one_field_of_the_wrong_type_is_the_learners_note(tmp_path):
    """The runner's status file, which the learner's code can rewrite, is read as its type
    (RunStatus), every field checked: the number of cells run, written as text, makes the
    whole status unread, and the learner gets the note they got before this was typed, not
    what the rest of it says (test_grading.py grades 'rewrites-its-status' so).  Taken as it
    came, the note 'its run ended at cell ...' would have failed on '3' + 1."""
    executed = nbformat.read(SOLUTION[NB01], as_version=4)
    (tmp_path / f'{NB01}.run.ipynb').write_text(nbformat.writes(executed))
    status = tmp_path / f'{NB01}.run.ipynb.status.json'
    written = dataclasses.asdict(RunStatus(ran=3, cells=9, timed_out=(), output_cut=(),
                                           finished=False))
    status.write_text(json.dumps(written))
    assert run_note(NotebookRun(*_read_back(tmp_path, NB01, executed))) == (
        'its run ended at cell 4 of 9: the notebook stopped or killed the processes running it')
    status.write_text(json.dumps({**written, 'ran': '3'}))
    assert run_note(NotebookRun(*_read_back(tmp_path, NB01, executed))) == (
        "running it stopped early: the runner's status was unreadable or rewritten (its kernel "
        'or the runner was killed, or the notebook changed it); what ran of the notebook is '
        'graded')


def test_malformed_nbgrader_metadata_is_removed_not_fatal():
    """A grade_id that is a list (a TypeError in the grader before) counts as no grade id."""
    release = nbformat.read(SOLUTION[NB01], as_version=4)
    submitted = nbformat.read(SOLUTION[NB01], as_version=4)
    submitted.cells.insert(3, nbformat.v4.new_code_cell('print(1)', metadata={'nbgrader': {
        'grade': True, 'grade_id': ['a', 'list'], 'points': 'ten', 'solution': False}}))
    prepared = notebooks.for_the_run(release, submitted)
    assert 'nbgrader' not in prepared.cells[3].metadata
    scored = notebooks.for_scoring(release, prepared, {})
    assert json.dumps(scored)  # nothing unserialisable left


def test_what_a_cell_printed_is_filed_whole_however_the_kernel_cut_it():
    """The same prints, sent by the kernel in one piece or in three (its flushes fall where a
    busy machine puts them), file the same notebook: the feedback page is the same."""
    release = nbformat.read(SOLUTION[NB01], as_version=4)
    printed = ['average rate: 2.000\n', '\tmin: 0.500s max: 0.500s\n', 'done\n']
    made = []
    for pieces in (printed, [''.join(printed)]):
        executed = nbformat.read(SOLUTION[NB01], as_version=4)
        cell = next(c for c in executed.cells
                    if c.cell_type == 'code' and not c.metadata.get('nbgrader', {}).get('grade'))
        cell.outputs = [*(nbformat.v4.new_output('stream', name='stdout', text=piece)
                          for piece in pieces),
                        nbformat.v4.new_output('stream', name='stderr', text='a warning\n')]
        made.append(nbformat.writes(notebooks.for_scoring(release, executed, {})))
    assert made[0] == made[1]


def test_a_notebook_without_code_of_the_learner_is_not_attempted():
    """Only a notebook whose code cells are the release's, text for text, goes unrun (0 points,
    noted); any code of the learner's, wherever they put it, gets the notebook run."""
    from grading_samples import LEARNER
    release = nbformat.read(LEARNER[NB01], as_version=4)
    assert notebooks.not_attempted(release, release)
    same = nbformat.read(LEARNER[NB01], as_version=4)
    code = [c for c in same.cells if c.cell_type == 'code']
    code[-1].source += '\n\n'  # blank lines are not writing
    next(c for c in same.cells if c.cell_type == 'markdown').source = 'my own notes'
    assert notebooks.not_attempted(release, same)
    answer = nbformat.read(SOLUTION[NB01], as_version=4)  # the answer cell written
    assert not notebooks.not_attempted(release, answer)
    own_cell = nbformat.read(LEARNER[NB01], as_version=4)  # the answer in a cell of their own
    own_cell.cells.append(nbformat.v4.new_code_cell('def documents_workspace(): ...'))
    assert not notebooks.not_attempted(release, own_cell)
    deleted = nbformat.read(LEARNER[NB01], as_version=4)
    deleted.cells.remove(next(c for c in deleted.cells if c.cell_type == 'code'))
    assert not notebooks.not_attempted(release, deleted)


#: Notebook 02's answer, right, that also puts a Python start-up file and a Fast DDS profile
#: wherever its judge might import or load them: its subject's cwd, home and temporary
#: folder, and every folder above them.
PLANTING_READER = '''\
import os
import xml.etree.ElementTree as ET
from pathlib import Path


def package_dependencies(package_xml: Path) -> list[str]:
    places = {Path.cwd(), Path(os.environ['HOME']), Path(os.environ.get('TMPDIR', '/tmp'))}
    for place in list(places):
        places.update(place.parents)
    for place in places:
        for name in ('sitecustomize.py', 'DEFAULT_FASTRTPS_PROFILES.xml'):
            try:
                (place / name).write_text('# planted by the learner')
            except OSError:
                pass
    return [e.text.strip() for e in ET.parse(package_xml).getroot() if e.tag == 'depend']
'''
PLANTED = ('sitecustomize.py', 'DEFAULT_FASTRTPS_PROFILES.xml')


@pytest.mark.sandbox
@pytest.mark.judge
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
@pytest.mark.timeout(300)
def test_a_subject_writes_nowhere_its_judge_reads(scratch, monkeypatch):
    """The learner's code in a subject may write its own folder, never the judge's cwd
    (``sys.path[0]`` of ``python -m``, where Fast DDS also looks for a profile), home or
    temporary folder. Before, the judge ran in the folder its subjects wrote, with its home
    and temporary folder inside: a later import or participant of the judge's could load
    the learner's file."""
    monkeypatch.setenv('ROS2NB_WORKSPACE', str(scratch.workspace))
    monkeypatch.setattr(ws_module, '_current', None)
    course.catch_up(3)  # the workspace as notebook 02 leaves it
    submitted = nbformat.read(SOLUTION[NB02], as_version=4)
    next(c for c in submitted.cells if 'def package_dependencies' in c.source).source = \
        PLANTING_READER
    results, problem, _flags = judge_notebook(scratch, NB02, submitted, Settings(120, 600, True),
                                             scratch.snapshot(NB02))
    assert problem is None and results and all(r.passed for r in results.values()), \
        results
    folder = scratch.top / f'judge-{NB02}'
    planted = {p.relative_to(folder).parts[0] for p in folder.rglob('*') if p.name in PLANTED}
    assert planted == {'subjects'}, f'a subject wrote files where its judge reads: {planted}'


#: A hook the learner's package declares (colcon.pkg) and installs: colcon has
#: install/setup.bash source it.  It notes that it ran and every judge process in sight,
#: and puts a program called bwrap first on the PATH it hands on: the same look again,
#: wherever that program runs, then the real bwrap.
LOOK_FOR_THE_JUDGE = '''\
for proc in /proc/[0-9]*; do
    if tr '\\0' ' ' < "$proc/cmdline" 2>/dev/null | grep -q 'ros2nb[.]judge'; then
        echo "$proc" >> "$HOME/saw-the-judge"
    fi
done
'''
PLANTED_HOOK = f'''\
touch "$HOME/hook-ran"
{LOOK_FOR_THE_JUDGE}
mkdir -p "$HOME/bin"
cat > "$HOME/bin/bwrap" <<'EOF'
#!/bin/sh
{LOOK_FOR_THE_JUDGE}
exec /usr/bin/bwrap "$@"
EOF
chmod +x "$HOME/bin/bwrap"
export PATH="$HOME/bin:$PATH"
'''


@pytest.mark.sandbox
@pytest.mark.judge
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
@pytest.mark.timeout(300)
def test_a_learners_build_scripts_never_run_in_the_judge(scratch, monkeypatch):
    """install/setup.bash and the hooks it sources were written by a build that ran the
    learner's setup.py: the judge has a subject source them and reads the environment
    that gives, as data.  Before, the judge sourced them itself, so a hook of the
    learner's ran beside the judge, in sight of its processes (and their stdout, where the
    verdict goes). The environment they give is the learner's nodes' own, set inside their
    sandbox: before, its PATH chose the program that sandboxes them, which then ran beside
    the judge. The judge grades with a seed of drawn inputs on its command line, which no
    process of the learner's sees."""
    monkeypatch.setenv('ROS2NB_WORKSPACE', str(scratch.workspace))
    monkeypatch.setattr(ws_module, '_current', None)
    course.catch_up(8)  # the package as notebook 05 leaves it (06 and 07 add no step)
    package = scratch.workspace / 'src' / course.PACKAGE
    (package / 'colcon.pkg').write_text(json.dumps(
        {'hooks': [f'share/{course.PACKAGE}/hook/planted.sh']}))
    (package / 'planted.sh').write_text(PLANTED_HOOK)
    # The hook goes in the notebook's own setup.py cell: the judge grades setup.py as the
    # notebook's %%part cells write it (ros2nb.judge.written), so a file changed beside them
    # would not carry it into the build.
    submitted = nbformat.read(SOLUTION[NB05], as_version=4)
    planted = [c for c in submitted.cells if c.source.startswith('%%part {SETUP_PY}')]
    assert len(planted) == 1, 'notebook 05 writes setup.py in one %%part cell'
    planted[0].source = planted[0].source.replace(
        '    data_files=[\n', f"    data_files=[\n        ('share/{course.PACKAGE}/hook', "
                             "['planted.sh']),\n", 1)
    assert 'planted.sh' in planted[0].source
    results, problem, _flags = judge_notebook(scratch, NB05, submitted,
                                             Settings(120, 600, True, seed=8675309),
                                             scratch.snapshot(NB05))
    assert problem is None and results and all(r.passed for r in results.values()), \
        results
    folder = scratch.top / f'judge-{NB05}'
    ran = [p.relative_to(folder).parts[0] for p in folder.rglob('hook-ran')]
    saw = [p.read_text().split() for p in folder.rglob('saw-the-judge')]
    # one hook-ran per process that sourced install/setup.bash: each has a home of its own
    assert ran and set(ran) == {'subjects'} and saw == [], \
        f'a hook of the learner\'s ran with the home of {ran}, in sight of the judge: {saw}'


def test_the_judge_hands_its_inputs_over_without_following_a_link(tmp_path, monkeypatch):
    """A learner's thread can swap the judge's scratch folder (subjects may write where it
    lies) for a link to a folder of the judge's own. A write by path then lands in that
    folder; what the judge hands over goes to the folder it made, whatever the path holds."""
    from ros2nb.errors import CheckFailed
    from ros2nb.judge.session import Session

    judges_own = tmp_path / 'judges-own'
    judges_own.mkdir()
    session = Session(tmp_path)
    try:
        made = session.scratch
        made.rename(tmp_path / 'moved-aside')
        made.symlink_to(judges_own)
        (made / 'by-path.xml').write_text('x')  # what the judge did before: it follows the link
        assert [p.name for p in judges_own.iterdir()] == ['by-path.xml']

        folder = session.hand_over('ros2nb-package-', {'graded_reader/package.xml': b'<p/>'})
        assert [p.name for p in judges_own.iterdir()] == ['by-path.xml']
        kept = tmp_path / 'moved-aside' / folder.name / 'graded_reader' / 'package.xml'
        assert kept.read_bytes() == b'<p/>'

        # A learner who guesses the next name and puts a link there first: never written through
        monkeypatch.setattr('secrets.token_hex', lambda _n: 'guessed')
        (tmp_path / 'moved-aside' / 'ros2nb-package-guessed').symlink_to(judges_own)
        with pytest.raises(CheckFailed, match="The check's own folder .* changed while the "
                                              r'grader wrote it \(File exists\)'):
            session.hand_over('ros2nb-package-', {'graded_reader/package.xml': b'<p/>'})
        assert [p.name for p in judges_own.iterdir()] == ['by-path.xml']
    finally:
        made.unlink()
        (tmp_path / 'moved-aside').rename(made)
        session.close()


def test_the_judge_reads_a_learners_bag_from_its_own_copy_links_refused(tmp_path):
    """A bag whose metadata.yaml is a link to a file only the judge may read: read by path,
    the judge read that file (and its words could reach the feedback); its own copy has
    the learner's files only, and a link gets one line."""
    from ros2nb.errors import CheckFailed
    from ros2nb.judge.session import Session

    secret = tmp_path / 'judge-only.yaml'
    secret.write_text('the hidden tests\n')
    session = Session(tmp_path)
    try:
        bag = session.scratch / 'ros2nb-bag-x' / 'hour'
        bag.mkdir(parents=True)
        (bag / 'hour_0.mcap').write_bytes(b'mcap')
        with session.taken_back(bag) as copy:
            assert sorted(p.name for p in copy.iterdir()) == ['hour_0.mcap']
            assert not copy.is_relative_to(session.scratch)  # where no subject sees it
        (bag / 'metadata.yaml').symlink_to(secret)
        assert (bag / 'metadata.yaml').read_text() == 'the hidden tests\n'  # by path
        with pytest.raises(CheckFailed, match=r'metadata.yaml cannot be read \(Too many levels '
                                              r'of symbolic links\): the grader reads files'):
            with session.taken_back(bag):
                pass
        (bag / 'metadata.yaml').unlink()
        bag.rename(bag.with_name('elsewhere'))
        bag.symlink_to(tmp_path)  # the bag folder itself a link
        with pytest.raises(CheckFailed, match=r'hour is not a folder'):
            with session.taken_back(bag):
                pass
    finally:
        session.close()


@pytest.mark.sandbox
@pytest.mark.judge
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
@pytest.mark.timeout(300)
@pytest.mark.parametrize('who', ['twin', 'attack'])
def test_a_copy_of_the_stand_ins_scores_its_twins_score_in_the_sandbox(who, scratch, monkeypatch):
    """The grader's judge, sandboxed with its subjects: notebook 03 built from the course's
    stand-ins through importlib loses what its twin (parts from a module that is not there)
    loses, and only it is flagged.  Before, its subjects imported the stand-ins: full marks."""
    from corpora import Learner as CorpusLearner, submission, write_parts
    from corpus_attacks import SENSOR_PARTS, SENSOR_PARTS_TWIN
    monkeypatch.setenv('ROS2NB_WORKSPACE', str(scratch.workspace))
    monkeypatch.setattr(ws_module, '_current', None)
    monkeypatch.setattr(course, 'reference_source', lambda name: None)
    cells = SENSOR_PARTS if who == 'attack' else SENSOR_PARTS_TWIN
    nb = submission(CorpusLearner(who, '03', cells))
    course.catch_up(3)
    write_parts(nb)
    notebook = '03-write-the-publisher'
    results, problem, flags = judge_notebook(scratch, notebook, nbformat.from_dict(nb),
                                             Settings(120, 600, True), scratch.snapshot(notebook))
    assert problem is None, problem
    lost = {gid for gid, r in results.items() if not r.passed}
    assert lost == {f'{notebook[:2]}-{part}' for part in (
        'sensor-constructor', 'sensor-callback', 'sensor-hour')}, results
    assert bool(flags) == (who == 'attack'), flags
