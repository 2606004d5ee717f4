"""Real ROS 2 nodes inside a Jupyter kernel: one context, one executor thread, one clock.

Runs in the learner's kernel, and in a check's subject (which makes a runtime of its own).
:class:`Runtime` (``core``) is made of its log lines (``logs``), its executor thread
(``spinning``), its nodes (``nodes``) and its clock (``clock``); ``current`` holds the
kernel's one runtime.  The learner's verbs (``start``, ``add``, ``spin``) are in
:mod:`ros2nb.kernel`.
"""

from .core import (INTERNAL_NODE_NAME, QUIET_SUBSCRIPTION, Runtime, enable_field_checks,
                   node_serving_nothing)
from .current import current_runtime, kernel_runtime
from .logs import CallbackFailure
from .nodes import NodeOrName

__all__ = ['CallbackFailure', 'INTERNAL_NODE_NAME', 'NodeOrName', 'QUIET_SUBSCRIPTION',
           'Runtime', 'current_runtime', 'enable_field_checks', 'kernel_runtime',
           'node_serving_nothing']
