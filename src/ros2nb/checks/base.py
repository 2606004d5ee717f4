"""What every check is made of: the words they share, and how one reaches the judge.

Part of :mod:`ros2nb.checks`.  A check is a public function the notebook calls
(``check_sensor_constructor()``) around a body that takes the judge and returns the
``Check passed`` sentence, or raises :class:`CheckFailed` with one line.  In the kernel
the public function asks a judge process to run it (:mod:`.dispatch`); in the judge, the
judge hands itself over with :func:`bind_judge` and the body runs here.  The checks never
import the judge: they use the methods of the object it binds (:class:`Judge`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, ContextManager, Optional, Protocol

from ..errors import CheckFailed, LearnerCodeError, Ros2nbError
from ..explain.exceptions import describe_error
from .dispatch import in_judge, run_in_judge

#: Seconds the judge waits for what a subject published to arrive over ROS, and for ROS
#: discovery to show a subject's node; the wait ends as soon as it is there, so a long
#: limit costs time only on a busy machine or when the thing never comes.  Generous: the
#: learner's verdict must not depend on how busy the machine is.
ARRIVAL_TIMEOUT_S = 60.0


class Judge(Protocol):
    """What a check may ask of the judge that runs it (:class:`ros2nb.judge.Session`)."""

    workspace: Path  #: the learner's workspace (read only)
    scratch: Path  #: a folder of the judge's own
    builds: dict[str, Any]  #: packages built so far, by their source's digest
    observer: Any  #: the judge's own ROS node: graph, messages, logs, stamped by its clock
    clock: Any  #: the judge's clock (:class:`ros2nb.judge.clock.JudgeClock`)
    probe_publisher: Any  #: the judge's Float32 publisher on /temperature

    def file_subject(self, relative: str) -> Any: ...
    def answer_subject(self, ref: 'AnswerRef', workspace: Optional[Path] = None) -> Any: ...
    def caught_up(self, steps: tuple[str, ...]) -> Path: ...
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


_judge: Optional[Judge] = None


def bind_judge(judge: Optional[Judge]) -> None:
    """Make ``judge`` the one the checks of this process use (the judge process calls it)."""
    global _judge
    _judge = judge


def current_judge() -> Judge:
    """The judge this process runs checks for.

    :raises RuntimeError: outside a judge that bound itself (a mistake of the course's).
    """
    if _judge is None:
        raise RuntimeError('no judge is bound in this process (ros2nb.judge binds itself)')
    return _judge


def passed(message: str) -> None:
    """Print the line a passing check shows."""
    print(f'Check passed: {message}')


def judged(name: str, body: Callable[..., str], **arguments: Any) -> None:
    """Run ``body(judge, **arguments)`` in the judge, asking one to run ``name`` from the kernel.

    :param name: the public check's name, e.g. ``'check_sensor_constructor'``: the judge
        calls the same public function, which knows its own arguments.
    """
    if in_judge():
        passed(body(current_judge(), **arguments))
    else:
        run_in_judge(name, {})


def call_learner(function: Callable[..., Any], *args: Any) -> Any:
    """Call the learner's function in the kernel: NotImplementedError becomes one line, and
    any other error the learner's code raised a failure through their own frames only (or
    the one line of a known mistake), never a traceback through the check, rclpy or rosbags.

    :raises CheckFailed: (or :class:`LearnerCodeError`) for an error in the learner's code.
    """
    try:
        return function(*args)
    except NotImplementedError:
        raise CheckFailed(f'{function.__name__}() still raises NotImplementedError: replace '
                          '"raise NotImplementedError()" with your code and run its cell '
                          'again.') from None
    except (CheckFailed, Ros2nbError):  # ros2nb's own line, raised in their code's call
        raise
    except Exception as error:  # their frames only, or the one line of a known mistake
        raise learner_error(f'{function.__name__}()', describe_error(error)) from None


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


def learner_error(what: str, error: dict, *, context: str = '') -> CheckFailed:
    """The CheckFailed for an exception the learner's code raised in a subject.

    A gap left unwritten says which one; a known mistake gets its one line; anything else
    shows the learner's own traceback (their frames only).

    :param what: whose code raised, e.g. ``TemperatureSensor.publish_temperature``.
    :param error: the subject's description of the exception.
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
