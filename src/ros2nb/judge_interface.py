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
from typing import (TYPE_CHECKING, Any, Callable, ContextManager, Optional, Protocol, Sequence,
                    TypeVar)

from .errors import CheckFailed, LearnerCodeError, NotDecided, Ros2nbError
from .outcomes import CHECK_FAILED, LEARNER_CODE_ERROR, NOT_DECIDED, CheckOutcome
from .processes import Process
from .subject_interface import Command
from .subject_replies import LearnerError, Reply

if TYPE_CHECKING:  # only the types: no ROS import here
    from rclpy.node import Node
    from rclpy.publisher import Publisher

#: Seconds the judge waits for what a subject published to arrive over ROS, and for ROS
#: discovery to show a subject's node; the wait ends as soon as it is there, so a long
#: limit costs time only on a busy machine or when the thing never comes.  Generous: the
#: learner's verdict must not depend on how busy the machine is.
ARRIVAL_TIMEOUT_S = 60.0
#: What the names of the judge's own nodes begin with, as the ROS graph shows them: what is
#: not the learner's on a topic.
JUDGE_NODES = '_ros2nb_judge'
#: The reply type of the command a check sends (:mod:`ros2nb.subject_interface`).
R = TypeVar('R', bound=Reply)


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


@dataclass(frozen=True)
class Heard:
    """A message the judge's node received.

    :ivar t_ns: the judge's clock when it arrived (ns of simulated time).
    :ivar value: what the check keeps of it (e.g. a Float32's ``data``).
    """

    t_ns: int
    value: Any


@dataclass(frozen=True)
class Line:
    """A /rosout line the judge's node received.

    :ivar t_ns: the judge's clock when it arrived (ns of simulated time).
    :ivar name: the logger's name (a node's name).
    :ivar level: 10 debug, 20 info, 30 warn, 40 error, 50 fatal.
    :ivar text: the message.
    """

    t_ns: int
    name: str
    level: int
    text: str


class Subject(Protocol):
    """A process of the judge's that runs the learner's code (:mod:`ros2nb.subject`)."""

    def request(self, command: Command[R], *, timeout: float = ...) -> R:
        """Send ``command`` (:mod:`ros2nb.subject_interface`) and return its typed reply.

        :param timeout: seconds the subject gets: of CPU time while it works, of the wall
            clock while it waits.
        :raises ros2nb.judge.subjects.SubjectHung: when none came in time (or it died).
        :raises ros2nb.typed_json.Unreadable: for a reply that does not fit its type.
        """


class ProgramOutput(Protocol):
    """What a program printed (stdout and stderr), collected as it comes."""

    def text(self) -> str:
        """Its last lines so far, one string."""


class Floods(Protocol):
    """What the learner's code sends beyond any node of the course (:mod:`ros2nb.judge.floods`)."""

    def forget(self) -> None:
        """Count afresh: no flood, every window empty (a new check)."""

    def raise_any(self) -> None:
        """Raise :class:`Flooded` once a flood was found (its processes ended first)."""

    def ended(self) -> None:
        """The processes that may flood were ended and reaped (one run of a program):
        what they sent is theirs, dropped wherever it still is; count afresh."""


class Observer(Protocol):
    """The judge's own ROS node (:class:`ros2nb.judge.observer.Observer`): what it hears is
    stamped with the judge's clock; every wait attends to the work of the learner's processes.
    """

    @property
    def node(self) -> Node:
        """The judge's rclpy node (spun by the judge), for a client or a publisher of a check's."""

    @property
    def logs(self) -> list[Line]:
        """Every /rosout line heard, in order of arrival (a check marks ``len(logs)``)."""

    @property
    def floods(self) -> Floods:
        """The flood counts of this judge."""

    def watch(self, topic: str, msg_type: Any, keep: Callable[[Any], Any] = ...) -> list[Heard]:
        """Hear every ``msg_type`` message on ``topic`` from now on, each kept as
        ``keep(msg)`` (default: its ``data``); the list they go to, the same for a topic
        watched again."""

    def wait_until(self, condition: Callable[[], bool], seconds: float) -> bool:
        """Wait until ``condition()`` holds: False once the learner's processes had
        ``seconds`` of work or idle waiting.

        :raises Flooded: at once, when a flood was found.
        """

    def settle(self, cpu_s: float) -> None:
        """Wait, the clock standing still, until the learner's processes sit idle or have
        worked ``cpu_s`` CPU seconds.

        :raises Flooded: at once, when a flood was found.
        """

    def lines_of(self, logger: str, start: int = 0) -> list[str]:
        """The texts of one logger's lines, from position ``start`` of :attr:`logs` on."""

    def endpoints(self, name: str, namespace: str, expected: list[tuple[str, str, str]],
                  seconds: float = ...) -> list[tuple[str, str, str]]:
        """The node ``namespace/name``'s ``(kind, topic, type)`` endpoints as the ROS graph
        shows them, once it holds ``expected`` (what the subject said it made) or after
        ``seconds``; sorted, without ROS's own topics.

        :raises NotDecided: when ``seconds`` pass first (the line says what was seen).
        """

    def spins(self, name: str, namespace: str = '/', seconds: float = ...) -> bool:
        """True once the node ``name`` answers a parameter call (it got into its spin)."""

    def has_node(self, name: str) -> bool:
        """True when a running node called ``name`` (any namespace) owns an endpoint."""

    def count_endpoints(self, name: str, namespace: str, kind: str, topic: str) -> int:
        """How many ``kind`` endpoints (``'publisher'``, ``'subscription'``) the node
        ``namespace/name`` owns on ``topic`` now, in the ROS graph."""

    def quiet_node(self) -> Node:
        """A node of the judge's that no thread spins (it takes only when told)."""


