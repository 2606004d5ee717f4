"""Grading on a real Dask cluster: ``dask scheduler`` and ``dask worker`` processes on loopback.

A small class (one learner per path a learner takes through the cluster: several notebooks on
one worker, a notebook not attempted, a file that is no notebook, a name nbgrader cannot use,
a browser's copy, a run that kills its kernel, code the judge flags) is graded twice with one
seed: here, and through two workers, one of which is killed (SIGKILL) while it holds a learner.
Both gradings end alike: the same scores, notes and feedback pages, byte for byte (the flags box
of "Code your instructor will look at" included), every learner graded exactly once.  A worker
of another course version is refused before any learner runs there; a learner whose task fails
on the workers is that learner's note.
"""

import csv
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
from dataclasses import dataclass
from pathlib import Path

import nbformat
import pytest

from dask_cluster import kill_when_grading, local_cluster
from grading_samples import EXPECTED, LEARNER, NB00, NB01, NB02, ROOT, SOLUTION, Case
from notebook_outputs import sanitize
from test_grading import CLASS_LIMIT_S, as_text, in_the_csv

from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.cluster.client import Cluster
from ros2nb_instructor.grading.reports.feedback import FLAGS_HEADING
from ros2nb_instructor.grading.scores.nbgrader_course import set_up_course
from ros2nb_instructor.grading.judging.learners import FLAGGED
from ros2nb_instructor.grading.judging.settings import CELL_TIMEOUT_S, NOTEBOOK_TIMEOUT_S, Settings
from ros2nb_instructor.grading.intake.submissions import find_learners

pytestmark = [pytest.mark.sandbox, pytest.mark.timeout(CLASS_LIMIT_S),
              pytest.mark.skipif(bubblewrap.problem() is not None,
                                 reason=str(bubblewrap.problem()))]
GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
NOTEBOOKS = sorted(SOLUTION)
#: The seed of both gradings' drawn inputs: the judges check both alike.
SEED = 4242
#: A progress line, as a local grading prints it.
PROGRESS = re.compile(r'^\[\d+/\d+ notebooks, \d+/\d+ learners; .* so far, .*\] (.*) graded$')
#: Notebook 01's answer with a call the judge flags (it reads stack frames): no point lost.
REACHING_IN = ("    return Path('~/Documents/ROS2_and_RL_Tutorials').expanduser()",
               "    import sys\n    sys._getframe(0)\n"
               "    return Path('~/Documents/ROS2_and_RL_Tutorials').expanduser()")


def _reaches_in() -> str:
    nb = nbformat.read(SOLUTION[NB01], as_version=4)
    answer = next(c for c in nb.cells if REACHING_IN[0] in c.source)
    answer.source = answer.source.replace(*REACHING_IN)
    return nbformat.writes(nb)


def small_class(folder: Path, learners: dict[str, dict[str, str]]) -> Path:
    """Learners of a few notebooks each: name -> {file name or notebook: the file's text}."""
    for name, files in learners.items():
        (folder / name).mkdir(parents=True)
        for notebook, text in files.items():
            file = notebook if notebook.endswith('.ipynb') else f'{notebook}.ipynb'
            (folder / name / file).write_text(text)
    return folder


#: The class: each learner one path through the cluster, with what grading must make of them.
CLASS = {
    'complete': Case({n: EXPECTED['complete'].scores[n] for n in (NB00, NB01, NB02)}),
    'untouched': Case({NB01: 0, NB02: 0}, {}, {NB01: 'not attempted', NB02: 'not attempted'}),
    'empty-file': EXPECTED['empty-file'],
    'Lovelace, Ada': Case({NB01: 1}, {}, {'_folder': 'graded under the id learner-'}),
    'browser-copy': Case({NB01: 1}, {}, {NB01: f'graded {NB01} (1).ipynb as {NB01}.ipynb'}),
    'kills-its-kernel': EXPECTED['kills-its-kernel'],
    # Frames read while the grader ran the code: the point stays (the judge decides on what
    # it sees; the hook only notes), and the flags box for the instructor says why, carried
    # back from the cluster like any feedback.
    'reaches-in': Case({NB01: 1}, {NB01: FLAGS_HEADING},
                       {NB01: f'{FLAGGED} answer cell {NB01}-challenge-1 line'}),
}


