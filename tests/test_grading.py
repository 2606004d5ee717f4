"""Grading a sample class with ros2nb-grade: real sandboxes, kernels, judges, nbgrader.

The class (tests/grading_samples.py) holds honest learners and one learner per hostile case.
Every score, every CSV row and every note is checked; then that nothing escaped: the
repository, the real home and a gradebook outside are byte-identical, and no process of the
class is left. The honest learners' scores are the ones they earn alone.
"""

import contextlib
import csv
import hashlib
import html
import json
import os
import re
import shutil
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

import pytest

from grading_samples import (EXPECTED, FULL, GRADE_WITH_FAULTS, MARK, NB01, NOT_UTF8, PWNED, ROOT,
                             SOLUTION, STAGES, build)

from ros2nb.temporary import owned_folder
from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.sandbox.scratch import HOME_BYTES

#: The longest the class may take to grade (s): a hang detector, not a speed target (make bench
#: is that), with room for a slow day on 2 cores beside CPU burners (docs/decisions.md).
CLASS_LIMIT_S = 1800
pytestmark = [pytest.mark.sandbox, pytest.mark.judge, pytest.mark.kernel,
              pytest.mark.timeout(CLASS_LIMIT_S),
              pytest.mark.skipif(bubblewrap.problem() is not None,
                                 reason=str(bubblewrap.problem()))]
#: The class is graded by ros2nb-grade's own main (GRADE_WITH_FAULTS: five learners meet a
#: planted fault) with its default limits per cell and per notebook: an honest notebook must
#: never meet them, however busy the machine (a 30 s limit cut a complete learner's simulated
#: hour under load).
NOTEBOOKS = sorted(SOLUTION)
#: Learners graded at once. Two learners of the class hang a cell until the 120 s limit: with
#: the default (the CPUs + 1) they hold two of three jobs for two minutes while the rest of
#: the class waits; they use no CPU meanwhile, so more jobs cost nothing.
CLASS_JOBS = 6


def fingerprint(root: Path, skip=('.venv', '.git', '.cache')) -> dict[str, str]:
    """Every file under ``root`` (git-ignored ones too): its content's hash."""
    found = {}
    for path in root.rglob('*'):
        parts = path.relative_to(root).parts
        if parts[0] in skip or '__pycache__' in parts or not path.is_file():
            continue
        found[str(path.relative_to(root))] = hashlib.sha256(path.read_bytes()).hexdigest()
    return found


def survivors() -> list[str]:
    """Processes whose command line carries the hostile samples' mark."""
    found = []
    for entry in os.listdir('/proc'):
        if entry.isdigit():
            try:
                command = Path(f'/proc/{entry}/cmdline').read_bytes()
            except OSError:
                continue
            if MARK.encode() in command and b'pytest' not in command:
                found.append(entry)
    return found


@contextlib.contextmanager
def disk_watched(folder: Path):
    """The most bytes the file system of ``folder`` grew by while the block ran (polled),
    as ``peak[0]``.  Everything else writing to that file system counts too: give a folder
    on one that only the watched program writes to (:func:`grader_tmp`)."""
    base, peak, stop = shutil.disk_usage(folder).used, [0], threading.Event()

    def watch() -> None:
        while not stop.wait(0.1):
            peak[0] = max(peak[0], shutil.disk_usage(folder).used - base)

    watcher = threading.Thread(target=watch, daemon=True)
    watcher.start()
    try:
        yield peak
    finally:
        stop.set()
        watcher.join()


@contextlib.contextmanager
def grader_tmp():
    """A TMPDIR for the grader, on a file system the rest of make test leaves alone.

    The grader's own copies go to TMPDIR (the learners' capped folders are tmpfs mounts of
    their own there, not counted).  The host's disk is shared with everything else make test
    runs (the image's build beside the class writes gigabytes to it while the class is graded),
    so its growth says nothing about the grader.  /dev/shm is a tmpfs that only ROS's shared
    memory segments (a few MB) use besides; the growth is measured there, in the grader's folder.
    """
    shm = Path('/dev/shm')
    folder = owned_folder('ros2nb-test-grader-tmp-', shm if shm.is_dir() else None)
    folder.chmod(0o1777)  # as /tmp: the sandboxes' own user passes through to its folders
    try:
        yield folder
    finally:
        shutil.rmtree(folder, ignore_errors=True)


@dataclass(frozen=True)
class Graded:
    """The sample class graded once, and what the grading could have touched."""

    out: Path  #: the grading/ folder ros2nb-grade wrote
    done: subprocess.CompletedProcess  #: ros2nb-grade's exit code and output
    repository: dict[str, str]  #: the repository's fingerprint before grading
    decoy_bytes: bytes  #: a gradebook outside the grading folder, before grading
    decoy: Path  #: that gradebook
    home_file: Path  #: a file a hostile learner tries to write into the real home
    forged: Path  #: a file a process left behind would write after grading
    left: list[str]  #: processes of the class still there after grading


