"""What ros2nb adds to an IPython kernel: ``%%part``, one-line errors, logs in their cell.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.  :func:`ros2nb.start` installs it in
a notebook; ``%load_ext ros2nb`` does too (notebook 05 runs no ROS in the kernel).
Runs in the learner's kernel.

- ``rclpy.spin(node)``, ``executor.spin()`` and ``spin_until_future_complete`` without a
  timeout, in a cell, say what to use instead of blocking the kernel.
- ``%%part FILE N [--overwrite]`` saves the cell as part N of FILE (:func:`ros2nb.write_part`).
- Known beginner mistakes raised through rclpy or a message class show as one line
  naming the learner's own line (:mod:`ros2nb.explain`); other errors keep their normal
  traceback, and ros2nb's own errors show as their one line.
- Log lines a cell's nodes made are printed at the end of that cell; lines made while no
  cell was running are counted, not shown later as if they were new.

All of it goes through IPython's own machinery: a registered cell magic, ``set_custom_exc``
and the ``pre_run_cell`` / ``post_run_cell`` events.
"""

from __future__ import annotations

import re
import shlex
import sys
import threading
from typing import Any, Optional

import rclpy
from rclpy.executors import Executor

from ..errors import Ros2nbError, UsageError
from ..explain.exceptions import explain_exception, learner_line
from ..runtime import kernel_runtime
from ..terminal.files import write_part

_INSTALLED = '_ros2nb_installed'
_original_spin = rclpy.spin
_original_executor_spin = Executor.spin
_original_until_complete = Executor.spin_until_future_complete
#: What to do instead of blocking a cell, for every spin that would.
_INSTEAD = ('hand the node over with ros2nb.add(node) and let it run with '
            'ros2nb.spin(seconds)')


def _spin_in_a_cell(node: Any, executor: Any = None) -> None:
    """``rclpy.spin`` in a kernel: from a cell it explains instead of blocking the kernel."""
    if threading.current_thread() is threading.main_thread():
        first = ('' if kernel_runtime() is not None else
                 'run ros2nb.start() instead of rclpy.init(), then ')
        raise Ros2nbError('rclpy.spin(node) never returns in a notebook cell (it would block the '
                          f'kernel until you press Stop): {first}hand the node over with '
                          'ros2nb.add(node) and let it run with ros2nb.spin(seconds).')
    return _original_spin(node, executor)


def _executor_spin_in_a_cell(executor: Executor) -> None:
    """``Executor.spin`` in a kernel: from a cell it explains instead of blocking the kernel
    (the executor of notebook 06 included; its threads spin as before)."""
    if threading.current_thread() is threading.main_thread():
        raise Ros2nbError('executor.spin() never returns in a notebook cell (it would block the '
                          f'kernel until you press Stop): {_INSTEAD}; to watch an executor at '
                          'work for a while, ros2nb.timer_runs(node, executor, seconds).')
    return _original_executor_spin(executor)


def _until_complete_in_a_cell(executor: Executor, future: Any,
                              timeout_sec: Optional[float] = None) -> None:
    """``spin_until_future_complete`` with no timeout, in a cell: explains instead of
    blocking the kernel until a future that may never complete does."""
    if threading.current_thread() is threading.main_thread() and (
            timeout_sec is None or timeout_sec < 0):
        raise Ros2nbError('spin_until_future_complete(...) without timeout_sec blocks the cell '
                          'until the future is done, which may be never: give it a limit, '
                          'timeout_sec=5.0, then check future.done(); or '
                          f'{_INSTEAD}.')
    return _original_until_complete(executor, future, timeout_sec)


def part(line: str, cell: str) -> None:
    """``%%part FILE N [--overwrite]``: save this cell as part N of FILE.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises UsageError: if the line is not ``FILE N``, or FILE is an unexpanded ``{NAME}``.
    """
    words = shlex.split(line)
    overwrite = '--overwrite' in words
    words = [w for w in words if w != '--overwrite']
    unexpanded = re.fullmatch(r'\{(\w+)\}', words[0]) if words else None
    if unexpanded:
        raise UsageError(f'{unexpanded.group(1)} is not defined in this kernel: run the cell near '
                         f'the top that sets {unexpanded.group(1)}, then this one again.')
    if len(words) != 2 or not words[1].isdigit():
        raise UsageError('Usage: %%part FILE N [--overwrite], e.g. '
                         '%%part src/sensor_simulator/sensor_simulator/temperature_publisher.py 1')
    write_part(words[0], int(words[1]), cell, overwrite=overwrite)


def _before_cell(_info: Any = None) -> None:
    rt = kernel_runtime()
    if rt is not None:
        rt.begin_cell()


def _after_cell(_result: Any = None) -> None:
    rt = kernel_runtime()
    if rt is not None and rt.alive:
        rt.print_pending()


def _explain(shell: Any, etype: type, value: BaseException, tb: Any,
             tb_offset: Optional[int] = None) -> None:
    """IPython custom exception handler: one line for known mistakes, else the usual display."""
    try:
        line = explain_exception(value, ros_started=kernel_runtime() is not None)
    except Exception:  # explaining must never hide the original error
        line = None
    if line is None:
        shell.showtraceback((etype, value, tb), tb_offset=tb_offset)
        return
    where = learner_line(value)
    shell._showtraceback(etype, value, [f'{etype.__name__} ({where}): {line}' if where
                                        else f'{etype.__name__}: {line}'])


def install(ip: Any = None) -> bool:
    """Install ros2nb's IPython additions once; return False outside IPython.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.
    """
    if ip is None:  # IPython is imported wherever it runs; ros2nb never imports it itself
        loaded = sys.modules.get('IPython')
        ip = loaded.get_ipython() if loaded is not None else None
    if ip is None:
        return False
    if getattr(ip, _INSTALLED, False):
        return True
    ip.register_magic_function(part, magic_kind='cell', magic_name='part')
    ip.events.register('pre_run_cell', _before_cell)
    ip.events.register('post_run_cell', _after_cell)
    ip.set_custom_exc((Exception,), _explain)
    rclpy.spin = _spin_in_a_cell
    setattr(Executor, 'spin', _executor_spin_in_a_cell)
    setattr(Executor, 'spin_until_future_complete', _until_complete_in_a_cell)
    setattr(ip, _INSTALLED, True)
    return True
