"""A class on one JupyterHub: two learners run notebook 04 at the same time, each on their own.

Everything here is real, nothing is mocked: JupyterHub from the course's venv, loaded with
the course's ``environment/jupyterhub_config.py``; configurable-http-proxy as ``make
hub-proxy`` installs it; two single-user servers started through the Hub's REST API, each
through the course's launcher ``ros2nb_instructor.hub.singleuser``; and one kernel on each server,
created with the server's REST API and driven over its kernel websocket with the learner's
own token. The hub lives in a temporary folder and listens on free ports of 127.0.0.1.

Two learners, ``ada`` and ``grace``, run ``solutions/04-write-the-subscriber.ipynb`` at the
same time, cell by cell in lockstep. Each must get exactly the stored outputs: for every
code cell not tagged ``nbval-ignore-output``, the text of its stream outputs and the
``ename``/``evalue`` of its errors, after ``tests/sanitize.cfg``'s replacements applied as
nbval's ``--nbval-sanitize-with`` applies them. Images and execution counts are ignored.

For the test, ``DummyAuthenticator`` and ``SimpleLocalProcessSpawner`` replace ``make hub``'s
PAM and ``LocalProcessSpawner``: the same machine and the same kind of server, but both
learners run as the Unix user running pytest, each with a home folder of their own in the
temporary folder (so their own copy of the notebooks and their own ROS workspace).

Neither the hub nor the servers get a ``ROS_DOMAIN_ID`` (it is removed from the hub's
environment and the course's config does not pass it on), as on a real hub: the learners'
kernels must keep apart by themselves.

Needs configurable-http-proxy in ``.cache/node`` (``make test`` installs it when npm can);
without it the test says so in one line and skips.
"""

from __future__ import annotations

import asyncio
import difflib
import json
import os
import re
import shutil
import time
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import pytest
import requests
from hubs import (API_S, CELL_S, LEARNERS, ROOT, SERVER_START_S, Hub, learner_token, problem,
                  server_ready, server_state, start_hub, start_server, stop_hub, wait_for)
from notebook_outputs import comparable_outputs, compared
from waiting import PATIENCE_S
from ros2nb.patience import LOOK_S, Patience, child_pids
from ros2nb.temporary import owned_folder
from tornado.httpclient import HTTPRequest
from tornado.websocket import (WebSocketClientConnection, WebSocketClosedError,
                               websocket_connect)

NOTEBOOK = ROOT / 'solutions' / '04-write-the-subscriber.ipynb'

pytestmark = [pytest.mark.hub, pytest.mark.kernel, pytest.mark.timeout(6 * PATIENCE_S)]

if problem():
    pytest.skip(problem(), allow_module_level=True)


# ----------------------------------------------------------------------- the kernels
class Kernel:
    """One kernel on a learner's server, driven over its websocket channels."""

    def __init__(self, learner: str, url: str, token: str,
                 connection: WebSocketClientConnection) -> None:
        self.learner, self.url, self.token = learner, url, token
        self.connection = connection
        self.session = uuid.uuid4().hex

    async def _send(self, message: str) -> None:
        """Send on the websocket; one that was closed before the send is opened again once.

        JupyterLab does the same when its kernel's websocket closes: it reconnects to the
        same kernel, which keeps its state.  (Beside a loaded make test, a server once closed
        a fresh kernel websocket before its first request was sent.)
        """
        try:
            await self.connection.write_message(message)
        except WebSocketClosedError:
            closed = (f'{self.learner}: the kernel websocket was closed before a request '
                      f'(code {self.connection.close_code}, {self.connection.close_reason!r})')
            self.connection = (await connect(self.learner, self.url, self.token)).connection
            try:
                await self.connection.write_message(message)
            except WebSocketClosedError:
                raise AssertionError(f'{closed}, and again after reconnecting') from None

    async def execute(self, code: str, seconds: float = CELL_S) -> list[dict]:
        """Run ``code`` and return its outputs (streams, errors, displays) in nbformat's shape."""
        msg_id = uuid.uuid4().hex
        await self._send(json.dumps({
            'channel': 'shell', 'buffers': [], 'metadata': {}, 'parent_header': {},
            'header': {'msg_id': msg_id, 'msg_type': 'execute_request', 'version': '5.3',
                       'session': self.session, 'username': self.learner},
            'content': {'code': code, 'silent': False, 'store_history': True,
                        'user_expressions': {}, 'allow_stdin': False, 'stop_on_error': True}}))
        outputs: list[dict] = []
        idle = replied = False
        # the hub, its servers and their kernels are this test's processes: a cell has
        # `seconds` of their work, or of their idle waiting, not of the wall clock
        patience, reading = Patience(child_pids(os.getpid()), seconds), None
        while not (idle and replied):
            reading = reading or asyncio.ensure_future(self.connection.read_message())
            done, _ = await asyncio.wait({reading}, timeout=LOOK_S)  # the read goes on
            if not done:
                if patience.exhausted():
                    raise AssertionError(f'{self.learner}: a cell ran longer than {seconds} s:\n'
                                         f'{code}')
                continue
            raw, reading = reading.result(), None
            if raw is None:
                raise AssertionError(f"{self.learner}: the kernel's websocket closed mid-cell")
            message = json.loads(raw) if isinstance(raw, str) else {}
            if message.get('parent_header', {}).get('msg_id') != msg_id:
                continue
            kind, content = message['msg_type'], message['content']
            idle = idle or (kind == 'status' and content['execution_state'] == 'idle')
            replied = replied or kind == 'execute_reply'
            if kind == 'stream':
                outputs.append({'output_type': 'stream', 'name': content['name'],
                                'text': content['text']})
            elif kind == 'error':
                outputs.append({'output_type': 'error', 'ename': content['ename'],
                                'evalue': content['evalue']})
            elif kind in ('display_data', 'execute_result'):
                outputs.append({'output_type': kind, 'data': content['data']})
        return outputs


