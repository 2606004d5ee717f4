"""A term: due dates and late policies (course.toml), hand-in times, LMS exports, one learner again.

The pure parts first (the settings' one-line mistakes, each policy's arithmetic, the times a
submission says, Canvas's and Moodle's columns read back with csv); then a class of four (on
time, a day late, past the cutoff, no hand-in time) graded for real under two policies, exported
for Canvas and Moodle, and one learner graded again under the second policy.
"""

from __future__ import annotations

import csv
import datetime
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from ros2nb.typed_json import Unreadable
from ros2nb_instructor.grading.export import exporting, lms
from ros2nb_instructor.grading.intake import course_settings, deadlines, due_dates, roster, term
from ros2nb_instructor.grading.reports import feedback
from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.intake.extensions import Extensions
from ros2nb_instructor.grading.intake.hand_in_times import TIMESTAMP, ZIP_ENTRY, parse_time
from ros2nb_instructor.grading.intake.submissions import Learner, find_learners
from ros2nb_instructor.grading.intake.zips import screen_zip

NB01 = '01-create-a-workspace'
NOTEBOOKS = ['00-setup-and-the-pubsub-idea', NB01]
DUE = datetime.datetime(2026, 10, 5, 23, 59, tzinfo=datetime.timezone.utc)
#: Two policies: 10 % a day begun (at most 50 %), a 15 min grace, 0 after 3 days, a missing
#: time graded as on time; and 5 % an hour begun (at most 30 %), no cutoff, a missing time 0.
DAILY = f'''[late]
penalty = "per-day"
percent = 10
cap_percent = 50
grace_minutes = 15
cutoff_hours = 72
[notebooks.{NB01}]
due = 2026-10-05T23:59:00Z
'''
HOURLY = f'''[late]
penalty = "per-hour"
percent = 5
cap_percent = 30
without_time = "zero"
[notebooks.{NB01}]
due = 2026-10-06T01:59:00+02:00
'''
#: The class: learner -> when their timestamp.txt says they handed in (None: no file).
HANDED_IN = {'on-time': '2026-10-05 23:50:00 UTC', 'a-day-late': '2026-10-06 23:59:00 UTC',
             'past-cutoff': '2026-10-10 12:00:00 UTC', 'no-time': None}
#: learner -> (raw, penalty, score) of notebook 01 (the solution: 1 point) under each policy.
EXPECTED = {'daily': {'on-time': (1, 0, 1), 'a-day-late': (1, 0.1, 0.9),
                      'past-cutoff': (1, 1, 0), 'no-time': (1, 0, 1)},
            'hourly': {'on-time': (1, 0, 1), 'a-day-late': (1, 0.3, 0.7),
                       'past-cutoff': (1, 0.3, 0.7), 'no-time': (1, 1, 0)}}


def settings(tmp_path: Path, text: str) -> deadlines.CourseSettings:
    path = tmp_path / 'course.toml'
    path.write_text(text)
    return course_settings.read_settings(path, NOTEBOOKS)


@pytest.mark.parametrize('text, said', [
    (f'[notebooks.{NB01}]\ndue = 2026-10-05T23:59:00\n',
     'has no time zone: write it with its offset, such as due = 2026-10-05T23:59:00+02:00'),
    ('[late]\npenalty = "per-day"\npercent = -10\n',
     'percent = -10 is negative: write percent = a number from 0 to 100'),
    ('[notebooks.03-write-the-publisher]\ndue = 2026-10-05T23:59:00Z\n',
     "no notebook '03-write-the-publisher' in the course: write one of its names"),
    ('[late]\npenalty = "weekly"\n', 'write penalty = one of "none", "per-day", "per-hour"'),
])
def test_a_mistake_in_the_settings_is_one_line_saying_what_to_write(tmp_path, text, said):
    with pytest.raises(deadlines.SettingsProblem) as problem:
        settings(tmp_path, text)
    assert len(problem.value.lines) == 1 and said in problem.value.lines[0], problem.value.lines


