"""Grading from the instructor's command line: a platform's zip, bad input, no sandbox.

Apart from tests/test_grading.py (one sample class, graded once) so that the two run side
by side under pytest-xdist (``--dist loadfile`` keeps a file on one worker).
"""

import csv
import fcntl
import os
import shutil
import signal
import subprocess
import sys
import threading
import zipfile
from pathlib import Path

import pytest

from grading_samples import LEARNER, NB01, SOLUTION
from waiting import PATIENCE_S, wait_for

from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.paths import ASSIGNMENT, gradebook_url

#: The instructor's grading command, as the course's venv installs it.
GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))

pytestmark = pytest.mark.timeout(1200)
#: ros2nb-grade refuses to start without a sandbox (unless told: NO_SANDBOX=1).
NEEDS_A_SANDBOX = pytest.mark.skipif(bubblewrap.problem() is not None,
                                     reason=str(bubblewrap.problem()))


@pytest.mark.sandbox
@pytest.mark.judge
@pytest.mark.kernel
@NEEDS_A_SANDBOX
def test_zip_from_a_learning_platform(tmp_path):
    """A learner is a folder at the archive's top (below one export folder); nested archives
    are refused, and nothing below a learner's folder names another learner.

    mallory's folder holds alice/, extracted/bob/ and carol/: all three are mallory's files
    (graded as one notebook of hers, the other copies named), never alice's, bob's or a
    carol's (before, alice and bob were refused as "in 2 places" and carol was graded from
    mallory's file).
    """
    solved, unsolved = SOLUTION[NB01], LEARNER[NB01]
    inner = tmp_path / 'inner.zip'
    with zipfile.ZipFile(inner, 'w') as zipped:
        zipped.write(solved, f'dan/{NB01}.ipynb')  # would decide who is graded if unpacked
    archive = tmp_path / 'class.zip'
    with zipfile.ZipFile(archive, 'w') as zipped:
        zipped.write(solved, f'course-export/ada/{NB01}.ipynb')
        zipped.write(unsolved, f'course-export/bo/{NB01}.ipynb')
        zipped.write(inner, 'course-export/eve/extra.zip')
        zipped.write(solved, f'course-export/eve/{NB01}.ipynb')
        zipped.write(unsolved, f'course-export/alice/{NB01}.ipynb')
        zipped.write(unsolved, f'course-export/bob/{NB01}.ipynb')
        zipped.write(solved, f'course-export/mallory/alice/{NB01}.ipynb')
        zipped.write(solved, f'course-export/mallory/extracted/bob/{NB01}.ipynb')
        zipped.write(solved, f'course-export/mallory/carol/{NB01}.ipynb')
    done = subprocess.run([GRADE, str(archive),
                           '--out', str(tmp_path / 'grading'), '--cell-timeout=60'],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    rows = {(r['learner'], r['notebook']): r['score']
            for r in csv.DictReader(open(tmp_path / 'grading' / 'grades.csv'))}
    totals = {learner: score for (learner, notebook), score in rows.items()
              if notebook == 'TOTAL'}
    assert totals == {'ada': '1', 'bo': '0', 'eve': '1', 'alice': '0', 'bob': '0',
                      'mallory': '1'}, done.stdout
    assert ('not graded: course-export/eve/extra.zip: an archive inside the archive is not '
            'unpacked') in done.stdout
    assert (f'not graded: course-export/mallory/carol/{NB01}.ipynb: another copy of '
            f'{NB01}.ipynb in mallory\'s folder; graded course-export/mallory/alice/'
            f'{NB01}.ipynb') in done.stdout
    assert 'appears in' not in done.stdout


@NEEDS_A_SANDBOX
def test_force_replaces_an_earlier_grading_only_once_complete(tmp_path):
    """FORCE=1 with a grading that cannot finish (here: no learner) keeps the earlier one.

    Before, the earlier grading/ was deleted first and the failed run left nothing.
    """
    earlier = tmp_path / 'grading'
    earlier.mkdir()
    (earlier / 'grades.csv').write_text('manual work\n')
    (tmp_path / 'class' / 'not-a-notebook.txt').parent.mkdir()
    (tmp_path / 'class' / 'not-a-notebook.txt').write_text('hello\n')
    done = subprocess.run([GRADE, str(tmp_path / 'class'), '--out', str(earlier), '--force'],
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 2 and 'has no learner folders' in done.stdout, done.stdout
    assert (earlier / 'grades.csv').read_text() == 'manual work\n'
    assert sorted(p.name for p in tmp_path.iterdir()) == ['class', 'grading']  # nothing left


@NEEDS_A_SANDBOX
def test_bad_input_gets_one_line(tmp_path):
    def grade(*args):
        return subprocess.run([GRADE, *args],
                              capture_output=True, text=True)
    missing = grade(str(tmp_path / 'nope'), '--out', str(tmp_path / 'g1'))
    assert missing.returncode == 2 and missing.stdout.count('\n') == 1
    assert 'does not exist' in missing.stdout
    (tmp_path / 'g2').mkdir()
    (tmp_path / 'g2' / 'grades.csv').write_text('manual work\n')
    (tmp_path / 'class').mkdir()
    again = grade(str(tmp_path / 'class'), '--out', str(tmp_path / 'g2'))
    assert again.returncode == 2 and 'FORCE=1' in again.stdout
    assert (tmp_path / 'g2' / 'grades.csv').read_text() == 'manual work\n'  # untouched
    # A term's inputs: a time the grader will not guess at, a roster row an unquoted comma
    # shifts, an extension of a learner nobody knows; each one line, the earlier grading kept.
    (tmp_path / 'class' / 'ada').mkdir()
    shutil.copy(SOLUTION[NB01], tmp_path / 'class' / 'ada' / f'{NB01}.ipynb')
    stamp = tmp_path / 'class' / 'ada' / 'timestamp.txt'
    (tmp_path / 'roster.csv').write_text('learner,name,sis_id\nada,Lovelace, Ada,S-1\n')
    (tmp_path / 'extensions.toml').write_text('[adda]\n"01" = { days = 1 }\n')
    (tmp_path / 'course.toml').write_text(f'[notebooks.{NB01}]\ndue = 2026-10-05T23:59:00Z\n')
    cases = [('2026-10-05 23:30:00 CEST', [],
              "timestamp.txt: '2026-10-05 23:30:00 CEST' is not a time with its offset"),
             ('2026-10-05T23:30:00Z', ['--roster', str(tmp_path / 'roster.csv')],
              'roster.csv line 2: 4 fields where the header has 3'),
             ('2026-10-05T23:30:00Z', ['--extensions', str(tmp_path / 'extensions.toml')],
              "no learner 'adda' in the submissions or the roster")]
    for time, extra, said in cases:
        stamp.write_text(time)
        refused = grade(str(tmp_path / 'class'), '--out', str(tmp_path / 'g2'), '--force',
                        '--settings', str(tmp_path / 'course.toml'), *extra)
        assert refused.returncode == 2 and refused.stdout.count('\n') == 1, refused.stdout
        assert said in refused.stdout, refused.stdout
        assert (tmp_path / 'g2' / 'grades.csv').read_text() == 'manual work\n'


def test_without_a_sandbox_grading_refuses_unless_told(tmp_path):
    """With bubblewrap not on PATH, one line; NO_SANDBOX=1 is the explicit way round."""
    (tmp_path / 'class' / 'ada').mkdir(parents=True)
    env = {**os.environ, 'PATH': str(Path(sys.executable).parent)}  # no /usr/bin: no bwrap
    done = subprocess.run([GRADE,
                           str(tmp_path / 'class'), '--out', str(tmp_path / 'g')],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 2
    assert done.stdout == ("No sandbox can be made here (bubblewrap is not installed: apt-get "
                           "install bubblewrap); grading runs learners' code, so it stops. For "
                           "work you trust, run again with NO_SANDBOX=1 (--no-sandbox).\n")


def test_a_scoring_process_that_ended_is_started_again(tmp_path):
    """nbgrader scores a class batch by batch in one process (gradebook.Scoring); one that
    ended between two batches (killed, crashed) is started again for the next batch, whose
    learner is scored all the same (without the new start, that batch was lost: 0 points)."""
    # Here, not at the top: nbgrader's package imports its server extensions (costly), and
    # every pytest-xdist worker imports each test file while it collects.
    from nbgrader.api import Gradebook
    from ros2nb_instructor.grading.scores.gradebook import Scoring
    from ros2nb_instructor.grading.scores.nbgrader_course import set_up_course
    course = tmp_path / 'nbgrader'
    course.mkdir()
    set_up_course(course)
    for learner in ('ada', 'bo'):
        folder = course / 'submitted' / learner / ASSIGNMENT
        folder.mkdir(parents=True)
        shutil.copy(SOLUTION[NB01], folder / f'{NB01}.ipynb')  # its check's output: passed
    with Scoring(course) as scoring:
        assert scoring.score(exclude=['bo'])
        scorers = [pid for pid in os.listdir('/proc') if pid.isdigit() and _runs(
            pid, b'ros2nb_instructor.grading.scores.scoring', str(course).encode())]
        assert len(scorers) == 1, scorers
        os.kill(int(scorers[0]), signal.SIGKILL)
        assert scoring.score(exclude=['ada'])
    with Gradebook(gradebook_url(course)) as gradebook:
        assert [gradebook.find_submission_notebook(NB01, ASSIGNMENT, learner).score
                for learner in ('ada', 'bo')] == [1, 1]


def _runs(pid: str, *words: bytes) -> bool:
    """Whether process ``pid``'s command line holds every one of ``words``."""
    try:
        command = Path(f'/proc/{pid}/cmdline').read_bytes()
    except OSError:
        return False
    return all(word in command for word in words)


@pytest.mark.parametrize('locked', [True, False], ids=['with the lock', 'without it'])
def test_a_grading_waits_for_the_course_another_is_making(locked, tmp_path, monkeypatch):
    """The nbgrader course is made once per version of the solutions (``kept_course``): a
    grading that asks while another is making it waits for that one.  Without the lock the
    second made it again (nbgrader's generate_assignment, seconds of CPU).  generate_assignment
    is played by a stand-in that holds until the test lets it finish."""
    from ros2nb_instructor.grading.scores import nbgrader_course
    monkeypatch.setattr(nbgrader_course, 'SET_UP_CACHE', tmp_path)
    made, at_lock, finish = [], [], threading.Event()
    real_flock = fcntl.flock

    def flock(fd, operation):
        at_lock.append(operation)
        if locked:
            real_flock(fd, operation)

    def generate(kept):
        made.append(kept)
        finish.wait(PATIENCE_S)
        kept.mkdir(exist_ok=True)
        (kept / 'gradebook.db').write_bytes(b'')

    monkeypatch.setattr(fcntl, 'flock', flock)
    monkeypatch.setattr(nbgrader_course, '_generate_course', generate)
    found = []
    graders = [threading.Thread(target=lambda: found.append(nbgrader_course.kept_course()))
               for _ in range(2)]
    graders[0].start()
    wait_for(lambda: made, 'the first grading making the course')
    graders[1].start()
    wait_for(lambda: len(at_lock) == 2, 'the second grading at the lock')
    if not locked:
        wait_for(lambda: len(made) == 2, 'the second grading making the course too')
    finish.set()
    for grader in graders:
        grader.join(PATIENCE_S)
    assert len(made) == (1 if locked else 2)
    assert found == [tmp_path / nbgrader_course._solutions_digest()] * 2