def open_kernel(hub: Hub, learner: str, token: str) -> tuple[str, str]:
    """Start a kernel on ``learner``'s server in ``notebooks/``; return its id and websocket URL."""
    started = requests.post(f'{hub.url}/user/{learner}/api/kernels', timeout=API_S,
                            headers={'Authorization': f'token {token}'},
                            json={'name': 'python3', 'path': 'notebooks'})
    assert started.status_code == 201, f'kernel for {learner}: {started.status_code} {started.text}'
    kernel_id = started.json()['id']
    ws = hub.url.replace('http://', 'ws://', 1)
    return kernel_id, (f'{ws}/user/{learner}/api/kernels/{kernel_id}/channels'
                       f'?session_id={uuid.uuid4().hex}')


async def connect(learner: str, url: str, token: str) -> Kernel:
    """Open the kernel's websocket channels with the learner's token."""
    request = HTTPRequest(url, headers={'Authorization': f'token {token}'}, request_timeout=API_S)
    return Kernel(learner, url, token, await websocket_connect(request))


# ------------------------------------------------------------ nbval's comparison rules
def difference(want: list[str], have: list[str], lines: int = 12) -> str:
    """Return the start of a unified diff between stored and received outputs."""
    diff = list(difflib.unified_diff([line for t in want for line in t.splitlines() or ['']],
                                     [line for t in have for line in t.splitlines() or ['']],
                                     'stored', 'got', n=1, lineterm=''))
    more = f'\n    ... {len(diff) - lines} more diff lines' if len(diff) > lines else ''
    return '\n'.join('    ' + line for line in diff[:lines]) + more


def code_cells(notebook: Path) -> list[dict]:
    """Return the notebook's code cells."""
    return [c for c in json.loads(notebook.read_text())['cells'] if c['cell_type'] == 'code']


def source(cell: dict) -> str:
    text = cell['source']
    return text if isinstance(text, str) else ''.join(text)


# ------------------------------------------------------------------------- the class
PROBE = ('import glob, json, os, sys, matplotlib; print(json.dumps({k: os.environ.get(k) for k in '
         '("ROS_DOMAIN_ID", "ROS2NB_WORKSPACE", "HOME")} | {"prefix": sys.prefix, '
         '"cwd": os.getcwd(), "font lists": glob.glob(matplotlib.get_cachedir() + '
         '"/fontlist-*.json")}))')


@dataclass
class ClassRun:
    """What each learner's kernel printed: the environment probe and every code cell."""

    hub: Hub
    probes: dict[str, dict]
    outputs: dict[str, list[list[dict]]]
    cells: list[dict]
    seconds: float


async def run_in_lockstep(kernels: dict[str, Kernel], cells: list[dict]) -> dict[str, list]:
    """Run every cell in all kernels at once; the next cell starts when all have finished."""
    outputs: dict[str, list] = {learner: [] for learner in kernels}
    for cell in cells:
        done = await asyncio.gather(*(k.execute(source(cell)) for k in kernels.values()))
        for learner, cell_outputs in zip(kernels, done):
            outputs[learner].append(cell_outputs)
    return outputs