def test_three_mistakes_are_three_lines(tmp_path):
    with pytest.raises(deadlines.SettingsProblem) as problem:
        settings(tmp_path, '[late]\ncap_percent = -1\n[notebooks.99-x]\n'
                           'due = 2026-01-01T00:00:00Z\n'
                           f'[notebooks.{NB01}]\ndue = 2026-10-05T23:59:00\n')
    assert len(problem.value.lines) == 3, problem.value.lines


@pytest.mark.parametrize('policy', ['daily', 'hourly'])
def test_each_policy_costs_what_it_says(tmp_path, policy):
    course = settings(tmp_path, DAILY if policy == 'daily' else HOURLY)
    for learner, stamp in HANDED_IN.items():
        when = (deadlines_time(stamp), TIMESTAMP) if stamp else None
        late = deadlines.assess(course, NB01, 1.0, when)
        assert (late.raw, late.penalty, late.final) == pytest.approx(EXPECTED[policy][learner]), \
            (learner, late)
        assert bool(late.note) == (EXPECTED[policy][learner][1] > 0 or stamp is None), late


def test_the_feedback_box_shows_both_times_in_the_due_dates_zone(tmp_path):
    """Due at 01:59 in +02:00, handed in 23:59 UTC the next day: the box says 01:59+02:00 for
    both, a day apart, and is red (lateness cost points)."""
    late = deadlines.assess(settings(tmp_path, HOURLY), NB01, 1.0,
                            (deadlines_time(HANDED_IN['a-day-late']), TIMESTAMP))
    box = feedback.late_html(late)
    assert '<th>due</th><td>2026-10-06 01:59:00+02:00</td>' in box, box
    assert '<th>handed in</th><td>2026-10-07 01:59:00+02:00 (timestamp.txt)</td>' in box, box
    assert 'panel-danger' in box and '<th>score</th><td>0.7</td>' in box, box


def deadlines_time(stamp: str) -> datetime.datetime:
    return parse_time(stamp, TIMESTAMP)


def test_no_settings_file_means_nothing_is_due(tmp_path):
    course = course_settings.read_settings(tmp_path / 'none.toml', NOTEBOOKS)
    late = deadlines.assess(course, NB01, 1.0, None)
    assert (late.penalty, late.note, late.due) == (0.0, '', None)


def test_the_hand_in_time_comes_from_the_submission(tmp_path):
    """nbgrader's timestamp.txt in a folder; in a platform zip, a timestamp.txt wins over the
    entries' own times (a zone-less one taken in the settings' zone; a UTC one as it is)."""
    (tmp_path / 'class' / 'ada').mkdir(parents=True)
    (tmp_path / 'class' / 'ada' / f'{NB01}.ipynb').write_text('{}')
    (tmp_path / 'class' / 'ada' / TIMESTAMP).write_text('2026-10-06 10:00:00.5 UTC\n')
    (learner,), _ = find_learners(tmp_path / 'class', NOTEBOOKS)
    assert learner.handed_in[NB01] == (datetime.datetime(2026, 10, 6, 10, 0, 0, 500000,
                                                         tzinfo=datetime.timezone.utc), TIMESTAMP)
    assert '_folder' not in learner.notes  # timestamp.txt is no stray file
    archive = tmp_path / 'class.zip'
    with zipfile.ZipFile(archive, 'w') as made:
        made.writestr(zipfile.ZipInfo(f'bo/{NB01}.ipynb', (2026, 10, 6, 9, 30, 0)), '{}')
        made.writestr(zipfile.ZipInfo(f'cy/{NB01}.ipynb', (2026, 10, 6, 9, 30, 0)), '{}')
        made.writestr('cy/timestamp.txt', '2026-10-05 20:00:00 UTC')
    times: dict = {}
    berlin = due_dates.zone('Europe/Berlin', '', [])
    screen_zip(archive, tmp_path / 'clean.zip', times, berlin)
    assert times['bo', f'{NB01}.ipynb'] == (datetime.datetime(2026, 10, 6, 9, 30, tzinfo=berlin),
                                            ZIP_ENTRY)
    assert times['cy', f'{NB01}.ipynb'][1] == TIMESTAMP


