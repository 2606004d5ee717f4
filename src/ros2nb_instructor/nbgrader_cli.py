"""The command that runs nbgrader's command line (``nbgrader ARGS``) for the course's tools.

nbgrader's own entry point, run by the course's Python, with one change: jsonschema (which
nbformat imports) would import ``rfc3987_syntax`` if it could, and that builds a parser for
IRIs at import, a second of CPU for a format no notebook uses.  Marked absent, jsonschema
goes without it, as it does wherever that package is not installed.
"""

from __future__ import annotations

import sys

_MAIN = ("import sys; sys.modules.setdefault('rfc3987_syntax', None); "
         "sys.argv[0] = 'nbgrader'; from nbgrader.apps.nbgraderapp import main; main()")


def nbgrader_argv(*args: str) -> list[str]:
    """Return the argv of ``nbgrader ARGS``, e.g. ``nbgrader_argv('autograde', 'ps1')``."""
    return [sys.executable, '-c', _MAIN, *args]