@pytest.fixture(scope='module')
def graded(tmp_path_factory) -> Iterator[Graded]:
    root = tmp_path_factory.mktemp('grading')
    out = root / 'grading'
    decoy = root / 'elsewhere' / 'gradebook.db'
    decoy.parent.mkdir()
    decoy.write_bytes(b'SQLite format 3\x00' + b'\x00' * 100)
    home_file = Path.home() / f'ros2nb-{MARK}-{os.getpid()}'
    forged = root / 'forged-after-grading.txt'
    submissions = build(root / 'class', grading_out=out, submissions=root / 'class',
                        decoy_gradebook=decoy, home_file=home_file, forged=forged)
    before = fingerprint(ROOT), decoy.read_bytes()
    started = time.monotonic()
    with grader_tmp() as tmp, disk_watched(tmp) as peak:  # where the grader's copies go
        done = subprocess.run(  # ros2nb-grade, with a fault planted for five learners
            [sys.executable, '-c', GRADE_WITH_FAULTS, str(submissions), '--out', str(out),
             '--jobs', str(CLASS_JOBS)], capture_output=True, text=True, timeout=CLASS_LIMIT_S,
            env=dict(os.environ, TMPDIR=str(tmp)))
    (root / 'disk-peak').write_text(str(peak[0]))
    print(f'graded {len(EXPECTED)} learners in {time.monotonic() - started:.0f} s')
    yield Graded(out, done, *before, decoy, home_file, forged, survivors())
    home_file.unlink(missing_ok=True)


def test_grading_exits_0(graded):
    done = graded.done
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r'\[\d+/\d+ notebooks, \d+/\d+ learners; .* so far, about .* left\]',
                     done.stdout), done.stdout  # progress, with an estimate


def test_the_grader_copies_stay_within_the_caps(graded):
    """A learner whose every notebook fills the 1 GiB workspace: each judge's snapshot of
    it is on a capped tmpfs, freed once judged, never in the grader's TMPDIR on the host
    (kept there until the learner's last notebook was judged, they would add up: 2 GiB here)."""
    out = graded.out
    peak = int((out.parent / 'disk-peak').read_text())
    assert peak < HOME_BYTES // 2, f'the grader\'s TMPDIR grew by {peak >> 20} MiB while grading'


def test_every_score_and_csv_row(graded):
    out = graded.out
    with open(out / 'grades.csv', newline='') as stream:
        rows = list(csv.DictReader(stream))
    assert len(rows) == len(EXPECTED) * (len(NOTEBOOKS) + 1)
    got = {(r['learner'], r['notebook']): float(r['score']) for r in rows}
    maxima = {r['notebook']: float(r['max_score']) for r in rows if r['learner'] == 'complete'}
    for learner, case in EXPECTED.items():
        row = in_the_csv(learner)
        for notebook in NOTEBOOKS:
            assert got[row, notebook] == case.scores.get(notebook, 0), \
                (learner, notebook, failure_lines(out, learner, notebook))
        assert got[row, 'TOTAL'] == sum(case.scores.values()), learner
    assert maxima == {**{n: float(p) for n, p in FULL.items()}, 'TOTAL': float(sum(FULL.values()))}


def failure_lines(out: Path, learner: str, notebook: str) -> list[str]:
    """The verdicts of failed cells on a learner's feedback page (what a wrong score is about)."""
    page = out / 'feedback' / learner / f'{notebook}.html'
    if not page.is_file():
        return ['no feedback page']
    return re.findall(r'\b\w*(?:Failed|Error|Hung): .{0,300}', shown(page))


def as_text(learner: str) -> str:
    """A folder name as the notes and pages say it: its bytes that are not UTF-8 as \\xNN."""
    return os.fsencode(learner).decode('utf-8', 'backslashreplace')


def in_the_csv(learner: str) -> str:
    """The learner column's value for a folder name: :func:`as_text`, and a ' before what a
    spreadsheet would read as a formula."""
    name = as_text(learner)
    return f"'{name}" if name.startswith(('=', '+', '-', '@', '\t', '\r')) else name


def test_a_fault_in_any_host_stage_is_one_learners_note(graded):
    """A fault planted in each host-side stage (reading the file, running it, judging it,
    filing it for nbgrader, its feedback page), one learner each, beside the class: grading
    ends with exit 0 and every other score stands (test_every_score_and_csv_row); each of
    them gets a note naming the fault (test_feedback_and_notes_say_what_happened), and a
    page that could not be made keeps its score."""
    out, done = graded.out, graded.done
    assert done.returncode == 0, done.stdout + done.stderr
    notes = json.loads((out / 'notes.json').read_text())['learners']
    for learner in ('plant-read', *(f'x-{stage}' for stage in STAGES[1:])):
        assert 'a fault planted in' in notes[learner][NB01], (learner, notes[learner])
    assert 'could not be written' in notes['x-feedback'][NB01]


