"""A pytest plugin for ``benchmarks/make_test_profile.py``: when each test starts and ends.

Loaded with ``-p timing_plugin`` (``benchmarks/`` on ``PYTHONPATH``) in every pytest process of
``make test``: xdist's workers and the two nbval passes.  Each writes one JSON line per test
start and end to the file ``$ROS2NB_TEST_CLOCK``: its pid, the test's id, ``time.monotonic()``
and its own CPU seconds so far.  xdist's controller, which runs no test itself, writes none.
"""

from __future__ import annotations

import json
import os
import time
from typing import Any

#: The file the lines go to (nothing is written when it is not set).
LOG_ENV = 'ROS2NB_TEST_CLOCK'
_writing = {'on': False}


def pytest_configure(config: Any) -> None:
    """Write only in processes that run tests (not in xdist's controller)."""
    controller = config.getoption('numprocesses', None) and not hasattr(config, 'workerinput')
    _writing['on'] = bool(os.environ.get(LOG_ENV)) and not controller


def _write(event: str, nodeid: str) -> None:
    if not _writing['on']:
        return
    own = os.times()
    line = {'event': event, 'pid': os.getpid(), 'test': nodeid, 't': time.monotonic(),
            'cpu': own.user + own.system}
    with open(os.environ[LOG_ENV], 'a') as log:
        log.write(json.dumps(line) + '\n')


def pytest_runtest_logstart(nodeid: str, location: Any) -> None:
    """A test starts in this process."""
    _write('start', nodeid)


def pytest_runtest_logfinish(nodeid: str, location: Any) -> None:
    """A test ended in this process."""
    _write('end', nodeid)
