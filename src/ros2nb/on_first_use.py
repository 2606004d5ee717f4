"""Names a package loads on first use (PEP 562): one way, for every package that needs it.

``ros2nb`` (its checks and bag verbs), ``ros2nb.checks`` (one module per lesson) and
``ros2nb.terminal`` (the bag verbs, with rosbags) keep what a process may never need out of
its start: a judge's subject only runs nodes.  No ROS import here.
"""

from __future__ import annotations

import importlib
from typing import Any, Callable, Mapping


def loader(namespace: dict[str, Any], where: Mapping[str, str]
           ) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """The ``__getattr__`` and ``__dir__`` of a package whose names load on first use.

    :param namespace: the package's ``globals()``: a loaded name is kept there, so that the
        next use finds it without asking again.
    :param where: each name and the module that holds it, relative to the package
        (``'terminal.bag'``); a name that is that module's own last part is the module itself
        (``'checks': 'checks'``).
    :raises AttributeError: (from ``__getattr__``) for a name the package does not have.
    """
    package = namespace['__name__']

    def __getattr__(name: str) -> Any:
        if name not in where:
            raise AttributeError(f'module {package!r} has no attribute {name!r}')
        module = importlib.import_module(f'{package}.{where[name]}')
        value = module if where[name].rpartition('.')[2] == name else getattr(module, name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted({*namespace, *where})

    return __getattr__, __dir__
