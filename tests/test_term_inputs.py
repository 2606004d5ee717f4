"""A term's inputs, read strictly: each bad one is one line and changes nothing (issue 77).

Due dates in named zones across a change of summer time; hand-in times as ISO 8601 with an
offset or refused; each notebook's own hand-in time (the guide's staggered example);
extensions; roster rows with the wrong number of fields or ids two learners share; Canvas's
submissions zip taken in through the roster.  All pure: no grading runs here.
"""

from __future__ import annotations

import datetime
import zipfile
import zoneinfo
from pathlib import Path

import pytest

from ros2nb_instructor.grading.intake import course_settings, deadlines, extensions
from ros2nb_instructor.grading.intake.hand_in_times import (HANDED_IN, TIMESTAMP, TimeProblem,
                                                            parse_time, record_text)
from ros2nb_instructor.grading.reports import feedback
from ros2nb_instructor.grading.intake.roster import RosterProblem, read_roster
from ros2nb_instructor.grading.intake.submissions import SubmissionProblem, find_learners
from ros2nb_instructor.grading.intake.zips import screen_zip

NB03, NB05 = '03-write-the-publisher', '05-entry-points-and-run'
NOTEBOOKS = ['00-setup-and-the-pubsub-idea', '01-create-a-workspace', NB03, NB05]
BERLIN = zoneinfo.ZoneInfo('Europe/Berlin')
UTC = datetime.timezone.utc
#: A term like the guide's: 03 due Oct 5, 05 due Oct 26 (the day after summer time ends in
#: Berlin), 10 % a day begun, 0 after a week.
GUIDE = f'''[late]
penalty = "per-day"
percent = 10
cutoff_hours = 168
time_zone = "Europe/Berlin"
[notebooks.{NB03}]
due = 2026-10-05T23:59:00
[notebooks.{NB05}]
due = 2026-10-26T23:59:00
'''


#: The guide's own course.toml (docs/instructors.md), 05 due Oct 19 with no late work.
GUIDE_AS_WRITTEN = f'''[late]
penalty = "per-day"
percent = 10
cap_percent = 50
grace_minutes = 15
cutoff_hours = 168
without_time = "on-time"
time_zone = "Europe/Berlin"
[notebooks.{NB03}]
due = 2026-10-05T23:59:00
[notebooks.{NB05}]
due = 2026-10-19T23:59:00+02:00
cutoff_hours = 0
'''


def settings(tmp_path: Path, text: str) -> deadlines.CourseSettings:
    (tmp_path / 'course.toml').write_text(text)
    return course_settings.read_settings(tmp_path / 'course.toml', NOTEBOOKS)


def one_line(tmp_path: Path, text: str) -> str:
    with pytest.raises(deadlines.SettingsProblem) as problem:
        settings(tmp_path, text)
    assert len(problem.value.lines) == 1, problem.value.lines
    return problem.value.lines[0]


def test_due_dates_in_a_named_zone_take_its_offset_on_their_day(tmp_path):
    """Oct 5 is summer time in Berlin (+02:00), Oct 26 winter time (+01:00): each due date
    is 23:59 there, and a hand-in one minute after each is one minute late."""
    course = settings(tmp_path, GUIDE)
    assert course.due[NB03].utcoffset() == datetime.timedelta(hours=2)
    assert course.due[NB05].utcoffset() == datetime.timedelta(hours=1)
    assert course.due[NB05].astimezone(UTC) == datetime.datetime(2026, 10, 26, 22, 59, tzinfo=UTC)
    for notebook in (NB03, NB05):
        minute_late = (course.due[notebook] + datetime.timedelta(minutes=1), HANDED_IN)
        late = deadlines.assess(course, notebook, 6.0, minute_late)
        assert late.late_s == 60 and late.penalty == pytest.approx(0.6), late
    assert late.shown()[0] == '2026-10-26 23:59:00+01:00 (Europe/Berlin)'


@pytest.mark.parametrize('due, said', [
    ('2026-10-26T23:59:00+02:00', 'has an offset Europe/Berlin did not have then (+01:00): write '
                                  'due = 2026-10-26T22:59:00+01:00'),
    ('2026-10-25T02:30:00', 'happens twice in Europe/Berlin (summer time ends then)'),
    ('2026-03-29T02:30:00', 'does not happen in Europe/Berlin (summer time skips it)'),
])
def test_a_due_date_its_zone_cannot_have_is_one_line(tmp_path, due, said):
    line = one_line(tmp_path, f'[late]\ntime_zone = "Europe/Berlin"\n[notebooks.{NB03}]\n'
                              f'due = {due}\n')
    assert said in line, line


def test_a_zone_that_does_not_exist_is_one_line(tmp_path):
    line = one_line(tmp_path, '[late]\ntime_zone = "Europe/Atlantis"\n')
    assert 'time_zone = \'Europe/Atlantis\' is no time zone: write time_zone = "Europe/Berlin"' \
        in line, line


