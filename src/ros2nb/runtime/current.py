"""The kernel's one runtime: set by :func:`ros2nb.start`, read by everything that needs it.

A process has at most one kernel runtime (a check's subject makes a runtime of its own
and never registers it here).  No ROS import.
"""

from __future__ import annotations

from typing import Any, Optional

from ..errors import Ros2nbError

_runtime: Optional[Any] = None  # a ros2nb.runtime.Runtime


def kernel_runtime() -> Optional[Any]:
    """Return the kernel's runtime, or None when ROS is not up (or no longer) in this kernel."""
    return _runtime


def set_kernel_runtime(runtime: Optional[Any]) -> None:
    """Make ``runtime`` the kernel's (None: there is none); only :mod:`ros2nb.kernel` calls it."""
    global _runtime
    _runtime = runtime


def current_runtime() -> Any:
    """Return the kernel's runtime.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :raises Ros2nbError: if :func:`ros2nb.start` has not been called, or ROS was shut down.
    """
    if _runtime is None:
        raise Ros2nbError('ROS 2 is not up in this kernel yet: run ros2nb.start() first.')
    _runtime.ensure_alive()
    return _runtime


def participant_prefix() -> Optional[bytes]:
    """The kernel's DDS participant prefix, or None while ROS is down (for the guards)."""
    rt = _runtime
    return rt.participant_prefix() if rt is not None and rt.alive else None
