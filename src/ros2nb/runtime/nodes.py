"""The nodes handed to the kernel: added, replaced, stopped, found by name.

Part of :class:`ros2nb.runtime.Runtime` (the :class:`NodeKeeping` side of it).  Handing a
node over twice never doubles it: the old one is taken out of service first.
"""

from __future__ import annotations

import contextlib
import gc
import os
from typing import Any, Iterable, Iterator, Optional, Union

import rclpy
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
        for handler in entity.event_handlers:
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


class NodeKeeping:
    """The running nodes by full name, and the emptied shells of replaced ones.

    Needs, from the runtime it is part of: ``executor``, ``exclusive``, ``drain``,
    ``alive``, ``ensure_alive``, ``own_logger``, ``sim_time``, ``_on_sim`` and ``_set_clock``.
    """

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
        self._retired.setdefault(name, []).append(node)

    def _discard(self, node: Node) -> None:
        """Stop a node for good, with the retired nodes of its name: it leaves the graph."""
        name = self._forget(node)
        for shell in self._retired.pop(name, []) + [node]:
            shell.destroy_node()

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
        for shells in self._retired.values():
            for shell in shells:
                shell.destroy_node()
        self._retired.clear()


def _live_nodes() -> Iterator[Node]:
    """Every rclpy node Python still holds in this process, of any context, half-built too."""
    return (candidate for candidate in gc.get_objects() if isinstance(candidate, Node))


def destroy_stray_nodes(context: rclpy.context.Context) -> None:
    """Destroy every node still alive on ``context``: made in a cell, never handed over, or kept
    in a variable after ``rclpy.shutdown()``.

    rcl keeps one /rosout publisher per logger name for the whole process.  A node of an
    ended context that Python's garbage collector frees later (whenever that happens)
    unregisters its name's publisher, which by then belongs to the new node of that name:
    the new node's log lines would stop reaching the cell part-way through a spin.
    """
    for candidate in _live_nodes():
        # a half-built node (its __init__ never called super().__init__) has no context
        if getattr(candidate, '_context', None) is context:
            with contextlib.suppress(Exception):  # already destroyed, or half-built
                candidate.destroy_node()