def test_learners_json_keeps_a_folder_name_that_is_not_utf8(tmp_path):
    """A Windows zip's folder name in cp1252 (not UTF-8) comes back exactly as it was, so
    LEARNER= finds its folder again (written as UTF-8 text, it stopped the class's grading)."""
    name = os.fsdecode(b'Zo\xeb-cp1252')
    learner = Learner(name, 'learner-001', {NB01: tmp_path / name / f'{NB01}.ipynb'})
    learner.handed_in[NB01] = (DUE, TIMESTAMP)
    term.save_state(tmp_path, [learner])
    (back,) = term.load_state(tmp_path)
    assert (back.name, back.files, back.handed_in) == (name, learner.files, learner.handed_in)


def test_learners_json_of_the_wrong_shape_names_the_learner_and_the_field(tmp_path):
    """learners.json is read as its type (LearnerState), every field checked: a hand-in time
    written as a number, not ISO 8601 text, is refused with the learner and the field named.
    Read by key, it stopped LEARNER= with fromisoformat's TypeError, naming neither."""
    learner = Learner('ada', 'ada', {NB01: tmp_path / 'ada' / f'{NB01}.ipynb'})
    learner.handed_in[NB01] = (DUE, TIMESTAMP)
    term.save_state(tmp_path, [learner])
    kept = json.loads((tmp_path / term.STATE).read_text())
    kept['ada']['handed_in'][NB01][0] = int(DUE.timestamp())
    (tmp_path / term.STATE).write_text(json.dumps(kept))
    with pytest.raises(Unreadable) as refused:
        term.load_state(tmp_path)
    assert str(refused.value) == (f"{tmp_path / term.STATE}, learner ada: "
                                  f"LearnerState.handed_in['{NB01}'][] is int, not str")


ROSTER = ('learner,name,lms_id,sis_id,login,email,section\n'
          'on-time,Ada Lovelace,101,S-1,ada,ada@example.org,A\n'
          'a-day-late,Bo Diddley,102,S-2,bo,bo@example.org,A\n'
          'absent,Cy Young,103,S-3,cy,cy@example.org,B\n')


def read_back(path: Path) -> list[list[str]]:
    with open(path, newline='', encoding='utf-8') as stream:
        return list(csv.reader(stream))


def a_table() -> lms.Table:
    """Three learners' marks; a-day-late has no mark of 00 yet (not due for them)."""
    return lms.Table(tuple(NOTEBOOKS), {NOTEBOOKS[0]: 1.0, NB01: 1.0}, {
        'on-time': {NOTEBOOKS[0]: lms.Mark(1.0, '1 of 1 points'), NB01: lms.Mark(1.0)},
        'a-day-late': {NOTEBOOKS[0]: lms.Mark(None, 'not due yet'),
                       NB01: lms.Mark(0.9, '0.9 of 1 points; handed in 1 day late')},
        '=HYPERLINK("http://x")': {NOTEBOOKS[0]: lms.Mark(0.0), NB01: lms.Mark(1.0)}})


def test_canvas_columns(tmp_path):
    """Student, ID, SIS User ID, SIS Login ID, Section, one column per notebook, as Canvas's
    importer reads them (canvas-lms lib/gradebook_importer.rb); the second row Points
    Possible; blank, never 0, where a learner has no mark yet; a roster learner without
    marks blank too; the one not in the roster listed apart, its name made inert."""
    (tmp_path / 'roster.csv').write_text(ROSTER)
    rows_of = roster.read_roster(tmp_path / 'roster.csv', 'canvas')
    said = lms.write('canvas', a_table(), rows_of, tmp_path / 'canvas.csv')
    rows = read_back(tmp_path / 'canvas.csv')
    assert rows[0] == ['Student', 'ID', 'SIS User ID', 'SIS Login ID', 'Section', *NOTEBOOKS]
    assert rows[1] == ['Points Possible', '', '', '', '', '1', '1']
    assert rows[2:] == [['Lovelace, Ada', '101', 'S-1', 'ada', 'A', '1', '1'],
                        ['Diddley, Bo', '102', 'S-2', 'bo', 'A', '', '0.9'],
                        ['Young, Cy', '103', 'S-3', 'cy', 'B', '', '']]
    assert said == [f'=HYPERLINK("http://x"): graded, not in the roster: written to '
                    f'{tmp_path / "not-in-roster.csv"}']
    assert read_back(tmp_path / 'not-in-roster.csv') == [
        ['learner', *NOTEBOOKS, 'total'], ['\'=HYPERLINK("http://x")', '0', '1', '1']]