class Clock(Protocol):
    """The judge's clock (:class:`ros2nb.judge.clock.JudgeClock`): the only simulated time
    the learner's nodes run on."""

    @property
    def now_ns(self) -> int:
        """The judge's simulated time now (ns)."""

    @property
    def now_s(self) -> float:
        """The judge's simulated time now (s)."""

    def drive(self, subject: Subject, command: Command[R], *, step_s: float, limit_s: float,
              probe_s: float = 0.0, timeout: float = ..., what: str = 'your code') -> R:
        """Send ``command`` and step the clock (``step_s`` s a step, at most ``limit_s`` s of
        simulated time) while the subject's spin wants it; its typed reply once it comes.

        :param probe_s: also stop ``probe_s`` before each whole step (a timer of another
            period shows).
        :param what: whose spin would run too long, for the message.
        :raises CheckFailed: when the spin wants more than ``limit_s``, or an announced
            message never arrives.
        """


class Judge(Protocol):
    """What a check's body may ask of the judge that runs it (:class:`ros2nb.judge.Session`)."""

    workspace: Path  #: the learner's workspace (read only)
    scratch: Path  #: a folder of the judge's own
    builds: dict[str, Path]  #: workspaces of packages built so far, by their source's digest
    seed: int  #: the seed of this run's drawn inputs (:func:`ros2nb.checks.drawn.chooser`)

    @property
    def observer(self) -> Observer:
        """The judge's own ROS node: graph, messages, logs, stamped by its clock."""

    @property
    def clock(self) -> Clock:
        """The judge's clock."""

    @property
    def probe_publisher(self) -> Publisher:
        """The judge's reliable Float32 publisher on /temperature (it plays the sensor)."""

    def file_subject(self, relative: str, stand_ins: tuple[str, ...] = ()) -> Subject:
        """A subject with the learner's file (``relative`` to the workspace) imported, and
        the course's ``stand_ins`` (:mod:`ros2nb.judge.stand_ins`, by name) sent to it once
        it is: one subject per set of stand-ins.

        :raises CheckFailed: when it is missing, or its import raised.
        """

    def answer_subject(self, ref: AnswerRef, workspace: Optional[Path] = None) -> Subject:
        """A subject with the context cells and the learner's answer cells run (in
        ``workspace``, by default the learner's)."""

    def answer_home(self, ref: AnswerRef, workspace: Optional[Path] = None) -> Path:
        """The home folder of the subject that runs ``ref`` (:meth:`answer_subject`): a folder
        of its own, never the judge's."""

    def answers_workspace(self, steps: tuple[str, ...]) -> Path:
        """The learner's workspace, or a copy with the course's reference node files where
        ``steps`` (:data:`ros2nb.course.STEPS`) are missing."""

    def drop(self, key: tuple[Any, ...]) -> None:
        """End the subject of ``key`` (``('file', relative)``), if one runs, and those of the
        same file with stand-ins."""

    def drop_all(self) -> None:
        """End every subject (their nodes leave the graph)."""

    def start(self, argv: list[str], *, cwd: Path, env: Optional[dict[str, str]] = None
              ) -> tuple[Process, ProgramOutput]:
        """Start a program of the learner's (sandboxed while grading), in a session of its own.

        :param env: its whole environment (default: a subject's).
        """

    def run(self, argv: list[str], *, seconds: float, cwd: Path,
            env: Optional[dict[str, str]] = None, what: Optional[str] = None,
            writable: Sequence[Path] = ()) -> tuple[int, str]:
        """Run a program of the learner's to its end; its exit code and output.

        :param seconds: what it gets: of its work while it works, of the wall clock while
            it waits.
        :param writable: folders of the judge's it is to write (a build's); it may write
            its own folder and no other.
        :raises ros2nb.judge.subjects.SubjectHung: when it still runs after them.
        """

    def start_program(self, path: Path, stand_in: Optional[str] = None
                      ) -> tuple[Process, ProgramOutput]:
        """Start the learner's ``main()`` in ``path`` as ``ros2 run`` would (its node class
        replaced by the course's ``stand_in`` when given)."""

    def subject_env(self) -> dict[str, str]:
        """The environment of a subject of this judge (its domain, plain logs, field checks)."""

    def hand_over(self, prefix: str, files: dict[str, bytes]) -> Path:
        """A new folder of the judge's, named from ``prefix``, with ``files`` (relative path to
        bytes) the learner's code may read.

        :raises CheckFailed: when the learner's code took a name over meanwhile.
        """

    def fresh_folder(self, prefix: str) -> ContextManager[Path]:
        """A new, empty folder of the judge's that the subjects and programs started while it
        is open may write (read what they left with :meth:`taken_back`); removed afterwards."""

    def taken_back(self, folder: Path) -> ContextManager[Path]:
        """A private copy of the files the learner's code left in ``folder`` (links refused).

        :raises CheckFailed: for a link, a folder, or too many bytes.
        """