def test_names_are_data(graded):
    """A folder name that is not UTF-8 and one that is a formula: graded, and written as
    plain text (the CSV cell a value, never a formula)."""
    out = graded.out
    text = (out / 'grades.csv').read_text(encoding='utf-8')
    assert 'Zo\\xeb-cp1252,' in text
    assert '\n"\'=HYPERLINK(""example.invalid"",""open me"")",' in text
    assert not any(line.startswith(('=', '"=')) for line in text.splitlines())
    assert (out / 'feedback' / NOT_UTF8 / f'{NB01}.html').is_file()


def shown(page: Path) -> str:
    """A feedback page's text as a browser displays it."""
    return ' '.join(html.unescape(re.sub(r'<[^>]+>', ' ', page.read_text())).split())


@pytest.mark.parametrize('learner', sorted(EXPECTED))
def test_feedback_and_notes_say_what_happened(graded, learner):
    out = graded.out
    case = EXPECTED[learner]
    notes = json.loads((out / 'notes.json').read_text())['learners'][as_text(learner)]
    for notebook in NOTEBOOKS:
        page = out / 'feedback' / learner / f'{notebook}.html'
        assert page.is_file(), page
        if notebook not in case.scores:
            assert 'Not submitted' in page.read_text()
        assert page.stat().st_size < 3_000_000  # 50 MB printed, a few hundred kB shown
    for notebook, phrase in case.feedback.items():
        assert phrase in shown(out / 'feedback' / learner / f'{notebook}.html'), (learner, phrase)
    for notebook, phrase in case.notes.items():
        if phrase:
            assert phrase in notes.get(notebook, ''), (learner, notes)
        else:  # an honest run has nothing to note
            assert notebook not in notes, (learner, notes)
    if learner == 'kills-its-kernel':
        assert 'longer than' not in notes[NB01]  # a dead kernel is not a slow one


@pytest.mark.parametrize('learner', ['complete', 'untouched', 'solved-only-04'])
def test_every_feedback_page_is_headed_by_the_learners_table_from_the_graders_results(
        graded, learner):
    """The table of the learner's progress (issue 69), first on every page of theirs: each
    notebook's points as the grader scored them, and the notebooks not handed in as such."""
    case = EXPECTED[learner]
    for page in NOTEBOOKS:
        path = graded.out / 'feedback' / learner / f'{page}.html'
        assert re.search(r'<body[^>]*><div class="container above"><div id="standing" '
                         r'class="standing"><table ', path.read_text()), (learner, page)
        text = shown(path)
        assert (f'Every notebook, as the grader found it: {sum(case.scores.values()):g} of '
                f'{sum(FULL.values()):g} points passed') in text, (learner, page)
        for notebook in NOTEBOOKS:
            row = re.search(rf'{notebook} (\S+) of (\S+) (.*?)(?= \d\d-|$)', text)
            assert row is not None, (notebook, text[:2000])
            assert row.group(1, 2) == (f'{case.scores.get(notebook, 0):g}', f'{FULL[notebook]:g}')
            assert (' not handed in' in row.group(3)) == (notebook not in case.scores), row.group(0)


def test_learners_content_is_text_in_the_feedback(graded):
    out = graded.out
    for page in (out / 'feedback').rglob('*.html'):
        text = page.read_text()
        assert not re.search(r'<script[^>]*>[^<]*pwned', text), page  # no learner script runs
        assert not re.search(r'<img[^>]*onerror', text, re.IGNORECASE), page
    text = (out / 'feedback' / 'script-in-feedback' / f'{NB01}.html').read_text()
    assert '&lt;script&gt;alert("pwned-markdown")&lt;/script&gt;' in text  # shown as text


def test_nothing_escaped(graded):
    out = graded.out
    assert graded.left == [], f'processes of the class outlived grading: {graded.left}'
    assert not graded.forged.exists()
    assert fingerprint(ROOT) == graded.repository  # the course, byte for byte, ignored too
    assert graded.decoy.read_bytes() == graded.decoy_bytes
    assert not graded.home_file.exists()
    with open(out / 'grades.csv') as stream:
        assert 'forged' not in stream.read()


