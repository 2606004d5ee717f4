"""Verdicts several lessons share: a node's endpoints and its name.

Part of :mod:`ros2nb.checks`.  Each raises :class:`CheckFailed` with one line naming what
the node has and what it needs, and returns quietly when it is right.
"""

from __future__ import annotations

import difflib
from typing import Sequence

from ..errors import CheckFailed
from ..subject_replies import NodeMade


def endpoint_verdict(node: str, found: list[tuple[str, str, str]], kind: str, topic: str,
                      type_name: str, made: Sequence[Sequence[str]] = ()) -> None:
    """Raise CheckFailed unless ``found`` holds a ``kind`` on ``topic`` of ``type_name``, and
    the node made (as ``made`` lists its endpoints, where it is given) only one."""
    mine = {t: ty for k, t, ty in found if k == kind}
    if mine.get(topic) == type_name:
        count = [tuple(e) for e in made].count((kind, topic, type_name))
        if count > 1:  # the graph shows one: the node's own list names the failure
            raise CheckFailed(f'{node} made {count} {kind}s on {topic}, where one does: create '
                              f'it once, in __init__.')
        return
    if topic in mine:
        raise CheckFailed(f'The {kind} of {node} on {topic} uses {mine[topic]}, but the topic '
                          f'carries {type_name}: import and pass that type.')
    if mine:
        have = ', '.join(f'{t} [{ty}]' for t, ty in sorted(mine.items()))
        close = difflib.get_close_matches(topic, list(mine), n=1)
        hint = (f': did you mean {topic}? Check the topic name' if close
                else ': check the topic name')
        raise CheckFailed(f'{node} has no {kind} on {topic} (it has: {have}){hint}.')
    raise CheckFailed(f'{node} has no {kind} yet: create one for {type_name} on {topic} in '
                      '__init__ and keep it in an attribute of the node.')


def node_name_verdict(info: NodeMade, want: str) -> None:
    """Raise CheckFailed unless the node made (``info``) is called ``want``."""
    if info.name != want:
        raise CheckFailed(f"The node is called {info.name}; name it {want} in its "
                          'super().__init__(...) call.')
