"""The nodes handed to the kernel: added, replaced, stopped, found by name.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`NodeKeeping` side of it).  Handing a
node over twice never doubles it: the old one is taken out of service first.

rcl keeps ONE /rosout publisher per logger name for the whole process: the first node of a
name registers it, every later node of that name logs through it, and the first node of
the name that is destroyed, or freed by Python, unregisters it for all of them (whichever
node registered it).  So a node of a name still in use is never destroyed here, and never
freed: :func:`keep_shared_names` holds every node that shares its name with another live
one, and the runtime destroys them all when it stops that name.
"""

from __future__ import annotations

import contextlib
import functools
import os
import weakref
from typing import TYPE_CHECKING, Any, ContextManager, Iterable, Iterator, Optional, Union

import rclpy
from rclpy.exceptions import InvalidHandle
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node

from ..errors import Ros2nbError, UsageError
from ..explain.guards import check_node

NodeOrName = Union[Node, str]

#: Set (to 1) in a subject whose nodes' last log lines the judge must still receive after the
#: learner's code stopped them (notebook 10's replay): a stopped node is then emptied but kept
#: until the process ends, so its /rosout publisher, with its transient-local history, stays
#: for a judge whose subscription matches late.
KEEP_STOPPED_ENV = 'ROS2NB_KEEP_STOPPED_NODES'


def drop_qos_warnings(node: Node, entities: Optional[Iterable[Any]] = None) -> None:
    """Destroy the QoS event handlers of ``entities`` (publishers or subscriptions of
    ``node``; every publisher of ``node`` when None).

    rclpy gives each publisher and subscription two by default, whose only work is a warning
    when the other side asks for an incompatible QoS or type.  Each handler is one more
    entity in every wait of the executor, which waits several times per step of simulated
    time.
    """
    for entity in (node.publishers if entities is None else entities):
        for handler in entity.event_handlers:  # type: ignore[union-attr]  # rclpy mistypes its list
            node.remove_waitable(handler)
            handler.destroy()
        entity.event_handlers = []


def rclpys_own_entities(node: Node) -> list[Any]:
    """What rclpy made for ``node`` itself, with rclpy's QoS (never the learner's): its
    ``/parameter_events`` publisher, and its time source's ``/clock`` subscription when the
    node is on simulated time.  A QoS warning of theirs could only ever be about another
    program's endpoint."""
    source = getattr(node, '_time_source', None)
    made = (getattr(node, '_parameter_event_publisher', None), getattr(source, '_clock_sub', None))
    return [entity for entity in made if entity is not None]


#: Every node made in this process since a runtime first came up (weakly: Python frees a
#: node nobody holds, as ever).
_made: 'weakref.WeakSet[Node]' = weakref.WeakSet()
#: The contexts of the runtimes of this process: a node made on one of them is held with the
#: other live nodes of its name (a judge's own nodes, on a context of its own, never are).
_watched: 'weakref.WeakSet[rclpy.context.Context]' = weakref.WeakSet()
#: Nodes that share their logger name with a live node of a runtime, by that name: held
#: until the runtime stops the name (:meth:`NodeKeeping._discard`) or ROS shuts down.
_shared: dict[str, list[Node]] = {}
#: Marks ``Node.__init__`` once :func:`keep_shared_names` wrapped it.
_KEEPS = '_ros2nb_keeps_shared_names'