class Flooded(CheckFailed):
    """The learner's code sent more to /rosout or a topic the judge hears than any node of
    the course would (:data:`ros2nb.judge.floods.FLOOD_LIMIT`): the judge ended its processes
    and kept no more of it.  A check may grade the other parts with a stand-in."""


def learner_error(what: str, error: LearnerError, *, context: str = '') -> CheckFailed:
    """The CheckFailed for an exception the learner's code raised in a subject.

    A gap left unwritten says which one; a known mistake gets its one line; anything else
    shows the learner's own traceback (their frames only).

    :param what: whose code raised, e.g. ``TemperatureSensor.publish_temperature``.
    :param error: the subject's description of the exception (:class:`LearnerError`).
    :param context: what it was doing, e.g. `` for 19.99 °C``.
    """
    if error.type == 'NotImplementedError':  # for any input: the input is no clue
        return CheckFailed(f'{what} still raises NotImplementedError: write your code '
                           'where it says YOUR CODE HERE and run that cell again.')
    if error.explanation:
        return CheckFailed(f'{what} raised{context}: {error.explanation}'
                           + (f' ({error.where})' if error.where else ''))
    return LearnerCodeError(f'{what} raised{context}: {error.type}: {error.message}',
                            error.traceback)


#: The line of a check that ended on an error of its own: one check's points, never the
#: notebook's (the others are graded as usual).
UNFINISHED = ('The grader could not finish this check ({error}); the other checks are '
              'graded as usual. If your code changes ros2nb or its processes, undo that; '
              'otherwise tell your instructor.')


def captured(call: Callable[[], Any]) -> CheckOutcome:
    """Run one check (in the judge); return its outcome.

    An error the check did not expect (a subject's reply of the wrong shape, say) fails
    that check with one line (:data:`UNFINISHED`), so a notebook's other checks still count.
    """
    out = io.StringIO()

    def failed(kind: str, message: str, traceback: Sequence[str] = ()) -> CheckOutcome:
        return CheckOutcome(False, tuple(out.getvalue().splitlines()), kind, message,
                            tuple(traceback))

    try:
        with contextlib.redirect_stdout(out):
            call()
    except LearnerCodeError as error:
        return failed(LEARNER_CODE_ERROR, str(error), error.traceback_lines)
    except NotDecided as error:
        return failed(NOT_DECIDED, str(error))
    except (CheckFailed, Ros2nbError) as error:
        return failed(CHECK_FAILED, str(error))
    except Exception as error:  # what a process that ran learner code said made no sense
        return failed(CHECK_FAILED, UNFINISHED.format(
            error=f'{type(error).__name__}: {(str(error).splitlines() or [""])[0][:160]}'))
    return CheckOutcome(True, tuple(out.getvalue().splitlines()))


def show_result(result: CheckOutcome) -> None:
    """Print a passed outcome's lines (:func:`captured`), or raise the failure it describes.

    :raises CheckFailed: (or :class:`LearnerCodeError`) with the judge's verdict.
    :raises NotDecided: when the judge could not decide.
    """
    if result.passed:
        print('\n'.join(result.lines))
        return
    message = result.message or 'the check failed without a message'
    if result.type == LEARNER_CODE_ERROR:
        raise LearnerCodeError(message, list(result.traceback))
    if result.type == NOT_DECIDED:
        raise NotDecided(message)
    raise CheckFailed(message)
