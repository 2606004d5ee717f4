"""ros2nb: run real ROS 2 Jazzy nodes inside a Jupyter kernel, for the pub/sub course.

Importing ``ros2nb`` does nothing by itself: call :func:`start` to bring ROS up.
Each public function names the notebook that introduces it in its docstring.
"""

from . import checks, course
from .graph import (message_type, node_list, record, topic_echo, topic_hz, topic_info,
                    topic_list, unmatched_topics)
from .checks import CheckFailed
from .pkg_create import PkgCreateError, pkg_create
from .runtime import Ros2nbError, add, runtime, shutdown, spin, start, stop
from .workspace import (ColconBuildError, FileProtectedError, colcon_build, create_workspace,
                        find_executable, import_file, ros2_run, run_and_interrupt, source_workspace, tree, workspace,
                        write_file, write_part)


def load_ipython_extension(ipython) -> None:
    """``%load_ext ros2nb`` registers the ``%%part FILE N`` cell magic (notebook 03)."""
    from .magics import load_ipython_extension as load
    load(ipython)

__all__ = [
    'CheckFailed', 'ColconBuildError', 'PkgCreateError', 'FileProtectedError', 'Ros2nbError', 'add', 'colcon_build',
    'create_workspace', 'find_executable', 'import_file', 'message_type', 'node_list', 'pkg_create',
    'record', 'ros2_run', 'run_and_interrupt', 'runtime', 'shutdown', 'source_workspace', 'spin', 'start', 'stop',
    'topic_echo', 'topic_hz', 'topic_info', 'topic_list', 'tree', 'unmatched_topics',
    'workspace', 'write_file', 'write_part',
]
