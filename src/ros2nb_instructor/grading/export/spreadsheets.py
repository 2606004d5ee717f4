"""Every CSV the grader writes, made so that a spreadsheet shows each cell as a value.

Runs on the instructor's host.  A cell that begins with ``=``, ``+``, ``-``, ``@``, a tab
or a carriage return is a formula to Excel, LibreOffice and Google Sheets; a learner's
folder name such as ``=HYPERLINK(...)`` would run when the instructor opens ``grades.csv``.
Every text cell of every CSV the grader writes goes through :func:`safe_cell`, which puts
a ``'`` in front of those (OWASP, "CSV Injection"); numbers and blanks stay as they are.
The one way to write such a file is :func:`write_csv`.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Iterable, Sequence, Union

#: What makes a spreadsheet read a cell as a formula (OWASP, "CSV Injection").
FORMULA_STARTS = ('=', '+', '-', '@', '\t', '\r')
#: A cell: text, or a number written as ``%g`` (a score, never a formula).
Cell = Union[str, float, int]


def safe_cell(cell: Cell) -> str:
    """``cell`` as a spreadsheet shows it as a value, never runs it: text beginning with
    ``=``, ``+``, ``-``, ``@``, a tab or a carriage return gets a ``'`` in front (the rest
    stays as it is); a number is written as ``%g``."""
    if isinstance(cell, (int, float)) and not isinstance(cell, bool):
        return f'{cell:g}'
    text = str(cell)
    return f"'{text}" if text.startswith(FORMULA_STARTS) else text


def write_csv(path: Path, header: Sequence[str], rows: Iterable[Sequence[Cell]]) -> None:
    """Write ``header`` and ``rows`` to ``path`` as UTF-8 CSV (the csv module's quoting),
    every cell through :func:`safe_cell`."""
    with open(path, 'w', newline='', encoding='utf-8') as stream:
        out = csv.writer(stream)
        out.writerow([safe_cell(c) for c in header])
        out.writerows([safe_cell(c) for c in row] for row in rows)