def class_files() -> dict[str, dict[str, str]]:
    solution = {n: SOLUTION[n].read_text() for n in (NB00, NB01, NB02)}
    killer = nbformat.read(SOLUTION[NB01], as_version=4)
    killer.cells.insert(1, nbformat.v4.new_code_cell(
        'import os, signal\nos.kill(os.getpid(), signal.SIGKILL)'))
    return {'complete': solution,
            'untouched': {n: LEARNER[n].read_text() for n in (NB01, NB02)},
            'empty-file': {NB01: ''},
            'Lovelace, Ada': {NB01: solution[NB01]},
            'browser-copy': {f'{NB01} (1).ipynb': solution[NB01]},
            'kills-its-kernel': {NB01: nbformat.writes(killer)},
            'reaches-in': {NB01: _reaches_in()}}


def grade(submissions: Path, out: Path, address: str = '', seed: int | None = None
          ) -> subprocess.CompletedProcess:
    """ros2nb-grade on ``submissions`` (on the Dask scheduler at ``address``, else here)."""
    where = ['--scheduler', address] if address else []
    drawn = ['--seed', str(seed)] if seed is not None else []
    return subprocess.run([GRADE, str(submissions), '--out', str(out), *where, *drawn],
                          capture_output=True, text=True, timeout=CLASS_LIMIT_S)


def graded_lines(stdout: str) -> list[str]:
    """The learners named by the progress lines, one per line printed."""
    return [m.group(1) for m in map(PROGRESS.match, stdout.splitlines()) if m]


@dataclass(frozen=True)
class OnDask:
    out: Path
    done: subprocess.CompletedProcess
    killed: dict  #: the worker killed while it held a learner: address, pid, its keys
    here: Path  #: the same class graded on this machine
    done_here: subprocess.CompletedProcess


@pytest.fixture(scope='module')
def on_dask(tmp_path_factory):
    """The small class graded here, then on two workers, one of them killed while it holds a
    learner (its nanny starts it again, as Kubernetes restarts a pod; the new worker is
    checked before it grades)."""
    root = tmp_path_factory.mktemp('dask-grading')
    submissions = small_class(root / 'class', class_files())
    here = root / 'grading-here'
    done_here = grade(submissions, here, seed=SEED)
    out = root / 'grading'
    killed = {}
    with local_cluster(root / 'cluster') as cluster:
        killer = threading.Thread(target=lambda: killed.update(
            kill_when_grading(cluster.address, 'w1')), daemon=True)
        killer.start()
        done = grade(submissions, out, cluster.address, seed=SEED)
        killer.join(timeout=1)
    yield OnDask(out, done, killed, here, done_here)


#: A learner's scratch folder, as a cell's output may show it: new for every grading (here
#: under the grader's temporary folder, on a worker under the worker's).
SCRATCH = re.compile(r'/tmp/ros2nb-(?:grading|worker)-[\w-]+/(?:scratch/)?learner-\w+/')


#: The box of "Code your instructor will look at" on a feedback page.
FLAGS_BOX = re.compile(r'<div id="flags".*?</ul>', re.S)


def pages(out: Path) -> dict[str, str]:
    """Every feedback page of a grading: its path under feedback/ -> its text, the learner's
    scratch folder aside, and what nbval sets aside of the notebooks' outputs in ``make test``
    (tests/sanitize.cfg: a build's seconds, a kernel's domain)."""
    return {str(p.relative_to(out / 'feedback')): sanitize(SCRATCH.sub('<scratch>/',
                                                                       p.read_text()))
            for p in sorted((out / 'feedback').rglob('*.html'))}


@pytest.mark.judge
@pytest.mark.kernel
def test_the_class_on_dask_scores_as_the_local_run(on_dask):
    out, done = on_dask.out, on_dask.done
    assert done.returncode == 0, done.stdout + done.stderr
    with open(out / 'grades.csv', newline='') as stream:
        got = {(r['learner'], r['notebook']): float(r['score']) for r in csv.DictReader(stream)}
    for learner, case in CLASS.items():
        for notebook in NOTEBOOKS:
            assert got[in_the_csv(learner), notebook] == case.scores.get(notebook, 0), \
                (learner, notebook)
    notes = json.loads((out / 'notes.json').read_text())['learners']
    for learner, case in CLASS.items():
        for notebook, phrase in case.notes.items():
            if phrase:
                assert phrase in notes[as_text(learner)].get(notebook, ''), (learner, notes)
    for learner, case in CLASS.items():
        for notebook, phrase in case.feedback.items():
            page = (out / 'feedback' / learner / f'{notebook}.html').read_text()
            assert phrase in page, (learner, notebook)
    assert FLAGS_HEADING not in (out / 'feedback' / 'complete' / f'{NB01}.html').read_text()
    for made in ('report.html', 'nbgrader/gradebook.db'):
        assert (out / made).is_file(), made


