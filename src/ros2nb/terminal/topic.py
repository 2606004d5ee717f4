"""``ros2 node list`` and ``ros2 topic list/info``, read from the kernel's ROS graph.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

These verbs read the graph through the kernel's hidden node ``/_ros2nb``, the way
ros2cli reads it through its daemon, and print what the CLI prints.  They always run
in the kernel (even when a real ``ros2`` is on PATH): ``topic echo/hz`` must share the
kernel's simulated clock (:mod:`ros2nb.terminal.echo`), and these keep them company.
"""

from __future__ import annotations

import difflib

from ..errors import Ros2nbError
from ..qos_profiles import endpoint_lines
from ..runtime import current_runtime

#: Topics every ROS 2 process has; they are never reported as unmatched.
INFRASTRUCTURE_TOPICS = ('/rosout', '/parameter_events', '/clock')


def hidden(name: str) -> bool:
    """True for a hidden name: one of its parts starts with ``_`` (as ros2cli hides them)."""
    return any(part.startswith('_') for part in name.split('/') if part)


def resolve(topic: str) -> str:
    """The fully qualified name of ``topic``, as the kernel's node resolves it."""
    return current_runtime().node.resolve_topic_name(topic)


def node_list(*, all: bool = False) -> list[str]:
    """Print and return the running nodes' names, like ``ros2 node list``.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param all: also show hidden nodes (names starting with ``_``), like ``--all``.
    :return: fully qualified node names, sorted.
    :raises Ros2nbError: if ROS is not up (run ``ros2nb.start()``).
    """
    names = sorted({(ns.rstrip('/') + '/' + name) for name, ns in
                    current_runtime().node.get_node_names_and_namespaces()})
    names = [n for n in names if all or not hidden(n)]
    for name in names:
        print(name)
    return names


def graph_topics() -> dict[str, list[str]]:
    """The graph's topics and their types, hidden ones aside."""
    return {name: types for name, types in current_runtime().node.get_topic_names_and_types()
            if not hidden(name)}


def unmatched_topics() -> list[str]:
    """Return one line per topic whose two sides do not meet.

    A topic with publishers but no subscriptions (or the reverse), as a typo such as
    ``temprature`` in one node makes, with the closest other topic name; and a topic used
    with two message types (a ``Float32`` publisher and a ``Float64`` subscription never
    exchange a message).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`topic_list`).

    :return: human-readable notes, empty when every topic is matched.
    """
    node = current_runtime().node
    notes = []
    topics = graph_topics()
    others = [n for n in topics if n not in INFRASTRUCTURE_TOPICS]
    for name in sorted(others):
        if len(topics[name]) > 1:
            owners: dict[str, set[str]] = {t: set() for t in topics[name]}
            for info in [*node.get_publishers_info_by_topic(name),
                         *node.get_subscriptions_info_by_topic(name)]:
                if not hidden(info.node_name):  # nodes not discovered yet stay unnamed
                    owners.setdefault(info.topic_type, set()).add(info.node_name)
            uses = [f'{t} ({", ".join(sorted(o))})' if o else t for t, o in sorted(owners.items())]
            notes.append(f'{name} is used with {len(topics[name])} message types: '
                         f'{", ".join(uses)}; both sides must use the same type')
            continue
        pubs, subs = node.count_publishers(name), node.count_subscribers(name)
        note = (f'{name} has {pubs} publisher(s) but no subscription' if pubs and not subs else
                f'{name} has {subs} subscription(s) but no publisher' if subs and not pubs else '')
        if note:
            close = difflib.get_close_matches(name, [o for o in others if o != name], n=1)
            notes.append(note + (f': is it a typo of {close[0]}?' if close else ''))
    return notes


def _print_unmatched() -> None:
    for note in unmatched_topics():
        print(f'Note: {note}')


def topic_list(*, show_types: bool = False) -> list[str]:
    """Print and return the topics in the graph, like ``ros2 topic list [-t]``.

    Afterwards it points out topics with publishers but no subscriptions (or the reverse).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param show_types: also print each topic's type, like ``-t``.
    :return: topic names, sorted.
    :raises Ros2nbError: if ROS is not up.
    """
    topics = graph_topics()
    for name in sorted(topics):
        print(f'{name} [{", ".join(topics[name])}]' if show_types else name)
    _print_unmatched()
    return sorted(topics)


def did_you_mean(topic: str) -> str:
    close = difflib.get_close_matches(topic, [t for t in graph_topics() if t != topic], n=1)
    return f' Did you mean {close[0]}?' if close else ''


def _unknown_topic(topic: str) -> Ros2nbError:
    hint = did_you_mean(topic) or ' Check the name with ros2nb.topic_list().'
    return Ros2nbError(f"Unknown topic '{topic}'.{hint}")


def topic_info(topic: str, *, verbose: bool = False) -> dict[str, int]:
    """Print a topic's type and publisher/subscription counts, like ``ros2 topic info [-v]``.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param topic: topic name, relative (``temperature``) or absolute (``/temperature``).
    :param verbose: also print every endpoint's node and QoS, like ``-v``.
    :return: ``{'publishers': n, 'subscriptions': m}``.
    :raises Ros2nbError: for an unknown topic (with the closest existing name).
    """
    name = resolve(topic)
    topics = graph_topics()
    if name not in topics:
        raise _unknown_topic(name)
    node = current_runtime().node
    pubs = node.get_publishers_info_by_topic(name)
    subs = node.get_subscriptions_info_by_topic(name)
    print(f'Type: {", ".join(topics[name])}')
    for label, endpoints in (('Publisher', pubs), ('Subscription', subs)):
        if verbose:
            print()
        print(f'{label} count: {len(endpoints)}')
        if not verbose:
            continue
        for info in sorted(endpoints, key=lambda e: (e.node_namespace, e.node_name)):
            print()
            print('\n'.join(endpoint_lines(info)))
    if name not in INFRASTRUCTURE_TOPICS and (not pubs or not subs):
        _print_unmatched()
    return {'publishers': len(pubs), 'subscriptions': len(subs)}
