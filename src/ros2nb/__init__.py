"""ros2nb: run real ROS 2 Jazzy nodes inside a Jupyter kernel, for the pub/sub course.

Importing ``ros2nb`` does nothing by itself: call :func:`start` to bring ROS up.
Each public function names the notebook that introduces it in its docstring.
"""

from . import checks, course, domains
from .errors import (CheckFailed, ColconBuildError, DomainsExhaustedError, FileProtectedError,
                     LearnerCodeError, PkgCreateError, Ros2nbError, UsageError)
from .graph import (message_type, node_list, record, topic_echo, topic_hz, topic_info,
                    topic_list, unmatched_topics)
from .pkg_create import pkg_create
from .runtime import add, current_runtime, shutdown, spin, start, stop
from .workspace import (colcon_build, create_workspace, current_workspace, find_executable,
                        import_file, ros2_run, run_and_interrupt, source_workspace, tree,
                        write_file, write_part)


def load_ipython_extension(ipython) -> None:
    """``%load_ext ros2nb``: the ``%%part FILE N`` cell magic and one-line errors (notebook 03)."""
    from .kernel import install
    install(ipython)


__all__ = [
    'CheckFailed', 'ColconBuildError', 'DomainsExhaustedError', 'FileProtectedError',
    'LearnerCodeError', 'PkgCreateError', 'Ros2nbError', 'UsageError', 'add', 'checks',
    'colcon_build', 'course', 'create_workspace', 'current_runtime', 'current_workspace',
    'domains', 'find_executable', 'import_file', 'message_type', 'node_list', 'pkg_create',
    'record', 'ros2_run', 'run_and_interrupt', 'shutdown', 'source_workspace', 'spin', 'start',
    'stop', 'topic_echo', 'topic_hz', 'topic_info', 'topic_list', 'tree', 'unmatched_topics',
    'write_file', 'write_part',
]