def keep_shared_names(context: rclpy.context.Context) -> None:
    """Know every node made from now on, and hold each node made on ``context`` (a runtime's)
    with every other live node of its logger name, so that none of them is freed while the
    others log.

    The node Python frees is one nobody holds any more: typically a half-built one, whose
    ``__init__`` raised after ``super().__init__`` (a part an earlier notebook left
    unwritten), kept only by the traceback of the cell that failed.  The garbage collector
    frees it whenever its allocation counts say so, not when the learner acts: the node of
    that name running by then stops reaching /rosout in the middle of a spin, and a check
    that hears the monitor's statuses there (notebook 10) hears none from that reading on.
    Held from the moment the second node of the name is made, the first is never freed
    before the runtime destroys them together.  Wrapping ``Node.__init__`` again changes
    nothing.
    """
    _watched.add(context)
    original = Node.__init__
    if getattr(original, _KEEPS, False):
        return

    @functools.wraps(original)
    def made(self: Node, *args: Any, **kwargs: Any) -> None:
        original(self, *args, **kwargs)
        _note(self)

    setattr(made, _KEEPS, True)
    setattr(Node, '__init__', made)  # every class made from Node, the learner's too


def _note(node: Node) -> None:
    """Know ``node``; on a runtime's context, hold it with every other live node of its
    logger name, if any."""
    if node.context in _watched:
        name = _logger_name(node)
        others = [other for other in _made if _logger_name(other) == name and _undestroyed(other)]
        if others:
            held = _shared.setdefault(name, [])
            held.extend(n for n in (*others, node) if not any(n is h for h in held))
    _made.add(node)


def _logger_name(node: Node) -> str:
    return node.get_logger().name


def _undestroyed(node: Node) -> bool:
    """False once ``destroy_node()`` ran: the node no longer holds rcl's /rosout publisher."""
    try:
        with node.handle:
            return True
    except InvalidHandle:
        return False


def _release(node: Node) -> list[Node]:
    """The other nodes held with ``node`` for its logger name, no longer held."""
    return [other for other in _shared.pop(_logger_name(node), []) if other is not node]


def _empty(node: Node) -> None:
    """Destroy every timer, publisher, subscription, service and client of ``node``, but not
    the node itself (nor, with it, its name's /rosout publisher): nothing stale keeps running
    or meets another node's endpoints."""
    for timer in list(node.timers):
        node.destroy_timer(timer)
    for publisher in list(node.publishers):
        node.destroy_publisher(publisher)
    for subscription in list(node.subscriptions):
        node.destroy_subscription(subscription)
    for service in list(node.services):
        node.destroy_service(service)
    for client in list(node.clients):
        node.destroy_client(client)


def _destroy(nodes: Iterable[Node]) -> None:
    """Destroy each node once (a node may be both a retired shell and held for its name)."""
    done: list[Node] = []
    for node in nodes:
        if any(node is d for d in done):
            continue
        done.append(node)
        with contextlib.suppress(InvalidHandle):  # the learner destroyed it already
            node.destroy_node()