def test_not_in_roster_csv_goes_once_the_roster_has_everyone(tmp_path):
    """Before, an export with a fuller roster left the earlier not-in-roster.csv, naming
    learners the new export had matched."""
    (tmp_path / 'roster.csv').write_text(ROSTER)
    rows_of = roster.read_roster(tmp_path / 'roster.csv', 'canvas')
    lms.write('canvas', a_table(), rows_of, tmp_path / 'canvas.csv')
    assert (tmp_path / 'not-in-roster.csv').exists()
    everyone = {**rows_of, '=HYPERLINK("http://x")': roster.RosterRow('=HYPERLINK("http://x")',
                                                                       lms_id='104')}
    assert lms.write('canvas', a_table(), everyone, tmp_path / 'canvas.csv') == []
    assert sorted(p.name for p in tmp_path.iterdir()) == ['canvas.csv', 'roster.csv']


def test_moodle_and_plain_columns(tmp_path):
    """Moodle: the user's columns, then each notebook and its "Feedback for" column (as
    Moodle's own export names it); a CSV cannot carry an item's maximum, so one line says
    which grade items the import needs."""
    (tmp_path / 'roster.csv').write_text(ROSTER)
    rows_of = roster.read_roster(tmp_path / 'roster.csv', 'moodle')
    lms.write('moodle', a_table(), rows_of, tmp_path / 'moodle.csv')
    rows = read_back(tmp_path / 'moodle.csv')
    assert rows[0] == ['First name', 'Last name', 'ID number', 'Username', 'Email address',
                       NOTEBOOKS[0], f'Feedback for {NOTEBOOKS[0]}', NB01, f'Feedback for {NB01}']
    assert rows[1:] == [
        ['Ada', 'Lovelace', 'S-1', 'ada', 'ada@example.org', '1', '1 of 1 points', '1', ''],
        ['Bo', 'Diddley', 'S-2', 'bo', 'bo@example.org', '', 'not due yet', '0.9',
         '0.9 of 1 points; handed in 1 day late'],
        ['Cy', 'Young', 'S-3', 'cy', 'cy@example.org', '', '', '', '']]
    assert lms.moodle_items(a_table()).startswith(
        "Moodle: map each notebook's column to a grade item whose maximum grade is its points "
        f'({NOTEBOOKS[0]} 1, {NB01} 1)')
    lms.write('csv', a_table(), None, tmp_path / 'plain.csv')
    assert read_back(tmp_path / 'plain.csv') == [
        ['learner', *NOTEBOOKS, 'total'], ['on-time', '1', '1', '2'],
        ['a-day-late', '', '0.9', '0.9'], ['\'=HYPERLINK("http://x")', '0', '1', '1']]