@pytest.mark.judge
@pytest.mark.kernel
def test_a_class_graded_on_dask_ends_as_graded_here(on_dask):
    """The same feedback pages, byte for byte but for the learner's scratch folder a cell may
    print and what nbval sets aside (the flags box of a flagged learner too), the same
    grades.csv and the same notes: what a worker made of a learner came back whole."""
    assert on_dask.done_here.returncode == 0, on_dask.done_here.stdout + on_dask.done_here.stderr
    assert on_dask.done.returncode == 0, on_dask.done.stdout + on_dask.done.stderr
    here, there = pages(on_dask.here), pages(on_dask.out)
    assert FLAGS_HEADING in here[f'reaches-in/{NB01}.html']  # the box the cluster must carry
    assert sorted(there) == sorted(here)
    for page in here:  # the flags box first: a worker that lost the flags fails here, named
        assert FLAGS_BOX.findall(there[page]) == FLAGS_BOX.findall(here[page]), page
    for page in here:
        assert there[page] == here[page], page
    for made in ('grades.csv', 'notes.json'):
        assert (on_dask.out / made).read_text() == (on_dask.here / made).read_text(), made


@pytest.mark.judge
@pytest.mark.kernel
def test_a_worker_killed_mid_class_costs_nobody(on_dask):
    """The worker held a learner in its sandbox when it was killed; that learner was graded
    again elsewhere, and every learner was taken once (one progress line, one TOTAL row)."""
    out, done, killed = on_dask.out, on_dask.done, on_dask.killed
    assert killed.get('keys'), f'no worker was killed while grading: {done.stdout[-2000:]}'
    assert done.returncode == 0, done.stdout + done.stderr
    learners = sorted(as_text(name) for name in CLASS)
    assert sorted(graded_lines(done.stdout)) == learners
    with open(out / 'grades.csv', newline='') as stream:
        totals = [r['learner'] for r in csv.DictReader(stream) if r['notebook'] == 'TOTAL']
    assert sorted(totals) == sorted(in_the_csv(name) for name in CLASS)
    notes = json.loads((out / 'notes.json').read_text())['learners']
    for key in killed['keys']:
        learner = next(name for name in learners if str(key).endswith(f'-{name}'))
        assert 'could not grade' not in json.dumps(notes[learner]), notes[learner]
    # The killed worker could not unmount its learner's tmpfs; a later task swept them.
    left = list(Path(tempfile.gettempdir()).glob(f"ros2nb-worker-{killed['pid']}-*"))
    assert left == [], left


def other_course(folder: Path) -> Path:
    """A copy of the course whose solutions changed by one byte: another course version."""
    for part in ('src/ros2nb', 'src/ros2nb_instructor', 'solutions', 'environment'):
        shutil.copytree(ROOT / part, folder / part,
                        ignore=shutil.ignore_patterns('__pycache__'))
    changed = folder / 'solutions' / f'{NB01}.ipynb'
    changed.write_bytes(changed.read_bytes() + b'\n')
    return folder


def test_a_worker_of_another_course_is_refused(tmp_path, capsys):
    """Refused with one line before any learner runs there; alone, grading does not start."""
    untouched = (ROOT / 'notebooks' / f'{NB01}.ipynb').read_text()
    submissions = small_class(tmp_path / 'class', {f'learner-{n}': {NB01: untouched}
                                                         for n in range(4)})
    other = other_course(tmp_path / 'other-course')
    env = dict(os.environ, PYTHONPATH=str(other / 'src'))
    with local_cluster(tmp_path / 'cluster', workers=0) as cluster:
        cluster.add_worker('other', env=env, cwd=other)
        cluster.wait_for_workers(1)
        alone = grade(submissions, tmp_path / 'grading', cluster.address)
        assert alone.returncode == 2, alone.stdout + alone.stderr
        refusals = [line for line in alone.stdout.splitlines() if 'refused' in line]
        assert len(refusals) == 1 and 'its course is version' in refusals[0], alone.stdout
        assert 'No worker of the Dask scheduler' in alone.stdout
        assert 'Traceback' not in alone.stdout + alone.stderr
        assert not (tmp_path / 'grading').exists()

        cluster.add_worker('same')
        cluster.wait_for_workers(2)
        course = tmp_path / 'course'
        course.mkdir()
        notebooks = set_up_course(course)
        learners, _ = find_learners(submissions, notebooks)
        graded = Cluster(cluster.address, Settings(CELL_TIMEOUT_S, NOTEBOOK_TIMEOUT_S, True))
        try:
            for _batch in graded.graded(course, learners, notebooks):
                pass
        finally:
            graded.close()
    said = capsys.readouterr().out
    assert [line for line in said.splitlines() if 'refused' in line] == refusals
    assert list(graded.refused) == [refusals[0].split()[1]]
    assert sorted(graded.graded_by) == sorted(learner.id for learner in learners)
    assert set(graded.graded_by.values()).isdisjoint(graded.refused), graded.graded_by
    assert all('not attempted' in learner.notes[NB01] for learner in learners)


