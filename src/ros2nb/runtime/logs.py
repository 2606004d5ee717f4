"""The kernel's log lines: read back from ``/rosout``, printed in the cell that made them.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`LogLines` side of it).  The nodes'
console output is off; their lines come back over ``/rosout`` (what rqt_console reads) and
are printed, by the thread that asks, in the ROS console format without timestamps.
"""

from __future__ import annotations

import collections
import sys
import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # only the type: this module imports no ROS
    from rcl_interfaces.msg import Log

#: Log lines kept while no cell is reading them; older ones are counted, not kept.
MAX_PENDING_LOG_LINES = 2000
#: rcl_interfaces/msg/Log levels -> the console's severity names.
SEVERITY_NAMES = {10: 'DEBUG', 20: 'INFO', 30: 'WARN', 40: 'ERROR', 50: 'FATAL'}
#: A stamp later than any line's: muted until the next spin starts (LogLines.mute_cell).
_UNTIL_NEXT_SPIN = 2 ** 63


@dataclass(frozen=True)
class CallbackFailure:
    """A callback that raised inside the executor.

    :ivar node: fully qualified name of the node whose callback raised.
    :ivar callback: qualified name of the callback, e.g.
        ``TemperatureMonitor.temperature_callback``.
    :ivar error: ``ExceptionType: message``, or ros2nb's one-line explanation of it.
    :ivar where: the learner's own line, ``FILE line N: source``; empty when none was found.
    :ivar kind: the exception's type name, e.g. ``NameError``.
    :ivar explained: True when ``error`` is ros2nb's explanation (else Python's own words).
    :ivar traceback: the traceback through the learner's own frames (lines).
    """

    node: str
    callback: str
    error: str
    where: str
    kind: str = ''
    explained: bool = False
    traceback: tuple[str, ...] = ()

    def __str__(self) -> str:
        text = (f'[ERROR] [{self.node.lstrip("/")}]: callback {self.callback} raised '
                f'{self.error}')
        if self.where:
            text += f'\n    {self.where}'
        return (text + f'\n    ros2nb stopped node {self.node}; the other nodes keep running. '
                'Fix the callback, re-run the cell that creates the node and hand it over again.')


class LogLines:
    """The log lines of the nodes handed over, and the cell each belongs to."""

    def __init__(self) -> None:
        self._our_loggers: set[str] = set()
        #: /rosout lines received so far, per logger name, from every process on the domain.
        self.log_counts: collections.Counter[str] = collections.Counter()
        # (cell epoch, logger name | None for our own lines | CallbackFailure, level,
        # text | the CallbackFailure, stamp ns): the second and fourth vary with the kind
        self._log_lines: collections.deque[tuple[int, Any, int, Any, int]] = collections.deque()
        self._overflow = 0
        self._epoch = 0
        # (epoch, wall-clock ns): lines of that cell stamped before then are not shown
        self._muted: tuple[int, int] = (-1, 0)
        self._lock = threading.Lock()
        #: Every callback that raised, in order (a judge's subject tells the judge the first).
        self.failures: list[CallbackFailure] = []

    def own_logger(self, name: str) -> None:
        """Show the lines of logger ``name`` (a node handed over) and of its children."""
        self._our_loggers.add(name)

    def disown_loggers_except(self, running: set[str]) -> None:
        """Stop showing the lines of loggers whose nodes were stopped (``running``: those kept).

        A process on this domain may run a node of the same name (``ros2nb.ros2_start``); its
        lines reach this kernel's /rosout too, and are not this kernel's to print.
        """
        with self._lock:
            self._our_loggers &= running

    def mute_cell(self, *, until_next_spin: bool = False) -> None:
        """Show none of the running cell's log lines made until now (an interrupted spin):
        those still on their way over /rosout are dropped, a later spin's are shown.
        /rosout stamps every line with the wall clock, in simulated time too.

        :param until_next_spin: also drop the cell's lines made from now until its next spin
            starts (:meth:`begin_spin`): nodes on the wall clock keep running after a spin.
        """
        self._muted = (self._epoch, _UNTIL_NEXT_SPIN if until_next_spin else time.time_ns())

    def begin_spin(self) -> None:
        """A spin starts: lines muted until it (:meth:`mute_cell`) are shown from now on."""
        if self._muted == (self._epoch, _UNTIL_NEXT_SPIN):
            self._muted = (self._epoch, time.time_ns())

    def begin_cell(self) -> None:
        """A new cell starts: lines made before it are no longer news (IPython pre_run_cell)."""
        self._epoch += 1

    def _on_log(self, msg: Log) -> None:
        """Take one /rosout message (the subscription's callback)."""
        with self._lock:
            self.log_counts[msg.name] += 1
            if len(self._log_lines) >= MAX_PENDING_LOG_LINES:
                self._log_lines.popleft()
                self._overflow += 1
            stamp_ns = msg.stamp.sec * 1_000_000_000 + msg.stamp.nanosec
            self._log_lines.append((self._epoch, msg.name, msg.level, msg.msg, stamp_ns))

    def emit(self, text: str) -> None:
        """Queue a line of our own (e.g. an echoed message) in order with the log lines."""
        with self._lock:
            self._log_lines.append((self._epoch, None, 0, text, time.time_ns()))

    def _report_failure(self, failure: CallbackFailure) -> None:
        """Queue a callback that raised, to be shown with the lines of its cell."""
        self.failures.append(failure)
        with self._lock:
            self._log_lines.append((self._epoch, CallbackFailure, 0, failure, time.time_ns()))

    def is_ours(self, logger_name: str) -> bool:
        """True for the loggers of nodes handed over (and their child loggers)."""
        return any(logger_name == n or logger_name.startswith(n + '.')
                   for n in self._our_loggers)

    def print_pending(self, *, show_logs: bool = True) -> int:
        """Print (from the calling thread) the log lines and callback failures of this cell.

        Lines made while no cell was running (nodes on the wall clock keep running between
        cells) are not shown as if they were new: one line says how many there were.

        :param show_logs: ``False`` hides the log lines; failures are always shown.
        :return: the number of log lines of this cell taken (printed or hidden).
        """
        with self._lock:
            queued, self._log_lines = list(self._log_lines), collections.deque()
            overflow, self._overflow = self._overflow, 0
        earlier = overflow
        taken = 0
        lines: list[str] = []
        for epoch, name, level, text, stamp_ns in queued:
            if name is CallbackFailure:
                sys.stdout.flush()
                print(text, file=sys.stderr)
                sys.stderr.flush()
            elif name is None or self.is_ours(name):
                if epoch < self._epoch:
                    earlier += 1
                    continue
                if (epoch, stamp_ns) <= self._muted:
                    continue
                taken += 1
                lines.append(text if name is None else
                             f'[{SEVERITY_NAMES.get(level, level)}] [{name}]: {text}')
        if earlier:
            lines.insert(0, f'({earlier} log lines made while no cell was running were not shown)')
        if show_logs and lines:
            print('\n'.join(lines))
            # Only after a print: a kernel's flush hands the text to its output thread and
            # waits for it, and a simulated hour asks once per simulated second (a third of it).
            sys.stdout.flush()
        return taken
