"""The learner's lab in a real browser: what ``make lab`` starts, driven as a learner would.

One JupyterLab server, started by ``ros2nb-lab`` as ``make lab`` starts it (the learner's
configuration, a working folder of its own, a token), and one headless chromium, shared
by the tests of this module in file order:

1. a learner notebook shows no instructor tool (no Nbgrader menu, no Create Assignment
   panel, no Validate button) and no news pop-up;
2. a finished notebook (01, the cheapest) runs to the end with Run All Cells, its check
   passing in its own cell;
3. Interrupt stops a running spin within 1 s, with one line;
4. a learner without a pointer goes through notebook 03 to its first check with the keyboard
   alone: runs the cells, sees the check fail on the unwritten part, writes it, and passes.

Screenshots go to a temporary folder whose name the tests print (``-s`` shows it).
"""

from __future__ import annotations

import os
import re
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nbformat
import pytest

import browser
from waiting import wait_for

pytestmark = [pytest.mark.browser, pytest.mark.kernel, pytest.mark.timeout(600)]

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK = '01-create-a-workspace.ipynb'
#: A cell that spins a ticking node for longer than any test waits, announcing the spin first.
SPIN_CELL = ("from rclpy.node import Node\n"
             "class Ticker(Node):\n"
             "    def __init__(self):\n"
             "        super().__init__('ticker')\n"
             "        self.create_timer(1.0, lambda: self.get_logger().info('tick'))\n"
             "ticker = ros2nb.add(Ticker())\n"
             "print('spinning')\n"
             "_ = ros2nb.spin(10 ** 7)\n")
#: The notebook's cells are all there and its kernel is idle (the status bar says so).
NOTEBOOK_READY = ("n => document.querySelectorAll('.jp-Notebook .jp-CodeCell').length === n && "
                  "(document.querySelector('#jp-main-statusbar') || {innerText: ''})"
                  ".innerText.includes('| Idle')")
CELL_DONE = ("i => !document.querySelectorAll('.jp-Notebook .jp-CodeCell .jp-InputPrompt')[i]"
             ".textContent.includes('*')")
INSTRUCTOR_TEXTS = ('Nbgrader', 'Create Assignment', 'Formgrader', 'Course List',
                    'Assignment List', 'Validate', 'Extension Manager')
NEWS_TEXT = 'official Jupyter news'


def free_port() -> int:
    with socket.socket() as s:
        s.bind(('127.0.0.1', 0))
        return s.getsockname()[1]


def answers(url: str) -> bool:
    try:
        with urllib.request.urlopen(url, timeout=2) as response:
            return response.status == 200
    except OSError:
        return False


@dataclass(frozen=True)
class Lab:
    """What the ``lab`` fixture hands a test.

    :ivar page: Playwright's page, on notebook 01 in the learner's lab.
    :ivar shots: where the test's screenshots go.
    :ivar work: the learner's work folder (``ROS2NB_WORK``).
    :ivar url: the lab's address with its token (``http://127.0.0.1:PORT/lab/tree/{}?token=...``,
        ``{}`` for a notebook's name).
    """

    page: Any
    shots: Path
    work: Path
    url: str


@pytest.fixture(scope='module')
def lab(tmp_path_factory):
    """A learner's lab (``ros2nb-lab``) on a free port with a token, and a page on notebook 01."""
    why = browser.problem()
    if why:
        pytest.skip(why)
    home = tmp_path_factory.mktemp('learners-lab')
    work = home / 'work'
    work.mkdir()
    shutil.copyfile(ROOT / 'solutions' / NOTEBOOK, work / NOTEBOOK)  # a learner who finished 01
    env = {k: v for k, v in os.environ.items()
           if k not in ('ROS_DOMAIN_ID', 'JUPYTER_CONFIG_PATH', 'PYTEST_CURRENT_TEST')}
    env.update(JUPYTER_CONFIG_DIR=str(home / 'config'), JUPYTER_DATA_DIR=str(home / 'data'),
               JUPYTER_RUNTIME_DIR=str(home / 'runtime'), IPYTHONDIR=str(home / 'ipython'),
               ROS2NB_WORK=str(work), ROS2NB_WORKSPACE=str(home / 'ws'))
    port, token = free_port(), secrets.token_hex(16)
    server = subprocess.Popen(
        [str(Path(sys.executable).parent / 'ros2nb-lab'), f'--ServerApp.port={port}',
         '--ServerApp.port_retries=0', '--ServerApp.open_browser=False',
         f'--IdentityProvider.token={token}'],
        env=env, stdout=subprocess.DEVNULL, stderr=open(home / 'server.log', 'w'),
        start_new_session=True)
    base = f'http://127.0.0.1:{port}'
    try:
        wait_for(lambda: server.poll() is not None or answers(f'{base}/api/status?token={token}'),
                 'the learner\'s lab answering',
                 seen=lambda: (home / 'server.log').read_text()[-800:])
        assert server.poll() is None, (home / 'server.log').read_text()
        shots = Path(tmp_path_factory.mktemp('lab-screenshots'))
        print(f'\nscreenshots: {shots}')
        with browser.chromium() as chromium:
            context = chromium.new_context(viewport={'width': 1400, 'height': 900})
            page = context.new_page()
            # Up to the document's parse, with no time limit: what follows is polled (a busy
            # machine takes longer than Playwright's 30 s to load the whole lab).
            page.goto(f'{base}/lab/tree/{NOTEBOOK}?token={token}', wait_until='domcontentloaded',
                      timeout=0)
            code_cells = sum(c.cell_type == 'code' for c in nbformat.read(work / NOTEBOOK, 4).cells)
            wait_for(lambda: page.evaluate(NOTEBOOK_READY, code_cells), 'the notebook shown',
                     seen=lambda: page.content()[-800:])
            yield Lab(page, shots, work, f'{base}/lab/tree/{{}}?token={token}')
            context.close()
    finally:
        os.killpg(server.pid, signal.SIGTERM)
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(server.pid, signal.SIGKILL)
            server.wait()


