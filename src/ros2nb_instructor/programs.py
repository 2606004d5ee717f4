"""Other programs the course's tools start (``nbgrader``, ``jupyter lab``), run by the
course's Python.

Each is its own entry point, with one change: jsonschema (which nbformat and Jupyter's
server import) would import ``rfc3987_syntax`` if it could, and that builds a parser for
IRIs at import, for a format no notebook uses (the lab's server answered after 2.3-3.9 CPU-s
with it, 1.1-1.2 without, on a slow machine).  Marked absent, jsonschema goes without it, as
it does wherever that package is not installed.  ``ros2nb_instructor`` marks it as it is
imported (see there): each program imports it first.
"""

from __future__ import annotations

import sys

_MAIN = ("import sys, ros2nb_instructor; "
         "sys.argv[0] = {name!r}; from {module} import main; sys.exit(main())")


def program_argv(name: str, module: str, *args: str) -> list[str]:
    """Return the argv that runs program ``name`` (``module``'s ``main()``) with ``args``.

    :param name: the program as its messages name it (its ``sys.argv[0]``), e.g. ``'nbgrader'``.
    :param module: the module whose ``main()`` is the program, e.g. ``'jupyterlab.labapp'``.
    """
    return [sys.executable, '-c', _MAIN.format(name=name, module=module), *args]


def nbgrader_argv(*args: str) -> list[str]:
    """Return the argv of ``nbgrader ARGS``, e.g. ``nbgrader_argv('autograde', 'ps1')``."""
    return program_argv('nbgrader', 'nbgrader.apps.nbgraderapp', *args)