@pytest.mark.judge
@pytest.mark.kernel
def test_a_learner_whose_task_fails_is_that_learners_note(tmp_path):
    """A scheduler that gives a task no second worker (allowed-failures 0): the learner whose
    worker is killed under them gets a note and 0; the class around them is graded (on the
    worker started again, checked before it grades)."""
    complete = SOLUTION[NB01].read_text()
    sleeper = json.loads(complete)
    sleeper['cells'].insert(1, {'cell_type': 'code', 'metadata': {}, 'outputs': [],
                                'execution_count': None,
                                'source': 'import time\ntime.sleep(100)'})
    # The sleeper has fewer notebooks, so the worker takes it last: when it is killed under
    # the sleeper it holds nobody else (honest's are the solutions, 1 point each).
    submissions = small_class(tmp_path / 'class', {
        'sleeper': {NB01: json.dumps(sleeper)}, 'empty': {NB00: '', NB01: ''},
        'honest': {NB00: SOLUTION[NB00].read_text(), NB01: complete}})
    env = dict(os.environ, DASK_DISTRIBUTED__SCHEDULER__ALLOWED_FAILURES='0')
    with local_cluster(tmp_path / 'cluster', workers=1, env=env) as cluster:
        killed = {}
        killer = threading.Thread(target=lambda: killed.update(
            kill_when_grading(cluster.address, 'w0', learner='sleeper', alone=True)), daemon=True)
        killer.start()
        done = grade(submissions, tmp_path / 'grading', cluster.address)
        killer.join(timeout=1)
    assert killed, done.stdout
    assert done.returncode == 0, done.stdout + done.stderr
    notes = json.loads((tmp_path / 'grading' / 'notes.json').read_text())['learners']
    assert 'the grader could not grade this learner (KilledWorker' in notes['sleeper']['_folder']
    with open(tmp_path / 'grading' / 'grades.csv', newline='') as stream:
        totals = {r['learner']: r['score'] for r in csv.DictReader(stream)
                  if r['notebook'] == 'TOTAL'}
    assert totals == {'sleeper': '0', 'honest': '2', 'empty': '0'}, done.stdout
    assert sorted(graded_lines(done.stdout)) == ['empty', 'honest', 'sleeper']


@pytest.mark.judge
@pytest.mark.kernel
def test_a_class_outlives_its_only_worker(tmp_path):
    """The one worker is killed while it holds every learner left (one in its sandbox, the
    others queued on it): its nanny starts it again, the new worker is checked, the learners
    no worker could take are submitted to it, and each is graded once, as if nothing happened."""
    complete = SOLUTION[NB01].read_text()
    slow = json.loads(complete)
    slow['cells'].insert(1, {'cell_type': 'code', 'metadata': {}, 'outputs': [],
                             'execution_count': None, 'source': 'import time\ntime.sleep(20)'})
    # The slow learner has more notebooks, so the worker takes it first and holds the rest.
    submissions = small_class(tmp_path / 'class', {
        'slow': {NB00: SOLUTION[NB00].read_text(), NB01: json.dumps(slow)},
        'honest': {NB01: complete}, 'empty': {NB01: ''}})
    with local_cluster(tmp_path / 'cluster', workers=1) as cluster:
        killed = {}
        killer = threading.Thread(target=lambda: killed.update(
            kill_when_grading(cluster.address, 'w0', learner='slow')), daemon=True)
        killer.start()
        done = grade(submissions, tmp_path / 'grading', cluster.address)
        killer.join(timeout=1)
    assert killed, done.stdout
    assert done.returncode == 0, done.stdout + done.stderr
    with open(tmp_path / 'grading' / 'grades.csv', newline='') as stream:
        totals = {r['learner']: r['score'] for r in csv.DictReader(stream)
                  if r['notebook'] == 'TOTAL'}
    assert totals == {'slow': '2', 'honest': '1', 'empty': '0'}, done.stdout
    assert sorted(graded_lines(done.stdout)) == ['empty', 'honest', 'slow']