def test_a_mark_is_blank_until_due_and_0_after(tmp_path):
    """Not handed in: blank while the notebook is not due for the learner (their extension
    included), 0 once it is; handed in: the score after lateness."""
    course = settings(tmp_path, DAILY)
    granted = Extensions({('bo', NB01): DUE + datetime.timedelta(days=2)})
    ada, bo = Learner('ada', 'ada'), Learner('bo', 'bo')
    day_after = DUE + datetime.timedelta(days=1)
    assert exporting.mark(ada, NB01, None, 1.0, course, granted, day_after) == \
        lms.Mark(0.0, 'not handed in: 0 of 1 points')
    assert exporting.mark(bo, NB01, None, 1.0, course, granted, day_after).score is None
    assert exporting.mark(bo, NB01, None, 1.0, course, granted,
                          DUE + datetime.timedelta(days=3)).score == 0.0
    bo.files[NB01] = Path('x.ipynb')
    bo.handed_in[NB01] = (day_after, TIMESTAMP)
    handed = exporting.mark(bo, NB01, 1.0, 1.0, course, granted, day_after)
    assert handed.score == 1.0 and 'extension to 2026-10-07 23:59:00+00:00' in handed.feedback
    assert exporting.notebooks_due_by(course, NOTEBOOKS, DUE - datetime.timedelta(days=1)) == (
        [], ['left out (not due by 2026-10-04T23:59:00+00:00): 00, 01'])


def test_make_export_refuses_in_one_line_and_writes_nothing(tmp_path):
    export = str(Path(sys.executable).with_name('ros2nb-export'))
    for args, said in ((['--due-by', '2026-10-20'], "DUE_BY: '2026-10-20' is not a time with its "
                                                    'offset: write ISO 8601'),
                       ([], 'holds no grading to export: run make grade first')):
        done = subprocess.run([export, 'csv', '--grading', str(tmp_path / 'grading'), *args],
                              capture_output=True, text=True, timeout=600)
        assert done.returncode == 2 and done.stdout.count('\n') == 1, done.stdout
        assert said in done.stdout, done.stdout
    assert list(tmp_path.iterdir()) == []


def test_each_roster_mistake_is_one_line(tmp_path):
    (tmp_path / 'roster.csv').write_text('learner,login\nada,\nbo,b\nbo,b2\n')
    with pytest.raises(roster.RosterProblem) as problem:
        roster.read_roster(tmp_path / 'roster.csv', 'canvas')
    lines = problem.value.lines
    assert len(lines) == 2, lines
    assert 'line 2: ada has none of the ids canvas matches by: write one of' in lines[0]
    assert 'line 4: bo is in the roster twice' in lines[1]


GRADE = str(Path(sys.executable).with_name('ros2nb-grade'))
SOLUTION = Path(__file__).resolve().parent.parent / 'solutions' / f'{NB01}.ipynb'


def grade(*args: object) -> subprocess.CompletedProcess:
    return subprocess.run([GRADE, *map(str, args)], capture_output=True, text=True, timeout=1800)


def csv_rows(out: Path) -> dict[str, dict[str, str]]:
    with open(out / 'grades.csv', newline='') as stream:
        return {r['learner']: r for r in csv.DictReader(stream) if r['notebook'] == NB01}


