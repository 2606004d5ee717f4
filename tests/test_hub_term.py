"""A term on the course's real JupyterHub, in the browser: hand in, grade, export, feedback.

Two learners, ``ada`` and ``grace``, log in to the hub (``tests/hubs.py``: the course's own
hub config, its hand-in service included) in Debian's chromium, each in a browser context of
their own, open notebook 01 (the cheapest to grade, finished) in their lab and hand it in
with ``ros2nb.hand_in("01")``, ada first, then grace.  01 was due an hour before; grace has
an extension of two days (``extensions.toml``), ada none.  The times come from the hand-in
service's clock, each notebook its own.

Then the instructor: ``make hub-collect`` (the store, with the times), ``make grade`` (in the
sandboxes), ``make export EXPORT=canvas`` (from the gradebook, nothing graded again) and
``make hub-feedback``.  Ada's 01 is late by less than a day: 10 % off, 0.9; grace's is on
time by her extension: 1.  Last, each learner sees, in their lab, their due date, hand-in and
a link to their feedback (``ros2nb.progress()``), and opens their own page on the hub; no
request of theirs reaches the other's.

Screenshots go to a temporary folder whose name the test prints (``-s`` shows it).
"""

from __future__ import annotations

import csv
import datetime
import json
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import requests

import browser
import hubs
from hubs import LEARNERS, ROOT, SERVER_START_S, Hub, server_ready, server_state, start_hub
from waiting import PATIENCE_S, wait_for

from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb.temporary import owned_folder

pytestmark = [pytest.mark.hub, pytest.mark.browser, pytest.mark.kernel, pytest.mark.sandbox,
              pytest.mark.judge, pytest.mark.timeout(12 * PATIENCE_S)]

for _why in (hubs.problem(), browser.problem(), bubblewrap.problem()):
    if _why:
        pytest.skip(_why, allow_module_level=True)

NB = '01-create-a-workspace'
ADA, GRACE = LEARNERS
BIN = Path(sys.executable).parent
#: The notebook's cells are all there and its kernel idle (JupyterLab's status bar says so).
READY = ("n => document.querySelectorAll('.jp-Notebook .jp-CodeCell').length === n && "
         "(document.querySelector('#jp-main-statusbar') || {innerText: ''})"
         ".innerText.includes('| Idle')")
#: The prompt of code cell ``i`` shows a number: it ran.
RAN = ("i => /\\[\\d+\\]/.test(document.querySelectorAll('.jp-Notebook .jp-CodeCell "
       ".jp-InputPrompt')[i].textContent)")
ROSTER = ('learner,name,lms_id,sis_id,login\n'
          'ada,Ada Lovelace,101,S-1,ada\n'
          'grace,Grace Hopper,102,S-2,grace\n')


def run(command: str, *args: object) -> subprocess.CompletedProcess:
    """One of the course's commands, as the instructor's make target runs it."""
    done = subprocess.run([str(BIN / command), *map(str, args)], capture_output=True, text=True,
                          timeout=6 * PATIENCE_S)
    assert done.returncode == 0, f'{command}: {done.stdout}{done.stderr}'
    return done


def a_cell(page: Any, code: str) -> list[str]:
    """Add a cell at the notebook's end, run it with Shift+Enter, and return its output's
    lines once it ran."""
    index = page.locator('.jp-Notebook .jp-CodeCell').count()
    page.locator('.jp-Notebook .jp-Cell').last.click()
    for key in ('Escape', 'b', 'Enter'):
        page.keyboard.press(key)
    page.keyboard.insert_text(code)
    page.keyboard.press('Shift+Enter')
    cell = page.locator('.jp-Notebook .jp-CodeCell').nth(index)
    wait_for(lambda: page.evaluate(RAN, index), f'the cell {code!r} run',
             seen=lambda: cell.inner_text())
    return [line for text in cell.locator('.jp-OutputArea-child').all_inner_texts()
            for line in text.strip().splitlines()]


