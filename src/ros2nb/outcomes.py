"""A check's outcome as a value: what the judge decided, one type from the judge to the
learner's kernel and to the grader's notebooks, gradebook, feedback pages and report.

Crossing a process it travels as JSON (:func:`dataclasses.asdict`) and is read back with
:func:`ros2nb.typed_json.decoded`, every field checked; its field names are its JSON keys.
The judge makes it (:func:`ros2nb.judge_interface.captured`); nothing else writes one.  No
ROS import.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs in a judge).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

#: :attr:`CheckOutcome.type` of a check that failed on what the learner wrote.
CHECK_FAILED = 'CheckFailed'
#: ... whose failure is an error the learner's code raised (its frames in ``traceback``).
LEARNER_CODE_ERROR = 'LearnerCodeError'
#: ... that could not decide (:class:`~ros2nb.errors.NotDecided`): no fault of the learner's.
NOT_DECIDED = 'NotDecided'


@dataclass(frozen=True)
class CheckOutcome:
    """What the judge decided about one check, or one graded cell (its checks in turn, up to
    the first that failed): the one value a verdict is made of, from the judge to the
    learner's kernel (one JSON line, :func:`show_result`), to the grader's notebook, gradebook,
    feedback pages and report.  Decoded with :func:`ros2nb.typed_json.decoded` wherever it
    crosses a process; its field names are its JSON keys.

    :ivar passed: whether it passed.
    :ivar lines: what the checks printed, one string per line.
    :ivar type: for a failure, :data:`CHECK_FAILED`, :data:`LEARNER_CODE_ERROR` or
        :data:`NOT_DECIDED`; None when it passed.
    :ivar message: for a failure, its one line; None when it passed.
    :ivar traceback: for :data:`LEARNER_CODE_ERROR`, the learner's frames, one string each.
    """

    passed: bool
    lines: tuple[str, ...] = ()
    type: Optional[str] = None
    message: Optional[str] = None
    traceback: tuple[str, ...] = ()

    @property
    def undecided(self) -> bool:
        """Whether the check could not decide (not the learner's failure)."""
        return not self.passed and self.type == NOT_DECIDED


@dataclass(frozen=True)
class CellChecked:
    """The line a grading judge prints as soon as one graded cell is decided (what a judge
    stopped at a limit still scores), read by the grader."""

    cell: str  #: the graded cell's nbgrader id
    result: CheckOutcome
    cpu_s: float  #: CPU seconds the judge's process tree spent on it


@dataclass(frozen=True)
class NotebookChecked:
    """A grading judge's last line: every graded cell's outcome, and its flags for the
    instructor (:mod:`ros2nb.judge.flags`), read by the grader."""

    results: dict[str, CheckOutcome]  #: graded cell id -> its outcome
    flags: list[str]