@pytest.mark.sandbox
@pytest.mark.judge
@pytest.mark.kernel
@pytest.mark.timeout(1800)
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
def test_a_class_under_two_policies_exported_and_one_learner_again(tmp_path):
    """On time, a day late, past the cutoff, no time: grades.csv, the feedback pages and
    report.html show raw score, penalty and score as each policy says; Canvas's and Moodle's
    exports hold them; one learner graded again under the other policy changes alone."""
    for learner, stamp in HANDED_IN.items():
        (tmp_path / 'class' / learner).mkdir(parents=True)
        (tmp_path / 'class' / learner / f'{NB01}.ipynb').write_bytes(SOLUTION.read_bytes())
        if stamp:
            (tmp_path / 'class' / learner / TIMESTAMP).write_text(stamp)
    (tmp_path / 'roster.csv').write_text(ROSTER)
    (tmp_path / 'daily.toml').write_text(DAILY)
    (tmp_path / 'hourly.toml').write_text(HOURLY)
    for policy, lms_name in (('daily', 'canvas'), ('hourly', 'moodle')):
        out = tmp_path / policy
        done = grade(tmp_path / 'class', '--out', out, '--settings', tmp_path / f'{policy}.toml',
                     '--export', lms_name, '--roster', tmp_path / 'roster.csv', '--seed', 7)
        assert done.returncode == 0, done.stdout + done.stderr
        # The lines name the files where the grading ends up, not the folder it is made in.
        assert f'export: wrote {out / "export" / f"{lms_name}.csv"}\n' in done.stdout, done.stdout
        rows = csv_rows(out)
        for learner, (raw, penalty, score) in EXPECTED[policy].items():
            row = rows[learner]
            assert (float(row['raw_score']), float(row['late_penalty']), float(row['score'])) \
                == pytest.approx((raw, penalty, score)), (policy, row)
            page = (out / 'feedback' / learner / f'{NB01}.html').read_text()
            assert 'id="late"' in page and f'<th>score</th><td>{score:g}</td>' in page, learner
        assert rows['absent']['score'] == '0'  # in the roster, no folder
        report = (out / 'report.html').read_text()
        assert 'id="late-work"' in report
        assert ('past the cutoff' in report) == (policy == 'daily')
        exported = read_back(out / 'export' / f'{lms_name}.csv')
        column = exported[0].index(NB01)
        by_id = {row[2]: row[column] for row in exported[1:]}  # SIS User ID / ID number
        assert by_id['S-1'] == f'{EXPECTED[policy]["on-time"][2]:g}'
        assert by_id['S-2'] == f'{EXPECTED[policy]["a-day-late"][2]:g}'
        assert by_id['S-3'] == '0'
        extra = {row[0] for row in read_back(out / 'export' / 'not-in-roster.csv')[1:]}
        assert extra == {'past-cutoff', 'no-time'}, extra  # listed, never dropped
        notes = json.loads((out / 'notes.json').read_text())['learners']
        assert notes['absent']['_folder'] == 'in the roster, nothing handed in: 0 points'
    again = grade(tmp_path / 'class', '--out', tmp_path / 'daily', '--settings',
                  tmp_path / 'hourly.toml', '--learner', 'a-day-late', '--seed', 7)
    assert again.returncode == 0, again.stdout + again.stderr
    rows = csv_rows(tmp_path / 'daily')
    assert float(rows['a-day-late']['late_penalty']) == pytest.approx(0.3)  # hourly now
    # The others are not graded again; the settings as they are now apply to the whole class.
    assert float(rows['past-cutoff']['score']) == pytest.approx(0.7)
    assert 'a-day-late graded' in again.stdout and 'on-time graded' not in again.stdout
    extended_then_exported(tmp_path, tmp_path / 'daily')


#: Past the cutoff, and given five more days (to Oct 10) after grading; absent, given a week.
EXTENDED = f'[past-cutoff]\n{NB01} = {{ days = 5 }}\n[absent]\n"01" = {{ days = 7 }}\n'


