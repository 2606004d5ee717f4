"""A real JupyterHub for the tests, loaded with the course's own config: started, stopped.

Everything is real: JupyterHub from the course's venv with ``environment/jupyterhub_config.py``
(and so its hand-in service), configurable-http-proxy as ``make hub-proxy`` installs it.  For a
test, ``DummyAuthenticator`` and ``SimpleLocalProcessSpawner`` replace ``make hub``'s PAM and
``LocalProcessSpawner``: every learner runs as the user running pytest, each with a home
folder of their own in the hub's temporary folder.  The hub listens on free ports of
127.0.0.1; its state and hand-in store live in its folder.  :func:`problem` says in one line
why no hub can be started here (no proxy), for a test to skip.

Used by ``tests/test_jupyterhub.py`` (two learners run a notebook at once) and
``tests/test_hub_term.py`` (a term in the browser).
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
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

import pytest
import requests
from waiting import PATIENCE_S, wait_for as poll

ROOT = Path(__file__).resolve().parent.parent
PROXY = ROOT / '.cache' / 'node' / 'node_modules' / '.bin' / 'configurable-http-proxy'
COURSE_CONFIG = ROOT / 'environment' / 'jupyterhub_config.py'
JUPYTERHUB = Path(sys.executable).with_name('jupyterhub')
LEARNERS = ('ada', 'grace')
#: Seconds for the hub to answer, for a server to start, for one cell or one API call:
#: waits that end as soon as their state is there, so a generous bound costs nothing.
HUB_START_S = SERVER_START_S = CELL_S = API_S = PATIENCE_S
#: Variables of the test's environment the hub must not see (conftest.py sets them).
NOT_FOR_THE_HUB = ('ROS_DOMAIN_ID', 'ROS2NB_WORKSPACE')



def problem() -> Optional[str]:
    """Why no JupyterHub can be started here, in one line (None when one can)."""
    if not (os.access(PROXY, os.X_OK) and shutil.which('node')):
        return ('configurable-http-proxy is not installed (make hub-proxy needs node, npm and '
                'the npm registry): no JupyterHub to test.')
    return None


@dataclass
class Hub:
    """A running JupyterHub of this test.

    :ivar url: its public URL (the proxy), e.g. ``http://127.0.0.1:40123``.
    :ivar token: the API token of the test's admin service.
    :ivar folder: its temporary folder (config, state, log, the learners' homes).
    :ivar process: the ``jupyterhub`` process.
    """

    url: str
    token: str
    folder: Path
    process: subprocess.Popen

    @property
    def log(self) -> Path:
        return self.folder / 'jupyterhub.log'

    def home(self, learner: str) -> Path:
        return self.folder / 'home' / learner

    def log_tail(self, lines: int = 40) -> str:
        """Return the end of the hub's log (its servers write there too), without the
        proxy's entries: once the hub is gone the proxy logs an error per request, and those
        would fill the tail and hide why the hub went (as when a hub exited 1 at start-up
        beside two CPU burners and its log tail held only the proxy's errors)."""
        text = self.log.read_text(errors='replace') if self.log.exists() else ''
        kept, proxy, dropped = [], False, 0
        for line in text.splitlines():
            if '[ConfigProxy]' in line:
                proxy = True
            elif line.startswith('['):  # the hub's and its servers' own entries: [E 2026-...
                proxy = False
            if proxy:
                dropped += 1
            else:
                kept.append(line)
        note = [f'({dropped} lines of the proxy left out)'] if dropped else []
        return '\n'.join(kept[-lines:] + note)

    def api(self, method: str, path: str, **kwargs) -> requests.Response:
        """Call the Hub's REST API (``/hub/api<path>``) as the test's admin service."""
        return requests.request(method, f'{self.url}/hub/api{path}', timeout=API_S,
                                headers={'Authorization': f'token {self.token}'}, **kwargs)


# ----------------------------------------------------------------------------- the hub
def free_port() -> int:
    """Return a TCP port of 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as probe:
        probe.bind(('127.0.0.1', 0))
        return probe.getsockname()[1]


def write_config(folder: Path, token: str, extra: str = '') -> Path:
    """Write the test's hub config: the course's, with a test login, spawner and ports, and
    ``extra`` (config lines) after them."""
    config = folder / 'jupyterhub_test_config.py'
    extra_args = ['--allow-root'] if os.geteuid() == 0 else []
    config.write_text(f'''\
c = get_config()
load_subconfig({str(COURSE_CONFIG)!r})
# Test only: any listed name logs in, and every server runs as the user running pytest.
c.JupyterHub.authenticator_class = 'dummy'
c.Authenticator.allowed_users = {set(LEARNERS)!r}
c.JupyterHub.spawner_class = 'simple'
c.SimpleLocalProcessSpawner.home_dir_template = {str(folder / 'home' / '{username}')!r}
c.Spawner.args = c.Spawner.args + {extra_args!r}
c.JupyterHub.bind_url = 'http://127.0.0.1:{free_port()}'
c.JupyterHub.hub_bind_url = 'http://127.0.0.1:{free_port()}'
c.ConfigurableHTTPProxy.api_url = 'http://127.0.0.1:{free_port()}'
# A server that is merely slow to start (a busy machine) is not a failure: the hub's own
# limits get the test's patience; POST .../server answers 202 after slow_spawn_timeout.
c.Spawner.start_timeout = c.Spawner.http_timeout = {int(SERVER_START_S)}
c.JupyterHub.services = c.JupyterHub.services + [{{'name': 'hub-test', 'api_token': {token!r}}}]
c.JupyterHub.load_roles = [{{'name': 'hub-test', 'services': ['hub-test'],
                            'scopes': ['admin:users', 'admin:servers', 'tokens']}}]
''' + extra)
    return config


def hub_environment(folder: Path) -> dict[str, str]:
    """Return this process's environment without a ROS domain or workspace, state (and the
    hand-in store) in ``folder``, the hand-in service on a free port."""
    env = {k: v for k, v in os.environ.items() if k not in NOT_FOR_THE_HUB}
    env['ROS2_COURSE_HUB_STATE'] = str(folder / 'state')
    env['ROS2_COURSE_HUB_HANDED_IN'] = str(folder / 'handed-in')
    env['ROS2_COURSE_HUB_HAND_IN_PORT'] = str(free_port())
    return env


def wait_for(check: Callable[[], object], seconds: float, what: str, hub: Hub,
             seen: Optional[Callable[[], object]] = None) -> None:
    """Poll ``check`` until it is true; fail with ``what``, what was seen and the hub's log."""
    def done() -> object:
        if hub.process.poll() is not None:
            pytest.fail(f'JupyterHub exited ({hub.process.returncode}) while waiting for '
                        f'{what}; its log ends:\n{hub.log_tail()}')
        return check()

    try:
        poll(done, what, seconds=seconds, seen=seen, interval=0.2)
    except AssertionError as error:
        pytest.fail(f'{error}; the hub log ends:\n{hub.log_tail()}')


def answers(hub: Hub) -> bool:
    """True once the Hub's API answers through the proxy."""
    try:
        return hub.api('GET', '/').status_code == 200
    except requests.RequestException:
        return False


def start_hub(folder: Path, extra: str = '') -> Hub:
    """Start JupyterHub in ``folder`` (with ``extra`` config lines) and wait until its API
    answers through the proxy."""
    token = secrets.token_hex(32)
    config = write_config(folder, token, extra)
    url = re.search(r"bind_url = '(http://[^']+)'", config.read_text()).group(1)
    with open(folder / 'jupyterhub.log', 'wb') as log:
        process = subprocess.Popen([str(JUPYTERHUB), '-f', str(config)], cwd=folder,
                                   env=hub_environment(folder), stdout=log,
                                   stderr=subprocess.STDOUT, start_new_session=True)
    hub = Hub(url=url, token=token, folder=folder, process=process)
    try:
        wait_for(lambda: answers(hub), HUB_START_S, 'JupyterHub answering through the proxy', hub)
    except BaseException:  # the caller never gets the hub to stop: stop it (and its proxy) here
        stop_hub(hub)
        raise
    return hub


def start_server(hub: Hub, learner: str) -> None:
    """Create ``learner`` and ask the hub to start their server (does not wait for it)."""
    created = hub.api('POST', f'/users/{learner}')
    assert created.status_code in (201, 409), f'creating {learner}: {created.text}'
    started = hub.api('POST', f'/users/{learner}/server')
    assert started.status_code in (201, 202), f'starting {learner}: {started.text}'


def server_state(hub: Hub, learner: str) -> dict:
    """The hub's model of ``learner``'s default server (``ready``, ``pending``, ...), or {}."""
    try:
        return hub.api('GET', f'/users/{learner}').json().get('servers', {}).get('', {})
    except requests.RequestException as error:  # the hub is busy: say so, poll again
        return {'unreachable': str(error)[:200]}


def server_ready(hub: Hub, learner: str) -> bool:
    """True once the hub reports ``learner``'s server as ready."""
    return bool(server_state(hub, learner).get('ready'))


def learner_token(hub: Hub, learner: str) -> str:
    """Return a new API token of ``learner``'s own (what their browser session would carry)."""
    issued = hub.api('POST', f'/users/{learner}/tokens',
                     json={'note': 'tests/test_jupyterhub.py', 'expires_in': 900})
    assert issued.status_code == 201, f'token for {learner}: {issued.text}'
    return issued.json()['token']


def processes_in(folder: Path) -> list[int]:
    """Return the ids of processes whose working folder is inside ``folder``."""
    found = []
    for entry in Path('/proc').iterdir():
        if not entry.name.isdigit():
            continue
        try:
            cwd = Path(os.readlink(entry / 'cwd'))
        except OSError:
            continue
        if cwd == folder or folder in cwd.parents:
            found.append(int(entry.name))
    return found


def stop_hub(hub: Hub) -> None:
    """Stop the servers, then the hub (and its proxy); kill whatever of this test is left."""
    for learner in LEARNERS:
        try:
            hub.api('DELETE', f'/users/{learner}/server')
        except requests.RequestException:
            pass  # the hub is gone already; what is left is killed below
    hub.process.send_signal(signal.SIGTERM)
    try:
        hub.process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        os.killpg(hub.process.pid, signal.SIGKILL)
        hub.process.wait()
    for pid in processes_in(hub.folder):
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