def menu(page, top: str, item: str) -> None:
    """Choose ``top`` > ``item`` in JupyterLab's menu bar."""
    page.click(f'.lm-MenuBar-itemLabel:text-is("{top}")')
    page.click(f'.lm-Menu-itemLabel:text-is("{item}")')


def prompts(page) -> list[str]:
    return page.eval_on_selector_all('.jp-Notebook .jp-CodeCell .jp-InputPrompt',
                                     'els => els.map(e => e.textContent.trim())')


def test_no_instructor_tool_and_no_news_popup(lab):
    page, shots, work = lab.page, lab.shots, lab.work
    labels = page.eval_on_selector_all('.lm-MenuBar-itemLabel',
                                       'els => els.map(e => e.textContent)')
    assert {'File', 'Run', 'Kernel'} <= set(labels), labels  # the menu bar is there, and read
    assert 'Nbgrader' not in labels, labels
    shown = page.inner_text('body')
    for text in INSTRUCTOR_TEXTS:
        assert text not in shown, text
    assert page.locator('button:has-text("Validate"), jp-button:has-text("Validate")').count() == 0
    news = page.evaluate("JSON.parse(document.getElementById('jupyter-config-data')"
                         ".textContent).news")
    assert news == {'disabled': True}
    assert NEWS_TEXT not in shown
    assert (work / '00-setup-and-the-pubsub-idea.ipynb').is_file()  # the course's, copied in
    page.screenshot(path=str(shots / 'learner-lab-01-opened.png'))


def test_a_finished_notebook_runs_to_the_end_with_its_check_passing(lab):
    page, shots = lab.page, lab.shots
    menu(page, 'Edit', 'Clear Outputs of All Cells')
    wait_for(lambda: all(p in ('[ ]:', '') for p in prompts(page)), 'outputs cleared',
             seen=lambda: prompts(page))
    menu(page, 'Run', 'Run All Cells')
    wait_for(lambda: all(p[1:-2].isdigit() for p in prompts(page)), 'every cell run',
             seen=lambda: prompts(page))
    checks = page.locator('.jp-CodeCell:has(.jp-InputArea:has-text("ros2nb.checks."))')
    assert checks.count() >= 1
    for index in range(checks.count()):
        lines = checks.nth(index).locator('.jp-OutputArea').inner_text().strip().splitlines()
        # its one line, then where it stands in the learner's progress (ros2nb.graded_parts)
        assert len(lines) == 2 and lines[0].startswith('Check passed:') \
            and lines[1].startswith('Progress: '), lines
    page.screenshot(path=str(shots / 'learner-lab-01-run-all.png'), full_page=True)


def shown_lines(cell) -> list[str]:
    """The lines of a cell's outputs as shown, each output on its own (the text of the whole
    output area has blank lines between outputs that show nowhere on the page)."""
    return [line for text in cell.locator('.jp-OutputArea-child').all_inner_texts()
            for line in text.strip().splitlines()]


def test_interrupt_stops_a_spin_with_one_line(lab):
    """Stop ends a spin that would run for 10**7 s, with one line. How fast (the target is
    under a second) is ``make bench BENCH_ARGS='--only interrupt'``'s to measure: a browser
    beside CPU burners cannot promise a second (docs/decisions.md)."""
    page, shots = lab.page, lab.shots
    index = page.locator('.jp-Notebook .jp-CodeCell').count()  # the new cell's, at the end
    page.locator('.jp-Notebook .jp-Cell').last.click()
    page.keyboard.press('Escape')
    page.keyboard.press('b')
    page.keyboard.press('Enter')
    page.keyboard.insert_text(SPIN_CELL)
    page.keyboard.press('Shift+Enter')
    cell = page.locator('.jp-Notebook .jp-CodeCell').nth(index)  # Shift+Enter added one below
    wait_for(lambda: 'spinning' in cell.locator('.jp-OutputArea').inner_text(), 'the spin running',
             seen=lambda: cell.inner_text())
    began = time.monotonic()
    page.click('.jp-NotebookPanel-toolbar [data-command="notebook:interrupt-kernel"]')
    wait_for(lambda: page.evaluate(CELL_DONE, index), 'the interrupted cell done', interval=0.01,
             seen=lambda: cell.inner_text())
    took = time.monotonic() - began
    print(f'\nInterrupt stopped the spin in {took:.2f} s')
    # Each output on its own: the text of the whole area has a blank line where a spin's
    # progress line came and went, which shows nowhere on the page.
    lines = shown_lines(cell)
    page.screenshot(path=str(shots / 'learner-lab-01-interrupted.png'))
    assert (lines[0] == 'spinning' and len(lines) == 2
            and lines[1].startswith('Interrupted after ')), lines