@pytest.mark.parametrize('text, expected', [
    ('2026-10-05T23:30:00+02:00', datetime.datetime(2026, 10, 5, 21, 30, tzinfo=UTC)),
    ('2026-10-05T21:30:00Z', datetime.datetime(2026, 10, 5, 21, 30, tzinfo=UTC)),
    ('2026-10-05 21:30:00.25 UTC', datetime.datetime(2026, 10, 5, 21, 30, 0, 250000, tzinfo=UTC)),
])
def test_a_hand_in_time_is_iso_8601_with_its_offset(text, expected):
    assert parse_time(text, 'timestamp.txt') == expected


@pytest.mark.parametrize('text', ['2026-10-05 23:30:00 +0200', '2026-10-05 23:30:00 CEST',
                                  '05/10/2026', '2026-10-05T23:30:00', '2026-13-05T23:30:00Z',
                                  '2026-10-05T23:30:00+02:99', '2026-10-05T23:30:00+24:00'])
def test_any_other_hand_in_time_is_refused_with_one_line(text):
    """Before, nbgrader's lenient parser read +0200 as 23:26:40 UTC, CEST as UTC and
    05/10/2026 as May 10: each moved a notebook across its due date without a word."""
    with pytest.raises(TimeProblem) as problem:
        parse_time(text, 'ada/timestamp.txt')
    said = str(problem.value)
    assert '\n' not in said and said.startswith('ada/timestamp.txt: ') and \
        'write ISO 8601, such as 2026-10-05T23:30:00+02:00' in said, said


def a_folder(tmp_path: Path, name: str, **files: str) -> Path:
    folder = tmp_path / 'class' / name
    folder.mkdir(parents=True, exist_ok=True)
    for notebook in (NB03, NB05):
        (folder / f'{notebook}.ipynb').write_text('{}')
    for file, text in files.items():
        (folder / file).write_text(text)
    return folder


def test_a_bad_time_in_a_folder_stops_grading_with_one_line(tmp_path):
    a_folder(tmp_path, 'ada', **{TIMESTAMP: '2026-10-05 23:30:00 CEST'})
    a_folder(tmp_path, 'bo', **{HANDED_IN: f'{{"{NB03}": "yesterday"}}'})
    with pytest.raises(SubmissionProblem) as problem:
        find_learners(tmp_path / 'class', NOTEBOOKS)
    assert len(problem.value.lines) == 2, problem.value.lines
    assert "'yesterday' is not a time with its offset" in problem.value.lines[1]


def test_the_guides_staggered_example_scores_each_notebook_by_its_own_time(tmp_path):
    """03 handed in on Oct 5, 05 on Oct 18, recorded per notebook (the hub's handed-in.json):
    both on time.  With one timestamp.txt (Oct 18) for the folder, 03 was twelve days late,
    past the cutoff: 0 of 6."""
    course = settings(tmp_path, GUIDE_AS_WRITTEN)
    times = {NB03: datetime.datetime(2026, 10, 5, 20, 0, tzinfo=UTC),
             NB05: datetime.datetime(2026, 10, 18, 9, 0, tzinfo=UTC)}
    a_folder(tmp_path, 'ada', **{HANDED_IN: record_text(times)})
    a_folder(tmp_path, 'bo', **{TIMESTAMP: '2026-10-18T11:00:00+02:00'})
    ada, bo = find_learners(tmp_path / 'class', NOTEBOOKS)[0]
    scored = {(lr.name, n): deadlines.assess(course, n, 6.0, lr.handed_in[n])
              for lr in (ada, bo) for n in (NB03, NB05)}
    assert [scored['ada', n].final for n in (NB03, NB05)] == [6.0, 6.0]
    assert scored['ada', NB03].source == HANDED_IN
    assert (scored['bo', NB03].final, scored['bo', NB05].final) == (0.0, 6.0)
    assert 'past the cutoff' in scored['bo', NB03].note


EXTENSIONS = f'''[ada]
{NB03} = 2026-10-08T23:59:00
[bo]
"05" = {{ days = 2 }}
'''


def test_an_extension_moves_one_learners_due_date_and_shows_on_the_feedback_page(tmp_path):
    course = settings(tmp_path, GUIDE)
    (tmp_path / 'extensions.toml').write_text(EXTENSIONS)
    granted = extensions.read_extensions(tmp_path / 'extensions.toml', course, NOTEBOOKS,
                                         ['ada', 'bo', 'cy'])
    assert granted.of('ada', NB03) == datetime.datetime(2026, 10, 8, 23, 59, tzinfo=BERLIN)
    assert granted.of('bo', NB05) == datetime.datetime(2026, 10, 28, 23, 59, tzinfo=BERLIN)
    assert granted.of('ada', NB05) is None and granted.of('cy', NB03) is None
    three_days_late = (course.due[NB03] + datetime.timedelta(days=3), HANDED_IN)
    theirs = deadlines.assess(course, NB03, 6.0, three_days_late, granted.of('ada', NB03))
    class_s = deadlines.assess(course, NB03, 6.0, three_days_late)
    assert (theirs.final, class_s.final) == (6.0, pytest.approx(4.2))
    box = feedback.late_html(theirs)
    assert ('<th>extension</th><td>to 2026-10-08 23:59:00+02:00 (Europe/Berlin) (the class&#39;s: '
            '2026-10-05 23:59:00+02:00 (Europe/Berlin))</td>') in box, box