def open_lab(chromium: Any, hub: Hub, learner: str) -> Any:
    """A browser context of ``learner``'s own: logged in to the hub, notebook 01 open."""
    context = chromium.new_context(viewport={'width': 1400, 'height': 900})
    page = context.new_page()
    page.goto(f'{hub.url}/hub/login', wait_until='domcontentloaded', timeout=0)
    page.fill('#username_input', learner)
    page.fill('#password_input', 'any')  # the test's DummyAuthenticator takes any
    page.click('#login_submit')
    wait_for(lambda: '/hub/login' not in page.url, f'{learner} logged in',
             seen=lambda: page.url)
    page.goto(f'{hub.url}/user/{learner}/lab/tree/notebooks/{NB}.ipynb',
              wait_until='domcontentloaded', timeout=0)
    cells = sum(c['cell_type'] == 'code' for c in
                json.loads((ROOT / 'solutions' / f'{NB}.ipynb').read_text())['cells'])
    wait_for(lambda: page.evaluate(READY, cells), f"{learner}'s notebook 01 shown",
             seen=lambda: page.url)
    return page


def a_term(folder: Path, due: datetime.datetime) -> None:
    """The instructor's files: 01 due at ``due``, 10 % a day begun; grace two more days."""
    (folder / 'course.toml').write_text(
        f'[late]\npenalty = "per-day"\npercent = 10\n[notebooks.{NB}]\n'
        f'due = {due.isoformat(timespec="seconds")}\n')
    (folder / 'extensions.toml').write_text(f'[{GRACE}]\n"01" = {{ days = 2 }}\n')
    (folder / 'roster.csv').write_text(ROSTER)
    for learner in LEARNERS:  # each has finished 01 before their server starts
        notebooks = folder / 'home' / learner / 'ros2-course' / 'notebooks'
        notebooks.mkdir(parents=True)
        shutil.copyfile(ROOT / 'solutions' / f'{NB}.ipynb', notebooks / f'{NB}.ipynb')


def grade_and_release(folder: Path) -> list[list[str]]:
    """The instructor's part: collect, grade, export for Canvas the notebooks due by now
    (01 alone), release; the Canvas rows."""
    settings = ('--settings', folder / 'course.toml', '--extensions', folder / 'extensions.toml')
    store = ('--store', folder / 'handed-in')
    run('ros2nb-hub-collect', folder / 'class', *store)
    for learner in LEARNERS:
        assert json.loads((folder / 'class' / learner / 'handed-in.json').read_text()).keys() \
            == {NB}, learner
    run('ros2nb-grade', folder / 'class', '--out', folder / 'grading', *settings, '--seed', 7)
    now = datetime.datetime.now(datetime.timezone.utc).isoformat(timespec='seconds')
    exported = run('ros2nb-export', 'canvas', '--grading', folder / 'grading', '--roster',
                   folder / 'roster.csv', *settings, '--due-by', now)
    assert 'graded' not in exported.stdout  # from the gradebook: nothing graded again
    run('ros2nb-hub-feedback', folder / 'grading', *store)
    with open(folder / 'grading' / 'export' / 'canvas.csv', newline='') as stream:
        return list(csv.reader(stream))


