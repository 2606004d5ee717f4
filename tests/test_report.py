"""The class report (``grading/report.html``) from grades and results, without grading a class.

The sample class (tests/test_grading.py) shows the report of a real grading in a browser; here
its pure logic: what each table counts, and that a learner's text stays text.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

from ros2nb.outcomes import CHECK_FAILED, CheckOutcome
from ros2nb_instructor.grading.reports.report import write_report
from ros2nb_instructor.grading.intake.submissions import Learner

NOTEBOOKS = ['03-write-the-publisher', '04-write-the-subscriber']
FAILURE = 'TemperatureSensor() never calls super().__init__'


def class_of_three() -> tuple[list[Learner], list[list[str]]]:
    """Three learners: one complete, one who failed the same check as another, one who handed
    in 03 only and named a folder like a script."""
    ada, bo = Learner('ada', 'ada'), Learner('bo', 'bo')
    mallory = Learner('<script>alert(1)</script>', 'mallory')
    for learner in (ada, bo, mallory):
        learner.files['03-write-the-publisher'] = Path('03.ipynb')
        learner.results['03-write-the-publisher'] = {'constructor': CheckOutcome(True)}
    for learner in (ada, bo):
        learner.files['04-write-the-subscriber'] = Path('04.ipynb')
    failed = CheckOutcome(False, (), CHECK_FAILED, FAILURE)
    ada.results['04-write-the-subscriber'] = {'callback': CheckOutcome(True)}
    bo.results['04-write-the-subscriber'] = {'callback': failed}
    mallory.results['03-write-the-publisher']['callback'] = failed
    mallory.note('_folder', '<b>bold</b> claims')
    rows = [['ada', NOTEBOOKS[0], '6', '6'], ['ada', NOTEBOOKS[1], '4', '4'],
            ['ada', 'TOTAL', '10', '10'],
            ['bo', NOTEBOOKS[0], '6', '6'], ['bo', NOTEBOOKS[1], '1', '4'],
            ['bo', 'TOTAL', '7', '10'],
            [mallory.shown, NOTEBOOKS[0], '3', '6'], [mallory.shown, 'TOTAL', '3', '10']]
    return [ada, bo, mallory], rows


def table(page: str, name: str) -> str:
    return re.search(rf'<table id="{name}">.*?</table>', page, re.S).group(0)


def test_the_report_counts_what_the_class_did(tmp_path):
    learners, rows = class_of_three()
    page = write_report(tmp_path, learners, NOTEBOOKS, rows, ['eve/extra.zip: not unpacked'])
    text = page.read_text()
    checks = table(text, 'checks')
    assert re.search(r'<td>03</td><td>constructor</td><td class="n">3</td><td class="n">3</td>',
                     checks), checks
    assert '<tr><td>04</td><td>callback</td><td class="n">1</td><td class="n">2</td>' in checks
    assert '<tr class="low"><td>03</td><td>callback</td><td class="n">0</td>' in checks  # fewer
    # than half passed: marked
    failures = table(text, 'failures')
    assert f'<td class="n">2</td><td>callback</td><td>{html.escape(FAILURE)}</td>' in failures
    learners_table = table(text, 'learners')
    assert '<td class="n none">–</td>' in learners_table  # 04 not handed in
    assert '10 of 10' in learners_table and '7 of 10' in learners_table
    assert 'eve/extra.zip: not unpacked' in text
    assert 'src="data:image/png;base64,' in text


def test_a_learners_text_stays_text(tmp_path):
    learners, rows = class_of_three()
    text = write_report(tmp_path, learners, NOTEBOOKS, rows, []).read_text()
    assert '<script>alert(1)</script>' not in text and '<b>bold</b>' not in text
    assert '&lt;script&gt;alert(1)&lt;/script&gt;' in text
    assert "script-src 'none'" in text or 'default-src' in text  # the page runs nothing


def _class_of(files: dict[str, dict[str, Path]]
              ) -> tuple[list[Learner], list[str], list[list[str]]]:
    learners, notebooks = [], sorted({n for handed in files.values() for n in handed})
    rows = []
    for name, handed in sorted(files.items()):
        learner = Learner(name, name)
        learner.files.update(handed)
        learners.append(learner)
        rows += [[name, notebook, '0', '1'] for notebook in notebooks]
    return learners, notebooks, rows


def _alike_rows(page: str) -> list[tuple[str, ...]]:
    return re.findall(r'<tr><td>(\d\d)</td><td>([^<]+)</td><td>([^<]+)</td><td>([^<]+)</td>'
                      r'<td class="n">(\d+)%</td></tr>', table(page, 'similarity'))


def test_answers_alike_are_listed_and_an_honest_class_has_none(tmp_path):
    """The sample class's answers alike: a copy of the course's 04 (its callback's names and
    comments changed) and two learners who share a 03 callback are listed; the honest
    learners, each in a style of their own, are not."""
    from grading_samples import alike_class
    classes = alike_class(tmp_path / 'class')
    page = write_report(tmp_path, *_class_of(classes['copies']), []).read_text()
    rows = _alike_rows(page)
    found = {(cell, first, second) for _nb, cell, first, second, _ratio in rows}
    course = "the course's answer"
    assert found == {
        ('04-monitor-callback-answer', course, 'copies-the-course'),
        ('04-monitor-constructor-answer', course, 'copies-the-course'),
        ('04-monitor-main-answer', course, 'copies-the-course'),  # copied as it was
        ('03-sensor-callback-answer', 'shares-it-renamed', 'shares-one')}, rows
    assert all(int(ratio) >= 85 for *_rest, ratio in rows), rows
    honest = write_report(tmp_path, *_class_of(classes['honest']), []).read_text()
    assert _alike_rows(honest) == [] and 'no two answers alike' in table(honest, 'similarity')
    assert 'id="common"' not in honest


def test_a_cell_most_of_the_class_writes_like_the_course_is_summed_up(tmp_path):
    """Four honest learners of 04, three of whom write main() as its comments dictate (the
    course's): one line says so, and no pair of them is listed."""
    from grading_samples import alike_class
    page = write_report(tmp_path, *_class_of(alike_class(tmp_path / 'class')['mains']),
                        []).read_text()
    assert _alike_rows(page) == [], _alike_rows(page)
    assert re.search(r'<p id="common">[^<]*04-monitor-main-answer: 3 of 4 '
                     r'\(honest-3, honest-4, honest-5\)</p>', page), page


#: The course's 04 callback disguised: its branches swapped, its names changed, a statement
#: that does nothing added.  Difflib's ratio over tokens had it at 0.716.
DISGUISED = """%%part {SUBSCRIBER} 4
    def temperature_callback(self, msg):
        reading = msg.data
        unused = reading * 2
        if reading < LOW_BELOW_C:
            label = 'Low'
        elif reading > HIGH_ABOVE_C:
            label = 'High'
        else:
            label = 'Normal'
        self.get_logger().info(f'Temperature: {reading:.2f}C - Status: {label}')
"""


def test_a_disguised_copy_and_a_copy_in_an_added_cell_are_listed(tmp_path):
    """Beside the honest class: the course's 04 callback disguised in the answer cell, and
    the same without the dead statement in a ``%%part`` cell the learner added after the
    answer cell they left as handed out (the part the judge grades is the added cell's).
    Each is listed beside the course's answer; no honest learner is."""
    import nbformat
    from grading_samples import NB04, alike_class
    from ros2nb_instructor.paths import NOTEBOOKS as HANDED_OUT
    files = alike_class(tmp_path / 'class')['honest']
    handed_out = nbformat.read(HANDED_OUT / f'{NB04}.ipynb', as_version=4)
    answer = next(i for i, cell in enumerate(handed_out.cells) if cell.metadata.get(
        'nbgrader', {}).get('grade_id') == '04-monitor-callback-answer')
    disguised, added = nbformat.from_dict(handed_out), nbformat.from_dict(handed_out)
    disguised.cells[answer].source = DISGUISED
    added.cells.insert(answer + 1, nbformat.v4.new_code_cell(
        DISGUISED.replace('        unused = reading * 2\n', '')))
    for name, nb in (('disguises-it', disguised), ('adds-a-cell', added)):
        (tmp_path / name).mkdir()
        nbformat.write(nb, tmp_path / name / f'{NB04}.ipynb')
        files[name] = {NB04: tmp_path / name / f'{NB04}.ipynb'}
    rows = _alike_rows(write_report(tmp_path, *_class_of(files), []).read_text())
    course = "the course's answer"
    assert {(cell, first, second) for _nb, cell, first, second, _ratio in rows} == {
        ('04-monitor-callback-answer', course, 'disguises-it'),
        ('04-monitor-callback-answer (an added cell)', course, 'adds-a-cell'),
        ('04-monitor-callback-answer (an added cell)', 'adds-a-cell', 'disguises-it')}, rows


def test_every_pair_at_the_threshold_is_listed_by_copydetects_own_measure(tmp_path):
    """Two classmates of 03 whose constructors share few distinct fingerprints, yet copydetect
    finds 0.98 of one in the other and 0.88 back (its shares count the characters its matches
    cover): listed.  A count of the fingerprints in common had ruled the pair out unmeasured."""
    import nbformat
    from corpora import every_learner
    from grading_samples import NB03, written_by
    from ros2nb_instructor.grading.reports.similarity import alike
    from ros2nb_instructor.paths import NOTEBOOKS as HANDED_OUT
    corpus, handed = every_learner(), {}
    for who, name in (('one', '03 a timer of 1 (an int)'),
                      ('two', '03 dead code: the timer under if False')):
        path = tmp_path / who / f'{NB03}.ipynb'
        path.parent.mkdir()
        nbformat.write(written_by(corpus[name]), path)
        handed[who] = path
    pairs, _common = alike('03', None, handed, HANDED_OUT / f'{NB03}.ipynb')
    assert [(p.cell, p.first, p.second) for p in pairs] == [
        ('03-sensor-constructor-answer', 'one', 'two')], pairs
    assert pairs[0].ratio >= 0.85, pairs


def test_the_honest_corpus_as_a_class_lists_no_two_classmates(tmp_path):
    """Every honest learner of tests/corpus_honest.py as one class per notebook, each with
    their other cells as handed out: no pair of classmates is listed.  Two 09 learners whose
    three small profiles, names set aside, share 26 characters ("def f(): return v") came to
    0.87 and 0.60: too little in common to tell a copy from chance (MIN_CHARS)."""
    import nbformat
    from corpus_honest import HONEST
    from grading_samples import NOTEBOOKS_BY_NUMBER, SOLUTION, written_by
    from ros2nb_instructor.grading.reports.similarity import COURSE, alike
    from ros2nb_instructor.paths import NOTEBOOKS as HANDED_OUT
    by_notebook: dict[str, dict[str, Path]] = {}
    for index, learner in enumerate(HONEST):
        notebook = NOTEBOOKS_BY_NUMBER[learner.notebook]
        path = tmp_path / f'honest-{index}' / f'{notebook}.ipynb'
        path.parent.mkdir(exist_ok=True)
        nbformat.write(written_by(learner), path)
        by_notebook.setdefault(notebook, {})[learner.name] = path
    between = []
    for notebook, handed in sorted(by_notebook.items()):
        pairs, _common = alike(notebook[:2], SOLUTION[notebook], handed,
                               HANDED_OUT / f'{notebook}.ipynb')
        between += [pair for pair in pairs if COURSE not in (pair.first, pair.second)]
    assert between == [], between