async def run_class(hub: Hub, tokens: dict[str, str], cells: list[dict]) -> tuple[dict, dict]:
    """Open one kernel per learner, probe its environment, then run the notebook in lockstep."""
    urls = {learner: open_kernel(hub, learner, tokens[learner])[1] for learner in LEARNERS}
    kernels = {learner: await connect(learner, urls[learner], tokens[learner])
               for learner in LEARNERS}
    try:
        probes = {}
        for learner, kernel in kernels.items():
            printed = await kernel.execute(PROBE)
            assert [o['output_type'] for o in printed] == ['stream'], printed
            probes[learner] = json.loads(printed[0]['text'])
        return probes, await run_in_lockstep(kernels, cells)
    finally:
        for kernel in kernels.values():
            kernel.connection.close()


@pytest.fixture(scope='module')
def class_run():
    folder = owned_folder('ros2nb-hub-')
    hub: Optional[Hub] = None
    try:
        began = time.monotonic()
        hub = start_hub(folder)
        for learner in LEARNERS:
            start_server(hub, learner)
        for learner in LEARNERS:
            wait_for(lambda: server_ready(hub, learner), SERVER_START_S,
                     f"{learner}'s server ready", hub, seen=lambda: server_state(hub, learner))
        tokens = {learner: learner_token(hub, learner) for learner in LEARNERS}
        cells = code_cells(NOTEBOOK)
        try:
            probes, outputs = asyncio.run(run_class(hub, tokens, cells))
        except Exception as error:  # noqa: BLE001 - said with what the hub logged
            pytest.fail(f'running the notebook on the hub: {type(error).__name__}: {error}; '
                        f'the hub log ends:\n{hub.log_tail()}')
        yield ClassRun(hub, probes, outputs, cells, time.monotonic() - began)
    finally:
        if hub is not None:
            stop_hub(hub)
        shutil.rmtree(folder, ignore_errors=True)


def test_each_learner_runs_in_the_course_venv_with_own_workspace_and_no_ros_domain(class_run):
    for learner, probe in class_run.probes.items():
        home = class_run.hub.home(learner)
        assert probe['ROS_DOMAIN_ID'] is None, (
            f'{learner}: the hub passed ROS_DOMAIN_ID={probe["ROS_DOMAIN_ID"]} on to the kernel')
        assert probe['HOME'] == str(home)
        assert probe['ROS2NB_WORKSPACE'] == str(home / 'ros2-course' / 'workspace' /
                                                'ROS2_and_RL_Tutorials')
        assert Path(probe['cwd']) == home / 'ros2-course' / 'notebooks'
        assert Path(probe['prefix']).resolve() == (ROOT / '.venv').resolve()
        # Without it, a first plot on a busy server shows "Matplotlib is building the font cache".
        assert probe['font lists'], (
            f"{learner}'s matplotlib font list was not built before the kernel started")


def test_each_learner_has_own_copy_of_the_learner_notebooks(class_run):
    shipped = {p.name: p.read_bytes() for p in (ROOT / 'notebooks').glob('*.ipynb')}
    for learner in LEARNERS:
        copy = class_run.hub.home(learner) / 'ros2-course' / 'notebooks'
        assert {p.name: p.read_bytes() for p in copy.glob('*.ipynb')} == shipped
        monitor = (class_run.hub.home(learner) / 'ros2-course' / 'workspace' /
                   'ROS2_and_RL_Tutorials' / 'src' / 'sensor_simulator' / 'sensor_simulator' /
                   'temperature_subscriber.py')
        assert monitor.is_file(), f"{learner}'s notebook 04 did not write {monitor}"


def test_two_learners_at_once_each_get_the_stored_outputs(class_run):
    differences = []
    for learner, outputs in class_run.outputs.items():
        for number, (cell, got) in enumerate(zip(class_run.cells, outputs)):
            if not compared(cell):
                continue
            want = comparable_outputs(cell.get('outputs', []))
            have = comparable_outputs(got)
            if have != want:
                differences.append(f'{learner}, code cell {number} ({source(cell)[:50]!r}):\n'
                                   + difference(want, have))
    print(f'hub, two servers and notebook 04 twice at once: {class_run.seconds:.0f} s')
    assert not differences, '\n'.join(differences)


def test_each_learner_gets_the_learners_lab_without_instructor_tools(class_run):
    hub = class_run.hub
    for learner in LEARNERS:
        token = learner_token(hub, learner)
        base = f'{hub.url}/user/{learner}'
        headers = {'Authorization': f'token {token}'}
        assert requests.get(f'{base}/formgrader', headers=headers, timeout=API_S).status_code == 404
        page = requests.get(f'{base}/lab', headers=headers, timeout=API_S).text
        config = json.loads(re.search(r'<script id="jupyter-config-data" type="application/json">'
                                      r'(.*?)</script>', page, re.S).group(1))
        assert '@jupyter/nbgrader:create-assignment' in config['disabledExtensions'], learner
        assert config['news'] == {'disabled': True}, learner
