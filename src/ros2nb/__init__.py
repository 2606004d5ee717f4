"""ros2nb: run real ROS 2 Jazzy nodes inside a Jupyter kernel, for the pub/sub course.

Importing ``ros2nb`` does nothing by itself: call :func:`start` to bring ROS up.
Each public function names the notebook that introduces it in its docstring.

Where each part runs (docs/architecture.md): ``kernel``, ``runtime``, ``terminal``,
``explain`` and ``checks`` in the learner's kernel; ``judge`` in a judge process that
decides from outside; ``subject`` in the processes that run the learner's code for the
judge.  The instructor's side is the package ``ros2nb_instructor``.
"""

from . import course, domains, qos
from .errors import (CheckFailed, ColconBuildError, DomainsExhaustedError, FileProtectedError,
                     LearnerCodeError, PkgCreateError, Ros2nbError, UsageError)
from .kernel import add, install, shutdown, spin, start, stop
from .on_first_use import loader
from .runtime import current_runtime
from .runtime.rates import callback_groups, timer_runs
from .temporary import temporary_folder
from .terminal.background import NodeProcess, ros2_start, stop_all
from .terminal.colcon import colcon_build, source_workspace
from .terminal.echo import message_type, record, topic_echo, topic_hz
from .terminal.graph import graph_edges, graph_picture
from .terminal.files import import_file, write_file, write_part
from .terminal.param import param_describe, param_dump, param_get, param_list, param_set
from .terminal.pkg_create import pkg_create
from .terminal.run import find_executable, ros2_run, run_and_interrupt
from .terminal.topic import node_list, topic_info, topic_list, unmatched_topics
from .terminal.workspace import create_workspace, current_workspace, tree


#: Loaded on first use (PEP 562): a process that only runs nodes, such as a judge's subject,
#: never pays for importing the notebooks' checks or rosbags (docs/decisions.md), and never
#: holds the course's rules (an answer) unless asked.
_ON_FIRST_USE = {'checks': 'checks', 'progress': 'checks', 'rules': 'rules',
                 'hand_in': 'hand_ins',
                 'figures': 'figures',
                 'Recording': 'terminal.bag',
                 'bag_info': 'terminal.bag', 'bag_play': 'terminal.bag',
                 'bag_record': 'terminal.bag'}


__getattr__, __dir__ = loader(globals(), _ON_FIRST_USE)


def load_ipython_extension(ipython: object) -> None:
    """``%load_ext ros2nb``: the ``%%part FILE N`` cell magic and one-line errors (notebook 03)."""
    install(ipython)


__all__ = [
    'CheckFailed', 'ColconBuildError', 'DomainsExhaustedError', 'FileProtectedError',
    'LearnerCodeError', 'NodeProcess', 'PkgCreateError', 'Recording', 'Ros2nbError', 'UsageError',
    'add', 'bag_info', 'bag_play', 'bag_record',
    'callback_groups', 'checks', 'colcon_build', 'course', 'create_workspace',
    'current_runtime', 'current_workspace', 'domains', 'figures', 'find_executable', 'graph_edges',
    'graph_picture', 'hand_in', 'import_file', 'message_type', 'node_list', 'param_describe',
    'param_dump', 'param_get', 'param_list', 'param_set', 'pkg_create', 'progress', 'qos',
    'record', 'rules',
    'ros2_run', 'ros2_start', 'run_and_interrupt', 'shutdown', 'source_workspace', 'spin',
    'start', 'stop', 'stop_all', 'temporary_folder', 'timer_runs', 'topic_echo', 'topic_hz',
    'topic_info', 'topic_list', 'tree', 'unmatched_topics', 'write_file', 'write_part',
]
