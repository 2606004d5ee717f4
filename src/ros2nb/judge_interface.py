"""What a check may ask of the judge, and the one JSON line a check's outcome travels as.

The judge's small interface, which the lessons' checks (:mod:`ros2nb.checks`) depend on and
the judge (:mod:`ros2nb.judge.session`) implements: the judge never depends on a lesson.
It runs in the kernel (a check's outcome read back, :func:`show_result`) and in the judge
(a check's body given the :class:`Judge`, its outcome :func:`captured`).  No ROS import.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs in a judge).
"""

from __future__ import annotations

import contextlib
import io
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, ContextManager, Optional, Protocol

from .errors import CheckFailed, LearnerCodeError, Ros2nbError

#: Seconds the judge waits for what a subject published to arrive over ROS, and for ROS
#: discovery to show a subject's node; the wait ends as soon as it is there, so a long
#: limit costs time only on a busy machine or when the thing never comes.  Generous: the
#: learner's verdict must not depend on how busy the machine is.
ARRIVAL_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class AnswerRef:
    """A name the learner defined in their answer cells, as the judge knows it: by source.

    :ivar name: e.g. ``'LoudListener'``.
    :ivar sources: the course's context cells, then the learner's answer cells, in order.
    """

    name: str
    sources: tuple[str, ...]

    @property
    def __name__(self) -> str:  # messages name it like the function or class itself
        return self.name


class Judge(Protocol):
    """What a check's body may ask of the judge that runs it (:class:`ros2nb.judge.Session`)."""

    workspace: Path  #: the learner's workspace (read only)
    scratch: Path  #: a folder of the judge's own
    builds: dict[str, Any]  #: packages built so far, by their source's digest
    observer: Any  #: the judge's own ROS node: graph, messages, logs, stamped by its clock
    clock: Any  #: the judge's clock (:class:`ros2nb.judge.clock.JudgeClock`)
    probe_publisher: Any  #: the judge's Float32 publisher on /temperature
    seed: int  #: the seed of this run's drawn inputs (:func:`ros2nb.checks.drawn.chooser`)

    def file_subject(self, relative: str, stand_ins: tuple[str, ...] = ()) -> Any: ...
    def answer_subject(self, ref: AnswerRef, workspace: Optional[Path] = None) -> Any: ...
    def answers_workspace(self, steps: tuple[str, ...]) -> Path: ...
    def drop(self, key: tuple) -> None: ...
    def drop_all(self) -> None: ...
    def start(self, argv: list[str], *, cwd: Path,
              env: Optional[dict[str, str]] = None) -> tuple[Any, Any]: ...
    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None, what: Optional[str] = None
            ) -> tuple[int, str]: ...
    def start_program(self, path: Path, stand_in: Optional[str] = None) -> tuple[Any, Any]: ...
    def subject_env(self) -> dict[str, str]: ...
    def hand_over(self, prefix: str, files: dict[str, bytes]) -> Path: ...
    def taken_back(self, folder: Path) -> ContextManager[Path]: ...


class Flooded(CheckFailed):
    """The learner's code sent more to /rosout or a topic the judge hears than any node of
    the course would (:data:`ros2nb.judge.floods.FLOOD_LIMIT`): the judge ended its processes
    and kept no more of it.  A check may grade the other parts with a stand-in."""


def learner_error(what: str, error: dict, *, context: str = '') -> CheckFailed:
    """The CheckFailed for an exception the learner's code raised in a subject.

    A gap left unwritten says which one; a known mistake gets its one line; anything else
    shows the learner's own traceback (their frames only).

    :param what: whose code raised, e.g. ``TemperatureSensor.publish_temperature``.
    :param error: the subject's description of the exception
        (:func:`ros2nb.explain.exceptions.describe_error`).
    :param context: what it was doing, e.g. `` for 19.99 °C``.
    """
    if error.get('type') == 'NotImplementedError':  # for any input: the input is no clue
        return CheckFailed(f'{what} still raises NotImplementedError: write your code '
                           'where it says YOUR CODE HERE and run that cell again.')
    if error.get('explanation'):
        where = error.get('where')
        return CheckFailed(f'{what} raised{context}: {error["explanation"]}'
                           + (f' ({where})' if where else ''))
    return LearnerCodeError(f'{what} raised{context}: {error["type"]}: {error["message"]}',
                            error.get('traceback', []))


#: The line of a check that ended on an error of its own: one check's points, never the
#: notebook's (the others are graded as usual).
UNFINISHED = ('The grader could not finish this check ({error}); the other checks are '
              'graded as usual. If your code changes ros2nb or its processes, undo that; '
              'otherwise tell your instructor.')


def captured(call: Callable[[], Any]) -> dict:
    """Run one check (in the judge); return its outcome as JSON-safe data for the kernel.

    An error the check did not expect (a subject's reply of the wrong shape, say) fails
    that check with one line (:data:`UNFINISHED`), so a notebook's other checks still count.

    :return: ``passed`` and the printed ``lines``; when failed also ``type``
        (``'CheckFailed'`` or ``'LearnerCodeError'``), ``message`` and, for the latter,
        ``traceback`` (the learner's frames, one string each).
    """
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(out):
            call()
    except LearnerCodeError as error:
        return {'passed': False, 'type': 'LearnerCodeError', 'message': str(error),
                'traceback': error.traceback_lines, 'lines': out.getvalue().splitlines()}
    except (CheckFailed, Ros2nbError) as error:
        return {'passed': False, 'type': 'CheckFailed', 'message': str(error),
                'lines': out.getvalue().splitlines()}
    except Exception as error:  # what a process that ran learner code said made no sense
        return {'passed': False, 'type': 'CheckFailed', 'lines': out.getvalue().splitlines(),
                'message': UNFINISHED.format(error=f'{type(error).__name__}: '
                                                   f'{(str(error).splitlines() or [""])[0][:160]}')}
    return {'passed': True, 'lines': out.getvalue().splitlines()}


def show_result(result: dict) -> None:
    """Print a passed result's lines (:func:`captured`), or raise the failure it describes.

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    """
    if result['passed']:
        print('\n'.join(result['lines']))
        return
    if result['type'] == 'LearnerCodeError':
        raise LearnerCodeError(result['message'], result['traceback'])
    raise CheckFailed(result['message'])
