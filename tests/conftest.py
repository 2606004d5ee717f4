"""The tests' lanes, and the fixtures more than one test module uses.

Lanes (docs/developing.md): every test that needs more than Python carries the marker of
its kind (:data:`KINDS`).  ``pytest --lane check`` (``make check``) runs the tests that carry
none of them; ``pytest --lane slow`` the others (``make test`` runs both lanes).  A test in
the check lane that brings ROS up or starts a kernel anyway fails, naming the marker it
lacks: the lane stays quick because nothing in it can quietly start what the markers name.
"""

from __future__ import annotations

from typing import Iterator

import pytest

import ros2nb
from ros2nb import domains
from ros2nb.judge.session import Session

from browser import module_chromium, page  # noqa: F401 - fixtures for every module
from docs_site import site  # noqa: F401 - the built website, for its browser tests
from judging import judge_session

#: The kinds of slow test, each a marker: what the test needs besides Python.
KINDS = {
    'ros': 'real rclpy nodes over DDS, or ROS programs and colcon builds, in or beside this '
           'process',
    'kernel': 'a real Jupyter kernel (or a Jupyter server that starts one)',
    'judge': 'the judge with its subject processes',
    'sandbox': 'bubblewrap sandboxes or root-only mounts, as the grader makes them',
    'browser': "Debian's chromium driven by Playwright",
    'image': "the course's image built and run with podman",
    'hub': 'a real JupyterHub with its proxy',
}
#: The marker expression of each lane.
LANES = {'check': f'not ({" or ".join(KINDS)})', 'slow': ' or '.join(KINDS)}


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption('--lane', choices=sorted(LANES),
                     help='check: the tests that need only Python (make check); slow: the '
                          'ones marked with a kind: ' + ', '.join(KINDS))


def pytest_configure(config: pytest.Config) -> None:
    for kind, needs in KINDS.items():
        config.addinivalue_line('markers', f'{kind}: {needs}')
    lane = config.getoption('--lane')
    if lane:
        given = config.option.markexpr
        config.option.markexpr = f'({given}) and ({LANES[lane]})' if given else LANES[lane]


@pytest.fixture(autouse=True)
def _stays_in_its_lane(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory,
                       monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """In the check lane, a test that claims a ROS domain (every process that brings ROS up
    through the course does: the lock file stays) or starts a Jupyter kernel (IPython makes
    its profile folder) fails and names the marker it lacks."""
    if request.config.getoption('--lane') != 'check':
        yield
        return
    locks = tmp_path_factory.mktemp('lane-domain-locks')
    ipython = tmp_path_factory.mktemp('lane-ipython')
    monkeypatch.setenv(domains.LOCKS_ENV, str(locks))
    monkeypatch.delenv(domains.DOMAIN_ENV, raising=False)  # so that bringing ROS up claims one
    monkeypatch.setenv('IPYTHONDIR', str(ipython))
    yield
    started = [kind for kind, found in (('ros', any(locks.glob('*.lock'))),
                                        ('kernel', any(ipython.iterdir()))) if found]
    if started:
        pytest.fail(f'{request.node.nodeid} started {" and ".join(started)} in the check lane: '
                    f'mark it @pytest.mark.{started[0]} (tests/conftest.py: KINDS)', pytrace=False)


@pytest.fixture(scope='module')
def session(request: pytest.FixtureRequest,
            tmp_path_factory: pytest.TempPathFactory) -> Iterator[Session]:
    """A judge session (this process is the judge) on a fresh workspace caught up to the
    notebook the test module names in ``CAUGHT_UP_TO`` (default 5: the course's package)."""
    notebook = getattr(request.module, 'CAUGHT_UP_TO', 5)
    with judge_session(tmp_path_factory.mktemp(f'judge{notebook:02d}'), notebook) as judge:
        yield judge


@pytest.fixture
def ros() -> Iterator[object]:
    """ros2nb started in this process on simulated time, as a notebook starts it; shut down
    afterwards."""
    runtime = ros2nb.start(sim_time=True)
    yield runtime
    ros2nb.shutdown()