KEYBOARD_NOTEBOOK = '03-write-the-publisher.ipynb'
#: The notebook on show (the lab keeps the tabs it hides in the page).
SHOWN = '.jp-NotebookPanel:not(.lm-mod-hidden) .jp-Notebook'
#: Notebook 03 shown, its cells all there and its kernel idle.
SHOWN_READY = ("n => { const nb = document.querySelector('" + SHOWN + "');"
               " return !!nb && nb.querySelectorAll('.jp-CodeCell').length === n &&"
               " (document.querySelector('#jp-main-statusbar') || {innerText: ''})"
               ".innerText.includes('| Idle'); }")
#: The index of the shown notebook's active cell, and whether the page's focus is in it.
WHERE = ("() => { const nb = document.querySelector('" + SHOWN + "');"
         " const cells = [...nb.querySelectorAll('.jp-Cell')];"
         " return [cells.findIndex(c => c.classList.contains('jp-mod-active')),"
         " nb.contains(document.activeElement)]; }")


def _cell(page, index: int):
    return page.locator(f'{SHOWN} .jp-Cell').nth(index)


def _output(page, index: int) -> str:
    """The text of cell ``index``'s output, once it ran (its prompt shows a number)."""
    prompt = _cell(page, index).locator('.jp-InputPrompt').inner_text()
    return _cell(page, index).locator('.jp-OutputArea').inner_text() \
        if re.search(r'\[\d+\]', prompt) else ''


def _press_until(page, key: str, index: int) -> None:
    """Press ``key`` until cell ``index`` is the active one, each press moving one cell."""
    for _ in range(page.locator(f'{SHOWN} .jp-Cell').count()):
        if page.evaluate(WHERE)[0] == index:
            return
        page.keyboard.press(key)
    assert page.evaluate(WHERE)[0] == index


def test_the_first_check_of_03_by_keyboard_alone(lab):
    """No click from here on: the notebook opened at its address (as a bookmark would), then
    only keys, each of JupyterLab's own: Shift+Enter runs a cell and moves on, Up selects the
    cell above, Enter edits it, Ctrl+A selects its text (which the learner's part replaces)."""
    # The same window: a second one on the same lab would be moved to a workspace of its own.
    page = lab.page
    page.goto(lab.url.format(KEYBOARD_NOTEBOOK), wait_until='domcontentloaded', timeout=0)
    notebook = nbformat.read(lab.work / KEYBOARD_NOTEBOOK, 4)
    wait_for(lambda: page.evaluate(SHOWN_READY, sum(c.cell_type == 'code'
                                                    for c in notebook.cells)),
             'notebook 03 shown', seen=lambda: page.content()[-800:])
    answer = next(i for i, c in enumerate(notebook.cells)
                  if c.metadata.get('nbgrader', {}).get('solution'))
    check = answer + 1
    assert 'learner-check' in notebook.cells[check].metadata.get('tags', [])
    wait_for(lambda: page.evaluate(WHERE) == [0, True], 'the first cell active, with the focus',
             seen=lambda: page.evaluate(WHERE))
    page.keyboard.press('Escape')  # command mode: keys act on cells
    _press_until(page, 'Shift+Enter', check + 1)  # everything up to the check, run
    # The check's one line first, then (once the cell ended) where the part stands.
    failed = wait_for(lambda: 'Progress: ' in _output(page, check)
                      and shown_lines(_cell(page, check)), 'the check of the unwritten part',
                      seen=lambda: _cell(page, check).inner_text())
    assert len(failed) == 2 and failed[0].startswith('CheckFailed: ') \
        and failed[1].startswith('Progress: ') and 'not passed yet' in failed[1], failed

    solution = nbformat.read(ROOT / 'solutions' / KEYBOARD_NOTEBOOK, 4).cells[answer].source
    _press_until(page, 'ArrowUp', answer)
    page.keyboard.press('Enter')  # edit mode, in the learner's cell
    page.keyboard.press('Control+a')
    page.keyboard.insert_text(re.sub(r' *### (BEGIN|END) SOLUTION\n?', '', solution))
    page.keyboard.press('Shift+Enter')  # saves the part; the check is next
    wait_for(lambda: page.evaluate(WHERE) == [check, True], 'the check cell active',
             seen=lambda: page.evaluate(WHERE))
    page.keyboard.press('Shift+Enter')
    wait_for(lambda: _output(page, check).strip().startswith('Check passed:'), 'the check passed',
             seen=lambda: _cell(page, check).inner_text())
    assert page.evaluate(WHERE) == [check + 1, True]
    page.screenshot(path=str(lab.shots / 'learner-lab-03-by-keyboard.png'))
