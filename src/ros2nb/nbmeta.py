"""What the course reads of a notebook's JSON: its cells, their text, their nbgrader metadata.

Plain JSON, no Jupyter import: the judge (in its sandbox) and the grader (on the
instructor's host) read notebooks the same way, and neither trusts a cell to be well formed.
"""

from __future__ import annotations

from typing import Any

#: Tag of the course's cells a graded answer may rely on (imports, constants).
CONTEXT_TAG = 'grading-context'
#: How a figure's caption line begins in a cell's output (``ros2nb.figures`` writes it, the
#: course's website reads the picture's alternative text by it).
CAPTION_START = 'Figure: '


def cells(notebook: dict[str, Any]) -> list[dict[str, Any]]:
    """The notebook's cells that are JSON objects (a malformed cell is left out)."""
    found = notebook.get('cells', []) if isinstance(notebook, dict) else []
    return [c for c in found if isinstance(c, dict)] if isinstance(found, list) else []


def text(cell: dict[str, Any]) -> str:
    """A cell's source as one string (nbformat stores either a string or a list of lines)."""
    source = cell.get('source', '')
    if isinstance(source, list):
        return ''.join(line for line in source if isinstance(line, str))
    return source if isinstance(source, str) else ''


def tags(cell: dict[str, Any]) -> list[str]:
    """A cell's tags (none when its metadata holds none, or none that make sense)."""
    meta = cell.get('metadata', {})
    found = meta.get('tags', []) if isinstance(meta, dict) else []
    return [t for t in found if isinstance(t, str)] if isinstance(found, list) else []


def nbgrader_metadata(cell: dict[str, Any]) -> dict[str, Any]:
    """A notebook cell's nbgrader metadata (empty when it has none, or none that makes sense)."""
    meta = cell.get('metadata', {})
    value = meta.get('nbgrader', {}) if isinstance(meta, dict) else {}
    return value if isinstance(value, dict) else {}


def graded_cells(notebook: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
    """The code cells nbgrader grades (the judge runs their checks), in notebook order, as
    ``(grade_id, cell)``."""
    return [(str(meta.get('grade_id')), cell) for cell in cells(notebook)
            for meta in [nbgrader_metadata(cell)]
            if meta.get('grade') and cell.get('cell_type') == 'code']
