"""What the judge may ask of a subject: every command, with its typed request and reply.

The one declaration both ends share: the judge sends a request (``subject.request(
WaitMatched(topic=..., seconds=...))``, :mod:`ros2nb.judge.subjects`), the subject serves it
(:mod:`ros2nb.subject.commands`, :mod:`ros2nb.subject.trials`: one method per command, named
by its ``op``, :class:`Serves`), and a check reads the reply's fields (``.ok``), never a
dict by string (the replies: :mod:`ros2nb.subject_replies`).  On the wire a request is one
JSON line, ``{"op": ..., **fields}`` (:func:`wire`), and a reply one JSON object of its
fields; :func:`ros2nb.typed_json.decoded` reads either back, every field checked against its
type, so a reply the judge cannot read fails that check alone with one line
(:data:`ros2nb.judge_interface.UNFINISHED`).

A new command is a request class here (``op``, its fields, ``Command[ITS_REPLY]``), its reply
class (:mod:`ros2nb.subject_replies`, or :class:`~ros2nb.subject_replies.Reply`), a method
of :class:`Serves`, and that method in the subject; the type checker (``make check``) holds
them together.  No ROS import.  Introduced in
``03-write-the-publisher.ipynb`` (every check of a node runs a subject).
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, field
from typing import Any, ClassVar, Generic, Optional, Protocol, TypeVar

from .typed_json import Unreadable, decoded
from .subject_replies import (Called, CellsRun, Counts, Loaded, NodeMade, PlotWitnessed,
                              QosMade, Reply, RoomsMade, WorkerSpun, WorkerStopped)



R = TypeVar('R', bound=Reply, covariant=True)


class Command(Generic[R]):
    """A request of the judge's; ``R`` is its reply's class (:func:`reply_type`).

    :cvar op: its name on the wire, and the name of the method that serves it (:class:`Serves`).
    """

    op: ClassVar[str]


@dataclass(frozen=True)
class LoadFile(Command[Loaded]):
    """The first command: import the learner's file ``path`` as module ``module``."""

    op: ClassVar[str] = 'load_file'
    path: str
    module: str


@dataclass(frozen=True)
class ExecCells(Command[CellsRun]):
    """The first command: run the course's context cells, then the learner's answer cells."""

    op: ClassVar[str] = 'exec_cells'
    sources: list[str]


@dataclass(frozen=True)
class StandIns(Command[Reply]):
    """Compile the course's stand-ins the judge sends as code (``source``:
    :func:`ros2nb.judge.stand_ins.source_of`), once the learner's code is loaded; kept in
    the subject under no name that code imports."""

    op: ClassVar[str] = 'stand_ins'
    source: str


@dataclass(frozen=True)
class Call(Command[Called]):
    """Call the learner's ``name`` once per list of arguments in ``inputs`` (a ``{"path": p}``
    argument is a Path)."""

    op: ClassVar[str] = 'call'
    name: str
    inputs: list[list[Any]]


@dataclass(frozen=True)
class NewNode(Command[NodeMade]):
    """Make ``cls(*args)`` with the course's ``stand_ins`` (compiled by :class:`StandIns`,
    by name) on the judge's clock (``seed``:
    of ``random``, when given); the node made before is stopped."""

    op: ClassVar[str] = 'new_node'
    cls: str
    stand_ins: list[str] = field(default_factory=list)
    seed: Optional[int] = None
    args: list[Any] = field(default_factory=list)


@dataclass(frozen=True)
class GetCounts(Command[Counts]):
    """What the subject counted so far."""

    op: ClassVar[str] = 'counts'


@dataclass(frozen=True)
class Run(Command[Counts]):
    """Let the nodes run ``seconds`` of the judge's clock (the judge steps it:
    :meth:`ros2nb.judge_interface.Clock.drive`)."""

    op: ClassVar[str] = 'run'
    seconds: float
    seed: Optional[int] = None


@dataclass(frozen=True)
class SetAttribute(Command[Reply]):
    """Set the node's attribute ``name`` to ``value``."""

    op: ClassVar[str] = 'set_attribute'
    name: str
    value: Any


@dataclass(frozen=True)
class WaitMatched(Command[Reply]):
    """Wait (at most ``seconds``) until the node's publishers on ``topic`` reach a
    subscription."""

    op: ClassVar[str] = 'wait_matched'
    topic: str
    seconds: float


@dataclass(frozen=True)
class WaitPublishers(Command[Reply]):
    """Wait (at most ``seconds``) until the node's subscriptions on ``topic`` matched a
    publisher."""

    op: ClassVar[str] = 'wait_publishers'
    topic: str
    seconds: float


@dataclass(frozen=True)
class WaitReceived(Command[Counts]):
    """Run callbacks until the node's subscriptions took ``count`` messages (at most
    ``seconds``); ``ok`` when they did."""

    op: ClassVar[str] = 'wait_received'
    count: int
    seconds: float


@dataclass(frozen=True)
class Serve(Command[Counts]):
    """Spin the node in the background from now on (it answers parameter calls)."""

    op: ClassVar[str] = 'serve'