def extended_then_exported(tmp_path: Path, out: Path) -> None:
    """After grading: the formgrader's manual points for on-time, an extension for
    past-cutoff applied by grading that learner alone, then ``make export`` for Canvas from
    the gradebook as it is, nothing graded again: the manual points, the extension, and a
    blank (never 0) for absent, whose extended due date is after DUE_BY."""
    from nbgrader.api import Gradebook
    from ros2nb_instructor.paths import ASSIGNMENT, gradebook_url
    with Gradebook(gradebook_url(out / 'nbgrader')) as gradebook:
        graded = gradebook.find_grade('01-create-a-workspace-challenge-1-check', NB01,
                                      ASSIGNMENT, 'on-time')
        graded.manual_score = 0.5
        gradebook.db.commit()
    (tmp_path / 'extensions.toml').write_text(EXTENDED)
    again = grade(tmp_path / 'class', '--out', out, '--settings', tmp_path / 'daily.toml',
                  '--extensions', tmp_path / 'extensions.toml', '--roster', tmp_path / 'roster.csv',
                  '--learner', 'past-cutoff', '--seed', 7)
    assert again.returncode == 0, again.stdout + again.stderr
    assert float(csv_rows(out)['past-cutoff']['score']) == 1.0
    page = (out / 'feedback' / 'past-cutoff' / f'{NB01}.html').read_text()
    assert '<th>extension</th><td>to 2026-10-10 23:59:00+00:00' in page, page
    assert 'to 2026-10-10 23:59:00+00:00' in (out / 'report.html').read_text()
    export = Path(sys.executable).with_name('ros2nb-export')
    done = subprocess.run(
        [str(export), 'canvas', '--grading', str(out), '--roster', str(tmp_path / 'roster.csv'),
         '--settings', str(tmp_path / 'daily.toml'), '--extensions',
         str(tmp_path / 'extensions.toml'), '--due-by', '2026-10-10T00:00:00Z'],
        capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stdout + done.stderr
    assert 'left out (not due by 2026-10-10T00:00:00+00:00): 00, 02, 03' in done.stdout
    exported = read_back(out / 'export' / 'canvas.csv')
    assert exported[0][5:] == [NB01] and exported[1][5:] == ['1']  # one assignment, its points
    by_id = {row[2]: row[5] for row in exported[2:]}
    assert by_id == {'S-1': '0.5', 'S-2': '0.9', 'S-3': ''}, exported  # manual; daily; not due
    assert 'graded' not in done.stdout.replace('graded, not in the roster', '')
    the_other_exports(tmp_path, out, exported)


def the_other_exports(tmp_path: Path, out: Path, canvas: list[list[str]]) -> None:
    """Moodle's and the plain CSV from the same gradebook, and nbgrader's own ``nbgrader
    export`` with the course's plugin writing Canvas's file again, the same (before, it
    wrote only the header rows)."""
    export = Path(sys.executable).with_name('ros2nb-export')
    common = ['--grading', str(out), '--settings', str(tmp_path / 'daily.toml'),
              '--extensions', str(tmp_path / 'extensions.toml'), '--due-by',
              '2026-10-10T00:00:00Z']
    moodle = subprocess.run([str(export), 'moodle', '--roster', str(tmp_path / 'roster.csv'),
                             *common], capture_output=True, text=True, timeout=600)
    assert moodle.returncode == 0, moodle.stdout + moodle.stderr
    assert f"whose maximum grade is its points ({NB01} 1)" in moodle.stdout
    rows = read_back(out / 'export' / 'moodle.csv')
    assert rows[0][5:] == [NB01, f'Feedback for {NB01}']
    assert {row[2]: row[5:] for row in rows[1:]} == {
        'S-1': ['0.5', '0.5 of 1 points'],
        'S-2': ['0.9', '0.9 of 1 points; handed in 1 day after the due date (timestamp.txt): '
                       '0.1 points off'],
        'S-3': ['', 'not due yet (due 2026-10-12 23:59+00:00)']}, rows
    plain = subprocess.run([str(export), 'csv', *common], capture_output=True, text=True,
                           timeout=600)
    assert plain.returncode == 0, plain.stdout + plain.stderr
    totals = {row[0]: row[-1] for row in read_back(out / 'export' / 'csv.csv')[1:]}
    assert totals['on-time'] == '0.5' and totals['past-cutoff'] == '1', totals
    (out / 'export' / 'canvas.csv').unlink()
    course = out / 'nbgrader'
    nbgrader = subprocess.run(
        [str(Path(sys.executable).with_name('nbgrader')), 'export',
         '--exporter=ros2nb_instructor.grading.export.exporting.CanvasExport',
         f'--CanvasExport.roster={tmp_path / "roster.csv"}',
         f'--CanvasExport.settings={tmp_path / "daily.toml"}',
         f'--CanvasExport.extensions={tmp_path / "extensions.toml"}',
         '--CanvasExport.due_by=2026-10-10T00:00:00Z', f'--CourseDirectory.root={course}',
         f'--CourseDirectory.db_url=sqlite:///{course / "gradebook.db"}'],
        cwd=course, capture_output=True, text=True, timeout=600)
    assert nbgrader.returncode == 0, nbgrader.stdout + nbgrader.stderr
    assert read_back(out / 'export' / 'canvas.csv') == canvas
