"""JSON read back into dataclasses, every field checked against its annotation.

What crosses a pipe from a process that runs the learner's code (a subject's reply,
:mod:`ros2nb.subject_replies`) is JSON anything may have written: :func:`decoded` turns it
into the declared dataclass or raises :class:`Unreadable` naming the field, so that the
reader either holds what the types say or fails with one line.  Dataclasses, ``Optional``
and other unions, ``list``, ``tuple``, ``dict[str, ...]``, ``bool``, ``int``, ``float``,
``str``, ``None`` and ``Any``.  No ROS import.
"""

from __future__ import annotations

import dataclasses
import functools
import types
import typing
from typing import Any, Union

#: The kinds a value of exactly that type is already (True is no int here, 1 no bool).
_PLAIN = frozenset({bool, int, float, str, type(None)})


class Unreadable(ValueError):
    """A request or reply whose JSON does not fit its type (the line names the field)."""


def decoded(kind: type[Any], data: Any) -> Any:
    """``data`` (parsed JSON) as an instance of the dataclass ``kind``, every field checked
    against its annotation (a list where a tuple is declared becomes the tuple).

    :raises Unreadable: for a missing, unknown or mistyped field, naming it.
    """
    return _decoded(kind, data, kind.__name__)


@functools.cache
def _fields(kind: type[Any]) -> tuple[dict[str, Any], frozenset[str]]:
    """A dataclass's fields' types and names, resolved once per class (a decode per step of
    the judge's clock would otherwise resolve them thousands of times an hour)."""
    return typing.get_type_hints(kind), frozenset(f.name for f in dataclasses.fields(kind))


@functools.cache
def _shape(kind: Any) -> tuple[Any, tuple[Any, ...], bool]:
    """A type's origin, arguments and whether it is a dataclass, looked up once per type."""
    return typing.get_origin(kind), typing.get_args(kind), dataclasses.is_dataclass(kind)


def _decoded(kind: Any, data: Any, where: str) -> Any:
    if type(data) is kind and kind in _PLAIN:
        return data
    if kind is Any:
        return data
    origin, args, is_dataclass = _shape(kind)
    if is_dataclass:
        if not isinstance(data, dict):
            raise Unreadable(f'{where} is not a JSON object')
        hints, known = _fields(kind)
        unknown = sorted(set(data) - known)
        if unknown:
            raise Unreadable(f'{where} has no field {unknown[0]!r}')
        make: Any = kind  # a dataclass: its fields by name
        try:
            return make(**{name: _decoded(hints[name], value, f'{where}.{name}')
                           for name, value in data.items()})
        except TypeError as error:  # a field without a default is missing
            raise Unreadable(f'{where}: {error}') from None
    if origin in (Union, types.UnionType):
        if data is None and type(None) in args:  # what every option before None gives too
            return None
        for option in args:
            try:
                return _decoded(option, data, where)
            except Unreadable:
                continue
        raise Unreadable(f'{where} is {type(data).__name__}, not {kind}')
    if origin in (list, tuple) and isinstance(data, list):
        if origin is list or (len(args) == 2 and args[1] is Ellipsis):
            return origin(_decoded(args[0], item, f'{where}[]') for item in data)
        if len(args) == len(data):
            return tuple(_decoded(a, item, f'{where}[]') for a, item in zip(args, data))
    if origin is dict and isinstance(data, dict) and all(isinstance(k, str) for k in data):
        if args[1] in _PLAIN and all(type(value) is args[1] for value in data.values()):
            return dict(data)  # counts: each value already what it must be
        return {key: _decoded(args[1], value, f'{where}[{key!r}]') for key, value in data.items()}
    if kind is float and isinstance(data, (int, float)) and not isinstance(data, bool):
        return float(data)
    if kind in (bool, int, str) and type(data) is kind or kind is type(None) and data is None:
        return data  # exactly: True is no int here, 1 no bool
    raise Unreadable(f'{where} is {type(data).__name__}, not {getattr(kind, "__name__", kind)}')
