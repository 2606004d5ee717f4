"""A subject's replies to the judge's commands (:mod:`ros2nb.subject_interface`), typed.

Each reply is a frozen dataclass the subject returns and the judge reads back with
:func:`ros2nb.typed_json.decoded`, every field checked against its type; a check reads its
fields (``reply.ok``, ``reply.name``), never a dict by string.  A reply only says how long to
wait or which failure to name: the judge believes nothing in it for a point.  No ROS import.
Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs a subject).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional, Union


@dataclass(frozen=True, kw_only=True)
class Reply:
    """A subject's reply to a command: whether it did what it was asked.

    :ivar ok: False when it could not (the reply's other fields say why).
    :ivar error: what the learner's code raised while the subject served it (their import,
        their function, or a callback of theirs that ran meanwhile), or None.
    """

    ok: bool
    error: Optional[LearnerError] = None


@dataclass(frozen=True, kw_only=True)
class LearnerError:
    """An exception the learner's code raised in a subject, as
    :func:`ros2nb.explain.exceptions.describe_error` tells it.

    :ivar type: the exception's class name, e.g. ``'ZeroDivisionError'``.
    :ivar message: its text (at most 500 characters).
    :ivar explanation: the one line of a known mistake, or None.
    :ivar traceback: the learner's own frames, one string each, as Python prints them.
    :ivar where: ``FILE line N: source`` of their innermost frame ('' when none).
    """

    type: str
    message: str
    explanation: Optional[str] = None
    traceback: list[str] = field(default_factory=list)
    where: Optional[str] = None


@dataclass(frozen=True, kw_only=True)
class CallbackFailure(LearnerError):
    """The first exception a callback of the learner's raised while their node ran.

    :ivar callback: e.g. ``'TemperatureSensor.publish_temperature'``.
    :ivar node: the node's name, when the runtime knew it.
    """

    callback: str
    node: Optional[str] = None


@dataclass(frozen=True, kw_only=True)
class Encoded:
    """A value the learner's code returned, as JSON carries it
    (:func:`ros2nb.subject.replies.encode`).

    :ivar type: its type's name (``'Path'``, ``'list'``, ``'QoSProfile'``, ...).
    :ivar value: plain values as they are (a float that is not finite as its repr), a list
        or tuple as its items, anything else as its repr (at most 200 characters).
    """

    type: str
    value: Union[None, bool, int, float, str, list[Encoded]]


@dataclass(frozen=True, kw_only=True)
class Output:
    """What one call of the learner's function gave: its ``result`` or the ``error`` it raised."""

    result: Optional[Encoded] = None
    error: Optional[LearnerError] = None


@dataclass(frozen=True, kw_only=True)
class Loaded(Reply):
    """:class:`LoadFile`'s reply: ``missing`` (no such file) or the ``error`` its import raised."""

    missing: bool = False


@dataclass(frozen=True, kw_only=True)
class CellsRun(Reply):
    """:class:`ExecCells`'s reply: what each cell that raised raised, in order."""

    cell_errors: list[LearnerError] = field(default_factory=list)


@dataclass(frozen=True, kw_only=True)
class Called(Reply):
    """:class:`Call`'s reply: ``undefined`` (no such name), or one :class:`Output` per call."""

    undefined: bool = False
    outputs: list[Output] = field(default_factory=list)


@dataclass(frozen=True, kw_only=True)
class Counts(Reply):
    """What the subject counted of its node so far: how long to wait, never what passes.

    :ivar received: messages the node's subscriptions took.
    :ivar logged: lines the node logged.
    :ivar failure: the first exception one of its callbacks raised, or None.
    :ivar published: messages published per topic since the subject started (None: not
        counted).
    :ivar shown: messages the course's redraw() told the judge (None before :class:`PlotShown`).
    """

    received: int = 0
    logged: int = 0
    failure: Optional[CallbackFailure] = None
    published: Optional[dict[str, int]] = None
    shown: Optional[int] = None


@dataclass(frozen=True, kw_only=True)
class NodeMade(Counts):
    """:class:`NewNode`'s reply: the node made, or why none was.

    :ivar no_class: the name is no Node subclass (``classes``: those the code defines).
    :ivar error: what the constructor raised.
    :ivar refused: ros2nb's one line when it refused the node.
    :ivar name: the node's name; ``namespace``; ``endpoints``: ``(kind, topic, type)``.
    :ivar started_lines: lines it logged while it was made.
    :ivar parameter_services: it serves parameters (only names a failure).
    """

    no_class: bool = False
    classes: list[str] = field(default_factory=list)
    refused: Optional[str] = None
    name: str = ''
    namespace: str = ''
    endpoints: list[tuple[str, str, str]] = field(default_factory=list)
    started_lines: int = 0
    parameter_services: bool = False


@dataclass(frozen=True, kw_only=True)
class WorkerSpun(Reply):
    """:class:`Worker`'s reply (notebook 06): what the learner's function made, or why not.

    :ivar undefined: no such function; ``error``: what it raised; ``returned``: what it
        returned instead of ``(node, executor)``; ``timers``: the node's timers, fewer than
        two; ``unmatched``: its service clients never found their servers.
    :ivar name: the node's name; ``namespace``: its namespace; ``executor``: its class name;
        ``threads``: a MultiThreadedExecutor's; ``groups``: ``(callback, group class, group
        number)``; ``coroutines``: the timers' callbacks that are coroutines.  Only the
        words of a failure the judge saw: nothing here earns a point.
    """

    undefined: bool = False
    returned: Optional[Encoded] = None
    timers: Optional[int] = None
    unmatched: bool = False
    name: Optional[str] = None
    namespace: Optional[str] = None
    executor: Optional[str] = None
    threads: Optional[int] = None
    groups: list[tuple[str, str, int]] = field(default_factory=list)
    coroutines: list[str] = field(default_factory=list)


@dataclass(frozen=True, kw_only=True)
class WorkerStopped(Reply):
    """:class:`WorkerStop`'s reply: the first exception the worker's callbacks raised."""

    failure: Optional[CallbackFailure] = None


@dataclass(frozen=True, kw_only=True)
class PlotWitnessed(Reply):
    """:class:`PlotShown`'s reply: ``ok`` once the witness reached the judge; ``shown``
    counts what it told (only how long the judge waits)."""

    shown: Optional[int] = None


@dataclass(frozen=True, kw_only=True)
class RoomsMade(Reply):
    """:class:`RoomNodes`'s reply: ``(name, namespace, endpoints)`` of each node made, or the
    ``error`` rclpy raised for the arguments."""

    nodes: list[tuple[str, str, list[tuple[str, str, str]]]] = field(default_factory=list)


@dataclass(frozen=True, kw_only=True)
class QosMade(Reply):
    """:class:`QosEndpoint`'s reply: the profile's ``history`` and ``depth`` (discovery does
    not carry them), or ``undefined``, the ``error`` raised, what it ``returned`` instead."""

    undefined: bool = False
    returned: Optional[Encoded] = None
    history: Optional[int] = None
    depth: Optional[int] = None
