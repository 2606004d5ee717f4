"""Waiting in tests: poll for the state a test needs, never sleep for a guessed time.

Every wait in ``tests/`` ends as soon as its state is there; the bound only matters when
the state never comes (then the test fails and says what it last saw).  All bounds derive
from :data:`PATIENCE_S`, so a slow machine needs one knob, not thirty.
"""

from __future__ import annotations

import os
import time
from typing import Any, Callable, Optional

#: The longest a test waits for a state that should come (s). Generous: on a machine
#: with other work going on, starting a kernel or a JupyterHub server can take a minute.
PATIENCE_S = float(os.environ.get('ROS2NB_TEST_PATIENCE_S', '180'))


def wait_until(condition: Callable[[], Any], seconds: float = PATIENCE_S,
               interval: float = 0.02) -> bool:
    """Poll ``condition()`` until it is true; return False if ``seconds`` pass first."""
    deadline = time.monotonic() + seconds
    while True:
        if condition():
            return True
        if time.monotonic() > deadline:
            return False
        time.sleep(interval)


def wait_for(condition: Callable[[], Any], what: str, *, seconds: float = PATIENCE_S,
             seen: Optional[Callable[[], Any]] = None, interval: float = 0.05) -> Any:
    """Poll ``condition()`` until it returns something true, and return that.

    :param what: the state waited for, e.g. ``"ada's server ready"``.
    :param seen: describes what was there instead, for the failure message.
    :raises AssertionError: ``what: not after N s; last seen: ...`` when time runs out.
    """
    deadline = time.monotonic() + seconds
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            last = seen() if seen is not None else value
            raise AssertionError(f'{what}: not after {seconds:g} s; last seen: {last!r}')
        time.sleep(interval)
