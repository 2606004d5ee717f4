"""Answers that look alike: each answer cell beside the course's own and every classmate's.

Runs on the instructor's host, for ``grading/report.html`` (:mod:`.report`).  An answer cell
(an nbgrader solution cell) is read as Python tokens (:mod:`tokenize`): comments, blank lines
and indentation are dropped, and every name that is not a keyword or a builtin becomes a
placeholder numbered by its first use, so renaming and reformatting change nothing.  Only the
learner's part counts (between ``### BEGIN SOLUTION`` and ``### END SOLUTION`` when the cell
keeps them): the lines the course gave are everyone's.  Two answers are compared with
:class:`difflib.SequenceMatcher`; pairs at or above :data:`THRESHOLD` are listed for a
person to judge.  Nothing here decides a grade.
"""

from __future__ import annotations

import builtins
import difflib
import io
import json
import itertools
import keyword
import re
import textwrap
import tokenize
from pathlib import Path
from typing import NamedTuple, Optional

from ros2nb import nbmeta

#: Share of matching tokens at or above which two answers are listed (docs/decisions.md).
THRESHOLD = 0.9
#: Fewest tokens an answer needs to be compared: shorter ones (a call, an assignment) are
#: written alike by any honest learner (docs/decisions.md).
MIN_TOKENS = 30
#: A cell that at least this share of the learners who handed it in (and at least
#: :data:`COMMON_LEARNERS` of them) wrote like the course's answer leaves little to choose
#: (a ``main()`` its comments dictate): it is summed up in one line, not listed pair by pair.
COMMON_SHARE, COMMON_LEARNERS = 0.5, 3
#: Most tokens of one answer compared (the course's longest answer has about 100): a cell
#: bloated to megabytes costs the report no more than this (difflib's time grows with the
#: product of the two lengths).
MAX_TOKENS = 2000
#: Who wrote the course's own answer, as the report names it.
COURSE = 'the course\'s answer'
_PART = re.compile(r'### BEGIN SOLUTION\n(.*?)### END SOLUTION', re.S)
_KEPT_NAMES = set(keyword.kwlist) | set(dir(builtins)) | {'self'}


class Common(NamedTuple):
    """A cell most of the class wrote like the course's answer: who, of how many."""

    notebook: str
    cell: str
    alike: tuple[str, ...]
    handed: int


class Pair(NamedTuple):
    """Two answers alike: the notebook, the cell, who wrote each, and how alike (0-1)."""

    notebook: str
    cell: str
    first: str
    second: str
    ratio: float


def learners_part(text: str) -> str:
    """The learner's part of an answer cell: between the solution markers when the cell keeps
    them, else the whole cell; its ``%%part`` line left out."""
    found = _PART.findall(text)
    body = '\n'.join(found) if found else text
    lines = body.splitlines()
    if lines and lines[0].lstrip().startswith('%%'):
        lines = lines[1:]
    return textwrap.dedent('\n'.join(lines)) + '\n'


def tokens(text: str) -> list[str]:
    """The answer as normalised tokens: no comments, layout or names of its own (each such
    name is ``_N``, numbered by its first use); words split on white space when the text
    is not Python."""
    names: dict[str, str] = {}
    found = []
    try:
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            if token.type in (tokenize.COMMENT, tokenize.NL, tokenize.NEWLINE, tokenize.INDENT,
                              tokenize.DEDENT, tokenize.ENDMARKER):
                continue
            word = token.string
            if token.type == tokenize.NAME and word not in _KEPT_NAMES:
                word = names.setdefault(word, f'_{len(names)}')
            found.append(word)
    except (tokenize.TokenError, IndentationError, SyntaxError):
        return text.split()
    return found


def answers(notebook: Path) -> dict[str, list[str]]:
    """grade id -> normalised tokens of each code answer cell of a notebook (none for a file
    that is not a notebook)."""
    try:
        nb = json.loads(notebook.read_text())
        cells = nbmeta.cells(nb)
    except (OSError, ValueError, AttributeError, TypeError):  # not a notebook: no answers
        return {}
    found = {}
    for cell in cells:
        meta = nbmeta.nbgrader_metadata(cell)
        if meta.get('solution') and cell.get('cell_type') == 'code':
            found[str(meta.get('grade_id', '?'))] = \
                tokens(learners_part(nbmeta.text(cell)))[:MAX_TOKENS]
    return found


def _ratio(a: list[str], b: list[str]) -> float:
    """How alike two answers are (0-1); 0 when difflib's quick upper bounds already fall
    under :data:`THRESHOLD` (the full ratio is never above them)."""
    matcher = difflib.SequenceMatcher(None, a, b, autojunk=False)
    if matcher.real_quick_ratio() < THRESHOLD or matcher.quick_ratio() < THRESHOLD:
        return 0.0
    return matcher.ratio()


def alike(notebook: str, course: Optional[Path], handed: dict[str, Path]
          ) -> tuple[list[Pair], list[Common]]:
    """Pairs of answers of one notebook at or above :data:`THRESHOLD`, most alike first, and
    the cells most of the class wrote like the course's answer (:data:`COMMON_SHARE`), whose
    pairs among those learners are left out.

    :param course: the course's own notebook (its solutions), compared with each learner's.
    :param handed: learner's name as shown -> their notebook file.
    """
    read = {who: answers(path) for who, path in sorted(handed.items())}
    if course is not None:
        read = {COURSE: answers(course), **read}
    pairs, common = [], []
    for cell in sorted({cell for found in read.values() for cell in found}):
        mine = _pairs(notebook, cell, read)
        near = {pair.second for pair in mine if pair.first == COURSE}
        writers = sum(1 for who, found in read.items() if who != COURSE and cell in found)
        if len(near) >= max(COMMON_LEARNERS, COMMON_SHARE * writers):
            common.append(Common(notebook, cell, tuple(sorted(near)), writers))
            near.add(COURSE)
            mine = [pair for pair in mine if not {pair.first, pair.second} <= near]
        pairs += mine
    return sorted(pairs, key=lambda p: (-p.ratio, p.notebook, p.cell, p.first, p.second)), common


def _pairs(notebook: str, cell: str, read: dict[str, dict[str, list[str]]]) -> list[Pair]:
    """The pairs of one cell at or above :data:`THRESHOLD` (the course's answer first)."""
    found = []
    written = [(who, cells[cell]) for who, cells in read.items() if cell in cells]
    for (first, a), (second, b) in itertools.combinations(written, 2):
        if min(len(a), len(b)) >= MIN_TOKENS and (ratio := _ratio(a, b)) >= THRESHOLD:
            found.append(Pair(notebook, cell, first, second, ratio))
    return found