def test_two_learners_hand_in_one_graded_late_one_extended_each_sees_their_own(tmp_path):
    folder = owned_folder('ros2nb-hub-term-')
    shots = tmp_path / 'shots'
    shots.mkdir()
    print(f'\nscreenshots: {shots}')
    due = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0) \
        - datetime.timedelta(hours=1)
    a_term(folder, due)
    hub = None
    try:
        hub = start_hub(folder, f"c.JupyterHub.services[0]['command'] += "
                                f"['--settings', {str(folder / 'course.toml')!r}]\n")
        for learner in LEARNERS:
            hubs.start_server(hub, learner)
        for learner in LEARNERS:
            hubs.wait_for(lambda: server_ready(hub, learner), SERVER_START_S,
                          f"{learner}'s server ready", hub,
                          seen=lambda: server_state(hub, learner))
        with browser.chromium() as chromium:
            pages = {learner: open_lab(chromium, hub, learner) for learner in LEARNERS}
            said = {}
            for learner in LEARNERS:  # ada first, then grace
                said[learner] = a_cell(pages[learner], f'import ros2nb\nros2nb.hand_in("{NB[:2]}")')
                pages[learner].screenshot(path=str(shots / f'{learner}-handed-in.png'))
            handed_in(folder, said, due)
            rows = grade_and_release(folder)
            assert rows[0][5:] == [NB] and rows[1][5:] == ['1'], rows
            assert {row[2]: row[5] for row in rows[2:]} == {'S-1': '0.9', 'S-2': '1'}, rows
            for learner in LEARNERS:
                sees_their_own(hub, pages[learner], learner, shots)
    except Exception as error:  # noqa: BLE001 - said with what the hub logged
        tail = hub.log_tail() if hub is not None else ''
        raise AssertionError(f'{type(error).__name__}: {error}\nthe hub log ends:\n{tail}') \
            from error
    finally:
        if hub is not None:
            hubs.stop_hub(hub)
        shutil.rmtree(folder, ignore_errors=True)


def handed_in(folder: Path, said: dict[str, list[str]], due: datetime.datetime) -> None:
    """Each hand-in's line in the lab, and the times the service kept: its own clock, ada's
    before grace's, ada's late and grace's on time by her extension."""
    for learner, expected in ((ADA, ': late by '), (GRACE, ': on time')):
        assert len(said[learner]) == 1, said[learner]
        line = said[learner][0]
        assert line.startswith(f"Handed in {NB} by the hub's clock, as saved at ") and \
            expected in line, line
    assert "(your extension; the class's: " in said[GRACE][0], said[GRACE]
    kept = {learner: datetime.datetime.fromisoformat(json.loads(
        (folder / 'handed-in' / learner / 'handed-in.json').read_text())[NB])
        for learner in LEARNERS}
    now = datetime.datetime.now(datetime.timezone.utc)
    assert due < kept[ADA] < kept[GRACE] <= now, kept


def sees_their_own(hub: Hub, page: Any, learner: str, shots: Path) -> None:
    """In the lab, progress() shows the due date, the hand-in and a link to the feedback;
    on the hub, the learner's own page, and nothing of the other's."""
    lines = a_cell(page, 'ros2nb.progress()')
    text = '\n'.join(lines)
    assert 'Your feedback (11 pages, one per notebook)' in text and 'due ' in text, text
    assert ('late by' in text) == (learner == ADA) and ('on time' in text) == (learner == GRACE)
    page.screenshot(path=str(shots / f'{learner}-progress.png'), full_page=True)
    other = GRACE if learner == ADA else ADA
    page.goto(f'{hub.url}/services/hand-in/feedback/', wait_until='domcontentloaded', timeout=0)
    wait_for(lambda: 'Your feedback' in page.inner_text('body'), f"{learner}'s feedback list",
             seen=lambda: page.url)
    assert f'Your feedback, {learner}' in page.inner_text('body')
    assert other not in page.inner_text('body')
    page.click(f'a:text-is("{NB}")')
    wait_for(lambda: 'Handed in' in page.inner_text('body'), f"{learner}'s feedback page",
             seen=lambda: page.url)
    body = page.inner_text('body')
    page.screenshot(path=str(shots / f'{learner}-feedback.png'), full_page=True)
    if learner == ADA:
        assert 'late penalty\t0.1' in body and 'score\t0.9' in body, body[:2000]
        assert 'extension\tto ' not in body
    else:
        assert 'extension\tto ' in body and 'score\t1' in body, body[:2000]
    cookies = {c['name']: c['value'] for c in page.context.cookies()}
    mine = requests.get(f'{hub.url}/services/hand-in/api/hand-ins', cookies=cookies,
                        timeout=PATIENCE_S)
    assert mine.status_code == 200 and mine.json()['learner'] == learner, mine.text
    nobody = requests.get(f'{hub.url}/services/hand-in/api/hand-ins', timeout=PATIENCE_S,
                          allow_redirects=False)
    assert nobody.status_code in (302, 403), nobody.status_code