@pytest.mark.parametrize('text, said', [
    (f'[ada]\n{NB03} = 2026-10-01T23:59:00\n', "is before the class's due date"),
    ('[ada]\n"01" = { days = 2 }\n', '01-create-a-workspace has no due date in course.toml'),
    ('[ada]\n"99" = { days = 2 }\n', "'99' is no notebook of the course"),
    ('[ada]\n"03" = { weeks = 1 }\n', 'write { days = 3 } or { hours = 12 }'),
    ('[adda]\n"03" = { days = 1 }\n', "no learner 'adda' in the submissions or the roster"),
])
def test_each_mistake_in_the_extensions_is_one_line(tmp_path, text, said):
    course = settings(tmp_path, GUIDE)
    (tmp_path / 'extensions.toml').write_text(text)
    with pytest.raises(extensions.ExtensionsProblem) as problem:
        extensions.read_extensions(tmp_path / 'extensions.toml', course, NOTEBOOKS, ['ada'])
    assert len(problem.value.lines) == 1 and said in problem.value.lines[0], problem.value.lines


@pytest.mark.parametrize('roster, said', [
    ('learner,name,sis_id\nada,Lovelace, Ada,S-1\n',
     'line 2: 4 fields where the header has 3: put a value that holds a comma in double quotes'),
    ('learner,sis_id\nada,S-1\nbo,s-1\n', "line 3: sis_id s-1 is also ada's"),
    ('learner,lms_id,login\nada,101,ada\nbo,101,bo\n', "line 3: lms_id 101 is also ada's"),
])
def test_a_roster_row_that_would_shift_or_double_a_learner_is_one_line(tmp_path, roster, said):
    (tmp_path / 'roster.csv').write_text(roster)
    with pytest.raises(RosterProblem) as problem:
        read_roster(tmp_path / 'roster.csv', 'canvas')
    assert len(problem.value.lines) == 1 and said in problem.value.lines[0], problem.value.lines


def test_a_quoted_comma_is_a_value(tmp_path):
    (tmp_path / 'roster.csv').write_text('learner,name,sis_id\nada,"Lovelace, Ada",S-1\n')
    row = read_roster(tmp_path / 'roster.csv', 'canvas')['ada']
    assert (row.name, row.sis_id, row.names()) == ('Lovelace, Ada', 'S-1', ('Ada', 'Lovelace'))


def test_canvas_submissions_zip_is_taken_in_through_the_roster(tmp_path):
    """Canvas names every file <name>[_LATE]_<user id>_<file id>_<file>, flat; the roster's
    lms_id says whose it is.  Its entries are stamped when Canvas made the zip, so none is
    taken as a hand-in time.  Before, the whole zip was refused (no learner folders)."""
    archive = tmp_path / 'submissions.zip'
    with zipfile.ZipFile(archive, 'w') as made:
        made.writestr(f'lovelaceada_101_5001_{NB03}.ipynb', '{}')
        made.writestr(f'diddleybo_LATE_102_5002_{NB03}-1.ipynb', '{}')
        made.writestr(f'strangerx_999_5003_{NB03}.ipynb', '{}')
    times: dict = {}
    refused = screen_zip(archive, tmp_path / 'clean.zip', times,
                         canvas_learners={'101': 'ada', '102': 'bo'})
    with zipfile.ZipFile(tmp_path / 'clean.zip') as clean:
        assert sorted(clean.namelist()) == [f'ada/{NB03}.ipynb', f'bo/{NB03}-1.ipynb']
    assert refused == [f'strangerx_999_5003_{NB03}.ipynb: Canvas user 999 is not in the roster '
                       '(lms_id column): add their row (ROSTER=roster.csv), not graded']
    assert times == {}


def test_an_export_leaves_blank_what_is_not_yet_due_or_not_scored(tmp_path):
    """A DUE_BY still to come made every notebook due by it due now (0 for who had not
    handed in yet), and a notebook handed in without a score in the gradebook was 0."""
    from ros2nb_instructor.grading.export.exporting import deciding_time, mark
    from ros2nb_instructor.grading.intake.submissions import Learner
    course = settings(tmp_path, GUIDE)
    soon = datetime.datetime.now(UTC) + datetime.timedelta(days=400)
    assert deciding_time(soon) < soon
    assert deciding_time(course.due[NB03]) == course.due[NB03]
    absent = Learner('absent', 'absent')
    not_yet = course.due[NB03] - datetime.timedelta(days=1)
    assert mark(absent, NB03, None, 6, course, extensions.NONE, not_yet).score is None
    assert mark(absent, NB03, None, 6, course, extensions.NONE, course.due[NB03]).score == 0.0
    unscored = Learner('unscored', 'unscored', files={NB03: tmp_path / f'{NB03}.ipynb'})
    said = mark(unscored, NB03, None, 6, course, extensions.NONE, course.due[NB03])
    assert said.score is None and "no score in the gradebook" in said.feedback, said