def test_the_gradebook_holds_only_what_nbgrader_scored(graded):
    """A notebook cannot forge manual scores: none are set, and nbgrader's export agrees."""
    out = graded.out
    course = out / 'nbgrader'
    export = out / 'export.csv'
    done = subprocess.run([sys.executable, '-m', 'nbgrader', 'export',
                           f'--CourseDirectory.root={course}',
                           f'--CourseDirectory.db_url=sqlite:///{course / "gradebook.db"}',
                           f'--to={export}'], cwd=course, capture_output=True, text=True,
                          env={**os.environ, 'PATH': f'{Path(sys.executable).parent}:'
                                                     f'{os.environ["PATH"]}'})
    assert done.returncode == 0, done.stderr
    rows = list(csv.DictReader(open(export)))
    totals = {r['student_id']: float(r['score']) for r in rows}
    assert totals['complete'] == sum(FULL.values()) and totals['forges-the-gradebook'] == 0.0
    import sqlite3
    with sqlite3.connect(course / 'gradebook.db') as db:
        assert db.execute('SELECT COUNT(*) FROM grade WHERE manual_score IS NOT NULL'
                          ).fetchone()[0] == 0


def test_links_are_never_followed(graded):
    """Links in the submissions folder are named, never graded as their targets."""
    out, done = graded.out, graded.done
    notes = json.loads((out / 'notes.json').read_text())
    assert any(line.startswith('"links-to-the-solutions": a link') for line in notes['not graded'])
    assert '"links-to-the-solutions": a link' in done.stdout
    assert (f'{NB01}.ipynb is a link (links are not followed'
            in notes['learners']['links-to-classmates']['_folder'])


def test_feedback_pages_forbid_scripts_and_show_learners_html_as_text(graded):
    """Every page carries the CSP; the raw cell's fake score box is text, not a box."""
    out = graded.out
    for page in (out / 'feedback').rglob('*.html'):
        text = page.read_text()
        assert "Content-Security-Policy\" content=\"default-src 'none'" in text, page
        assert not re.search(r'<script|<[^>]*(?:javascript:|onerror=|src="http|href="data:)[^>]*>',
                             text, re.I), page  # learners' HTML is in the page as text only
    text = (out / 'feedback' / 'feedback-attacks' / f'{NB01}.html').read_text()
    assert 'panel-heading">\nScore: 1.0 / 1.0 (drawn by me)' not in text  # no box of its own
    assert '&lt;div class="panel panel-default"&gt;' in text
    pasted = (out / 'feedback' / 'pasted-image' / f'{NB01}.html').read_text()
    assert re.search(r'<img [^>]*src="data:image/png;base64,', pasted)  # the pasted image shows


def _opened(page, path: Path) -> tuple[str, object, list[str]]:
    """Open ``path`` in the browser: its title, the learner's window flag, requests that left."""
    left = []
    page.on('request', lambda request: left.append(request.url)
            if not request.url.startswith(('file://', 'data:')) else None)
    page.goto(path.as_uri())
    page.wait_for_load_state('load')
    return page.title(), page.evaluate('window.pwned'), left


def test_no_learner_script_runs_in_a_browser(graded, page, tmp_path):
    """Every feedback page of a notebook the class handed in, in chromium: no script ran,
    nothing loaded (a page of a notebook not handed in holds nothing of the learner's).

    A planted page (the same payloads, unsanitised) shows the check sees a script that runs.
    """
    out = graded.out
    planted = tmp_path / 'planted.html'
    planted.write_text(f'<html><head><title>planted</title></head><body><img src="x" '
                       f"onerror=\"document.title='{PWNED}';window.pwned=1\"></body></html>")
    title, flag, _ = _opened(page, planted)
    assert title == PWNED and flag == 1  # the hole, planted: the check sees it
    opened = 0
    for learner, case in EXPECTED.items():
        for notebook in case.scores:
            title, flag, left = _opened(page, out / 'feedback' / learner / f'{notebook}.html')
            assert (title, flag, left) == (notebook, None, []), (learner, notebook)
            opened += 1
    assert opened >= len(EXPECTED)


def test_the_class_report_in_a_browser(graded, page, tmp_path):
    """grading/report.html in chromium: it loads nothing, runs nothing, draws the plot of
    scores, and its tables hold every learner and the checks' counts the grades imply."""
    out = graded.out
    title, flag, left = _opened(page, out / 'report.html')
    assert (title, flag, left) == ('The class at a glance', None, [])
    assert page.evaluate("document.getElementById('spread').naturalWidth") > 300  # drawn
    assert page.locator('#learners tr').count() == len(EXPECTED) + 1  # and its header
    passed_01 = sum(1 for case in EXPECTED.values() if case.scores.get(NB01) == FULL[NB01])
    row = page.locator('#checks tr', has_text=f'{NB01[:2]}-').first.inner_text().split('\t')
    assert int(row[2]) == passed_01, row
    assert page.locator('#failures tr').count() > 1  # the class has failures to show
    page.screenshot(path=str(tmp_path / 'report.png'), full_page=True)