@dataclass(frozen=True)
class Worker(Command[WorkerSpun]):
    """Notebook 06: spin the executor the learner's ``name()`` returns with the node it
    returns, on the wall clock, as it is: once the node's service clients have found their
    servers (``seconds`` at most), for the slow job is the judge's to answer.  The judge
    holds the slow job open and listens for the heartbeat meanwhile
    (:mod:`ros2nb.checks.lesson06_worker`)."""

    op: ClassVar[str] = 'worker'
    name: str
    seconds: float


@dataclass(frozen=True)
class WorkerStop(Command[WorkerStopped]):
    """Stop spinning the learner's worker."""

    op: ClassVar[str] = 'worker_stop'


@dataclass(frozen=True)
class PlotShown(Command[PlotWitnessed]):
    """Notebook 07: the course's ``redraw()`` on the node's class, telling ``topic`` what
    each drawing drew, as plain data; wait ``seconds`` at most for the judge's
    subscription."""

    op: ClassVar[str] = 'plot_shown'
    topic: str
    seconds: float


@dataclass(frozen=True)
class RoomNodes(Command[RoomsMade]):
    """Notebook 06: a stand-in sensor and monitor, each started with ``arguments``."""

    op: ClassVar[str] = 'room_nodes'
    arguments: list[str]


@dataclass(frozen=True)
class QosEndpoint(Command[QosMade]):
    """Notebook 09: a ``kind`` (``'subscription'`` or ``'publisher'``) of Int32 on ``topic``
    with the profile the learner's ``name()`` returns; a publisher publishes ``numbers``."""

    op: ClassVar[str] = 'qos_endpoint'
    name: str
    topic: str
    kind: str
    numbers: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class QosAcked(Command[Reply]):
    """Notebook 09: wait (at most ``seconds``) until the judge's late joiner acknowledged
    the publisher's burst."""

    op: ClassVar[str] = 'qos_acked'
    seconds: float


#: The first command, which loads the learner's code (and only the first), by its ``op``.
LOADERS: dict[str, type[Command[Any]]] = {LoadFile.op: LoadFile, ExecCells.op: ExecCells}
#: Every command the command loop serves, by its ``op``.
COMMANDS: dict[str, type[Command[Any]]] = {command.op: command for command in (
    StandIns, Call, NewNode, GetCounts, Run, SetAttribute, WaitMatched, WaitPublishers,
    WaitReceived, Serve, Worker, WorkerStop, PlotShown, RoomNodes,
    QosEndpoint, QosAcked)}


class Serves(Protocol):
    """What a subject serves: one method per command of :data:`COMMANDS`, named by its
    ``op`` (:class:`ros2nb.subject.commands.Subject` is checked against it)."""

    def stand_ins(self, command: StandIns) -> Reply: ...
    def call(self, command: Call) -> Called: ...
    def new_node(self, command: NewNode) -> NodeMade: ...
    def counts(self, command: GetCounts) -> Counts: ...
    def run(self, command: Run) -> Counts: ...
    def set_attribute(self, command: SetAttribute) -> Reply: ...
    def wait_matched(self, command: WaitMatched) -> Reply: ...
    def wait_publishers(self, command: WaitPublishers) -> Reply: ...
    def wait_received(self, command: WaitReceived) -> Counts: ...
    def serve(self, command: Serve) -> Counts: ...
    def worker(self, command: Worker) -> WorkerSpun: ...
    def worker_stop(self, command: WorkerStop) -> WorkerStopped: ...
    def plot_shown(self, command: PlotShown) -> PlotWitnessed: ...
    def room_nodes(self, command: RoomNodes) -> RoomsMade: ...
    def qos_endpoint(self, command: QosEndpoint) -> QosMade: ...
    def qos_acked(self, command: QosAcked) -> Reply: ...


# ------------------------------------------------------------------ the wire
def reply_type(command: type[Command[R]]) -> type[R]:
    """The reply class of a command class (the ``R`` of its ``Command[R]`` base)."""
    for base in getattr(command, '__orig_bases__', ()):
        if typing.get_origin(base) is Command:
            reply: type[R] = typing.get_args(base)[0]
            return reply
    raise TypeError(f'{command.__name__} names no reply type: derive it from Command[...]')


def wire(value: Any) -> dict[str, Any]:
    """A request (with its ``op``) or a reply as the JSON object the wire carries."""
    fields = dataclasses.asdict(value)
    return {'op': value.op, **fields} if isinstance(value, Command) else fields


def command_of(data: Any, among: dict[str, type[Command[Any]]]) -> Command[Any]:
    """A request's JSON object as its command, one of ``among`` (by its ``op``).

    :raises Unreadable: for an ``op`` not among them, or fields that do not fit it.
    """
    op = data.get('op') if isinstance(data, dict) else None
    if not isinstance(op, str) or op not in among:
        raise Unreadable(f'no command {op!r} here')
    command: Command[Any] = decoded(among[op], {k: v for k, v in data.items() if k != 'op'})
    return command