class NodeKeeping:
    """The running nodes by full name, and the emptied shells of replaced ones.

    Needs, from the runtime it is part of (declared below for the type checker):
    ``executor``, ``exclusive``, ``drain``, ``alive``, ``ensure_alive``, ``own_logger``,
    ``sim_time``, ``_on_sim`` and ``_set_clock``.
    """

    executor: SingleThreadedExecutor
    sim_time: bool
    _on_sim: set[str]

    if TYPE_CHECKING:  # the runtime's other sides define these: only their types here
        @property
        def alive(self) -> bool: ...
        def exclusive(self) -> ContextManager[object]: ...
        def drain(self) -> int: ...
        def ensure_alive(self) -> None: ...
        def own_logger(self, name: str) -> None: ...
        def _set_clock(self, nodes: Iterable[Node], sim: bool) -> None: ...

    def __init__(self) -> None:
        self._nodes: dict[str, Node] = {}
        self._retired: dict[str, list[Node]] = {}

    def add(self, node: Node) -> Node:
        """Hand ``node`` over, replacing a running node of the same name; see :func:`add`."""
        self.ensure_alive()
        check_node(node, self)
        name = node.get_fully_qualified_name()
        with self.exclusive():
            old = self._nodes.get(name)
            if old is not None and old is not node:
                self._retire(old)
            for other in _shared.get(_logger_name(node), []):
                if other is not node and other is not old:
                    _empty(other)  # e.g. half-built by an earlier cell: kept, never running
            self._nodes[name] = node
            self.own_logger(node.get_logger().name)
            drop_qos_warnings(node, rclpys_own_entities(node))
            self.executor.add_node(node)
            self._set_clock([node], self.sim_time)
            self.drain()
        return node

    def _forget(self, node: Node) -> str:
        """Take ``node`` out of the executor and the books; return its full name."""
        name = node.get_fully_qualified_name()
        self._nodes.pop(name, None)
        self._on_sim.discard(name)
        self.executor.remove_node(node)
        return name

    def _retire(self, node: Node) -> None:
        """Take a replaced node out of service without destroying the node itself.

        rcl registers one /rosout publisher per logger name; destroying the old node would
        unregister it for the new node of the same name too, and its logs would vanish.
        So every timer, publisher, subscription and service of the old node is destroyed
        (nothing stale keeps running) and the empty node is kept until no live node has
        that name.
        """
        name = self._forget(node)
        _empty(node)
        self._retired.setdefault(name, []).append(node)

    def _discard(self, node: Node) -> None:
        """Stop a node for good, with the retired nodes of its name and every other node held
        for its name (:func:`keep_shared_names`): they leave the graph together."""
        name = self._forget(node)
        _destroy([*self._retired.pop(name, []), *_release(node), node])

    def stop(self, node: Optional[NodeOrName] = None) -> list[str]:
        """Stop one running node (or all); see :func:`stop`."""
        with self.exclusive():
            targets = list(self._nodes.values()) if node is None else [self.find(node)]
            names = [target.get_name() for target in targets]
            keep = os.environ.get(KEEP_STOPPED_ENV) == '1'
            for target in targets:
                self._retire(target) if keep else self._discard(target)
            if self.alive:
                self.drain()
        return names

    def find(self, node: NodeOrName) -> Node:
        """Return the running node given as a node or a name.

        :raises Ros2nbError: naming the running nodes when there is none of that name.
        """
        if isinstance(node, Node):
            key = node.get_fully_qualified_name()
        elif isinstance(node, str):
            key = node if node.startswith('/') else '/' + node
        else:
            raise UsageError(f'Give a node or its name, not {type(node).__name__}.')
        try:
            return self._nodes[key]
        except KeyError:
            running = ', '.join(sorted(self._nodes)) or 'none'
            raise Ros2nbError(f'No running node named {key!r} (running: {running}); '
                              'hand it over with ros2nb.add(node) first.') from None

    @property
    def nodes(self) -> dict[str, Node]:
        """The running nodes handed over, by fully qualified name."""
        return dict(self._nodes)

    def _destroy_all_nodes(self) -> None:
        """Destroy every node handed over and every retired shell (at shutdown)."""
        for node in list(self._nodes.values()):
            self._discard(node)
        _destroy(shell for shells in self._retired.values() for shell in shells)
        self._retired.clear()


def _live_nodes() -> Iterator[Node]:
    """Every rclpy node Python still holds in this process, of any context, half-built too
    (made since a runtime came up: :func:`keep_shared_names`)."""
    return iter(list(_made))


def destroy_stray_nodes(context: rclpy.context.Context) -> None:
    """Destroy every node still alive on ``context``: made in a cell, never handed over, or kept
    in a variable after ``rclpy.shutdown()``.

    rcl keeps one /rosout publisher per logger name for the whole process.  A node of an
    ended context that Python's garbage collector frees later (whenever that happens)
    unregisters its name's publisher, which by then belongs to the new node of that name:
    the new node's log lines would stop reaching the cell part-way through a spin.
    """
    for candidate in _live_nodes():
        if getattr(candidate, '_context', None) is context:
            with contextlib.suppress(Exception):  # already destroyed
                candidate.destroy_node()
    _watched.discard(context)
    for name, held in list(_shared.items()):  # held for a runtime still up, or let go
        if not any(node.context in _watched and node.context.ok() and _undestroyed(node)
                   for node in held):
            del _shared[name]
