"""What a check passed on, kept with its outcome, so that a pass goes stale when that changes.

Part of :mod:`ros2nb.checks`, in the learner's kernel.  When a check ends, the learner's
progress record (:mod:`ros2nb.graded_parts`) keeps, beside passed or failed, what it ran
on: for a check of the learner's package (03-08), the digest of each file of that notebook
(:data:`ros2nb.course.JUDGED_FILES`); for a check of a function or class of theirs, its
source.  ``ros2nb.progress()`` then says "passed, then changed" (:data:`STALE`) for a pass
whose file is no longer what passed, or whose source the notebook, as saved, no longer
holds (the grader grades the saved notebook).  Nothing grades from it.
"""

from __future__ import annotations

import hashlib
import inspect
import json
from pathlib import Path
from typing import Any, Mapping, Optional, Sequence

from .. import course, nbmeta
from ..graded_parts import Part
from ..terminal.workspace import current_workspace

#: Longest source kept for a check of a function (a learner's answer is a few lines).
MAX_SOURCE = 20_000


def _digest(path: Path) -> str:
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return ''


def taken(notebook: int, args: Sequence[Any]) -> dict[str, Any]:
    """What a check of ``notebook`` (its number) ran on: ``files`` (path -> sha256) for the
    package files it judges, ``source`` for the learner's function or class it was given."""
    evidence: dict[str, Any] = {}
    files = course.JUDGED_FILES.get(notebook, ())
    if files:
        root = current_workspace()
        evidence['files'] = {str(root / f): _digest(root / f) for f in files}
    for arg in args:
        if inspect.isfunction(arg) or inspect.isclass(arg):
            try:
                evidence['source'] = inspect.getsource(arg)[:MAX_SOURCE]
            except (OSError, TypeError):  # defined where no source is kept
                pass
            break
    return evidence


def _lines(text: str) -> list[str]:
    return [line.strip() for line in text.splitlines() if line.strip()]


def _saved_source(notebook: Path) -> Optional[str]:
    """The code cells of the saved notebook, one text (None when it cannot be read)."""
    try:
        cells = nbmeta.cells(json.loads(notebook.read_text()))
    except (OSError, ValueError):
        return None
    return '\n'.join(nbmeta.text(c) for c in cells if c.get('cell_type') == 'code')


def changed(part: Part, outcome: Mapping[str, Any], work: Path) -> Optional[str]:
    """Why a pass of ``part`` no longer stands for the learner's work (None: it does).

    :param work: the learner's work folder (their notebooks, as saved).
    """
    for path, digest in (outcome.get('files') or {}).items():
        if _digest(Path(path)) != digest:
            return f'{Path(path).name} changed since'
    source = outcome.get('source')
    if isinstance(source, str) and source:
        saved = _saved_source(work / f'{part.notebook}.ipynb')
        wanted = _lines(source)
        if saved is not None and not _contains(_lines(saved), wanted):
            return 'the notebook as saved holds other code: save it, or run the check again'
    return None


def _contains(lines: list[str], wanted: list[str]) -> bool:
    """Whether ``wanted`` appears in ``lines`` as consecutive lines."""
    size = len(wanted)
    return any(lines[i:i + size] == wanted for i in range(len(lines) - size + 1))
