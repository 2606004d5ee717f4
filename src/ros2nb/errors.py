"""The errors ros2nb raises.  Each message says what to do next, in one line.

This module imports nothing of ROS, so the grader and tools can use it without rclpy.

In a notebook every error here shows as its one line, without a traceback through
ros2nb (IPython's ``_render_traceback_`` protocol): the learner's next step is in the
message, and the lines of ros2nb would only hide it.
"""

from __future__ import annotations


#: What a learner is told whenever ROS was shut down under ros2nb in their kernel.
SHUT_DOWN_MESSAGE = ('ROS 2 was shut down in this kernel (rclpy.shutdown() was called): run '
                     'ros2nb.shutdown(); ros2nb.start() to bring it back, then re-run the cells '
                     'that create your nodes.')


class _OneLine:
    """Mixin: IPython shows ``Type: message`` and nothing else."""

    def _render_traceback_(self) -> list[str]:
        return [f'{type(self).__name__}: {self}']


class Ros2nbError(_OneLine, RuntimeError):
    """A ros2nb call could not be done; the message says what to do next."""


class ColconBuildError(Ros2nbError):
    """``colcon build`` failed; the message is the first cause found in its output."""


class FileProtectedError(Ros2nbError):
    """ros2nb refused to overwrite a file you changed."""


class DomainsExhaustedError(Ros2nbError):
    """Every safe ROS domain on this machine is held by another course kernel."""


class CheckFailed(_OneLine, AssertionError):
    """A check of your work did not pass; the message says what to change."""


class NotDecided(_OneLine, RuntimeError):
    """A check could not decide, for a reason that is not your code's: something it waited
    for from the grader's own side (its processes, its clock, ROS discovery between them)
    never came on a machine too busy to bring it.  Nothing is wrong with your code yet: the
    check runs again by itself (:data:`ros2nb.checks.NOT_DECIDED_TRIES` times in all), and
    says so when it still could not decide.

    Not a :class:`CheckFailed`: no check may take it for the learner's failure and word it
    as one.
    """


class LearnerCodeError(CheckFailed):
    """Your own code raised while a check ran it; shown with its traceback (your lines only).

    :ivar traceback_lines: Python's traceback text limited to frames in your code, ending
        with the ``Type: message`` line, as a list of lines.
    """

    def __init__(self, message: str, traceback_lines: list[str]) -> None:
        super().__init__(message)
        self.traceback_lines = list(traceback_lines)

    def _render_traceback_(self) -> list[str]:
        return [*self.traceback_lines, f'{type(self).__name__}: {self}']


class PkgCreateError(Exception):
    """``ros2 pkg create`` would refuse (or :func:`ros2nb.pkg_create` cannot reproduce) the request.

    The message is the text the command line prints; nothing has been created.
    """

    def _render_traceback_(self) -> list[str]:
        return str(self).strip('\n').splitlines()


class UsageError(_OneLine, ValueError):
    """A ros2nb function got an argument it cannot use; the message says what to pass."""
