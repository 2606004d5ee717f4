"""Answers that look alike: what the judge graded of each learner, beside the course's own
answer and every classmate's, by copydetect's winnowed fingerprints (as MOSS does).

Runs on the instructor's host, for ``grading/report.html`` (:mod:`.report`).  What is
compared is what the judge grades of a notebook (:func:`graded`): every answer cell, and
every ``%%part`` cell the learner added, as the file part it writes (a later cell that
writes the same part stands for it, as in the learner's file).  copydetect reads each as
Python with its names, strings, comments and layout set aside, and keeps fingerprints of
:data:`K` characters of what is left; the course's handed-out text (given lines, the
placeholder) is its boilerplate, no one's work.  A set of fingerprints keeps a copy whose
branches were reordered (most of them stay), and a copy padded with code of its own is
measured by the share of the other answer found in it.  Parts too small to be told apart
(:data:`MIN_CHARS`) are compared together, one group per notebook, so that none is left
out.  Pairs at or above :data:`THRESHOLD` are listed for a person to judge.  Nothing here
decides a grade.
"""

from __future__ import annotations

import io
import itertools
import json
import re
import shlex
import textwrap
from pathlib import Path
from typing import Any, NamedTuple, Optional

from ros2nb import nbmeta

#: Share of one answer found in the other at or above which two answers are listed, and the
#: share of the other found in the one they need as well (docs/decisions.md, "Answers alike").
THRESHOLD, FLOOR = 0.85, 0.6
#: Characters of a fingerprint (copydetect's noise threshold: no shorter match counts) and
#: of the filtered code a part needs to be compared on its own; smaller ones are compared in
#: their notebook's group (docs/decisions.md).
K, MIN_CHARS = 12, 40
#: A cell that at least this share of the learners who handed it in (and at least
#: :data:`COMMON_LEARNERS` of them) wrote like the course's answer leaves little to choose
#: (a ``main()`` its comments dictate): it is summed up in one line, not listed pair by pair.
COMMON_SHARE, COMMON_LEARNERS = 0.5, 3
#: Most characters of one part compared: a cell bloated to megabytes costs the report no
#: more than this.
MAX_CHARS = 20_000
#: Who wrote the course's own answer, as the report names it.
COURSE = 'the course\'s answer'
#: The name of a notebook's group of parts too small to compare alone.
SMALL = 'small parts together'
_PART = re.compile(r'### BEGIN SOLUTION\n(.*?)### END SOLUTION', re.S)


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


def _part_of(text: str) -> Optional[tuple[str, str]]:
    """The file and part a ``%%part`` cell writes, or None."""
    first = text.split('\n', 1)[0]
    if not first.startswith('%%part'):
        return None
    try:
        words = [w for w in shlex.split(first)[1:] if not w.startswith('--')]
    except ValueError:
        return None
    return (words[0], words[1]) if len(words) >= 2 else None


def _read(path: Optional[Path]) -> list[dict[str, Any]]:
    try:
        return [c for c in nbmeta.cells(json.loads(path.read_text()))
                if c.get('cell_type') == 'code'] if path else []
    except (OSError, ValueError, AttributeError, TypeError):  # not a notebook: nothing
        return []


class Course(NamedTuple):
    """What the course gives of a notebook: its code cells' texts (no one's work), the
    answer each ``%%part`` belongs to, and the boilerplate's fingerprints."""

    texts: frozenset[str]
    parts: dict[tuple[str, str], str]
    boilerplate: object


def course_of(solution: Optional[Path], handed_out: Optional[Path]) -> Course:
    """The course's side of a notebook: ``solution`` (its answers) and ``handed_out`` (the
    learner's version: given lines and placeholders, the boilerplate)."""
    import numpy as np
    given = _read(handed_out)
    texts = frozenset(nbmeta.text(c) for c in [*_read(solution), *given]
                      if c in given or not nbmeta.nbgrader_metadata(c).get('solution'))
    parts = {}
    for cell in _read(solution):
        meta, part = nbmeta.nbgrader_metadata(cell), _part_of(nbmeta.text(cell))
        if meta.get('solution') and part:
            parts[part] = str(meta.get('grade_id', '?'))
    hashes = set()
    for cell in given:
        hashes |= _fingerprint(learners_part(nbmeta.text(cell))).hashes
    return Course(texts, parts, np.array(sorted(hashes), dtype=np.int64))


def graded(cells: list[dict[str, Any]], course: Course) -> dict[str, str]:
    """Name -> the learner's text of each part the judge grades in a notebook's code cells:
    answer cells by grade id, ``%%part`` cells the learner added by the answer whose part
    they write (``... (an added cell)``) or by file and part; cells as the course gave them
    (unsolved answers, given cells) are left out."""
    found: dict[str, str] = {}
    written: dict[tuple[str, str], str] = {}
    for cell in cells:
        text = nbmeta.text(cell)
        if text in course.texts:
            continue
        meta, part = nbmeta.nbgrader_metadata(cell), _part_of(text)
        if part is not None:
            old = written.pop(part, None)
            if old is not None:
                found.pop(old, None)
            answer = course.parts.get(part)
            own = bool(answer) and meta.get('solution') and meta.get('grade_id') == answer
            name = (str(meta.get('grade_id', '?')) if meta.get('solution') and answer is None
                    else str(answer) if own
                    else f'{answer} (an added cell)' if answer else f'{part[0]} part {part[1]}')
            written[part] = name
        elif meta.get('solution'):
            name = str(meta.get('grade_id', '?'))
        else:
            continue
        found[name] = learners_part(text)[:MAX_CHARS]
    return found


def _fingerprint(text: str, boilerplate: object = None) -> Any:
    """copydetect's fingerprint of ``text`` read as Python (its filtered code, its hashes)."""
    from copydetect import CodeFingerprint  # type: ignore[import-untyped]  # no stubs, no py.typed
    return CodeFingerprint('answer.py', K, 1, boilerplate=boilerplate, language='python',
                           fp=io.StringIO(text))


def _ratio(a: Any, b: Any) -> float:
    """How alike two fingerprinted parts are (0-1), by copydetect's own measure: the larger
    share of either found in the other (a copy padded with dead code keeps the share of the
    original found in it); 0 when the smaller share is under :data:`FLOOR` (one holds far
    more than the other: an answer that builds on a few lines everyone writes, such as a
    ``main()`` with an executor), or when what the two have in common covers fewer than
    :data:`MIN_CHARS` characters of filtered code (too little to tell a copy from chance, as
    a part that small is too little to compare alone)."""
    from copydetect import compare_files
    if not a.hashes or not b.hashes:
        return 0.0
    # Every pair is measured: copydetect's shares count the characters its matches cover,
    # which a few fingerprints in common can cover, so a count of the fingerprints in common
    # is no bound on them (docs/decisions.md).
    overlap, shares, _slices = compare_files(a, b)
    return float(max(shares)) if min(shares) >= FLOOR and overlap >= MIN_CHARS else 0.0


def fingerprints(cells: list[dict[str, Any]], course: Course, small: set[str]) -> dict[str, Any]:
    """name -> fingerprint of each part of :func:`graded`, the ``small`` ones (and those too
    small themselves) in one group, :data:`SMALL`."""
    parts = graded(cells, course)
    alone = {name: _fingerprint(text, course.boilerplate) for name, text in parts.items()
             if name not in small}
    grouped = sorted(name for name in parts if name in small or
                     len(alone[name].filtered_code) < MIN_CHARS)
    found = {name: alone[name] for name in alone if name not in grouped}
    if grouped:
        found[SMALL] = _fingerprint('\n'.join(parts[name] for name in grouped),
                                    course.boilerplate)
    return found


def alike(notebook: str, solution: Optional[Path], handed: dict[str, Path],
          handed_out: Optional[Path] = None) -> tuple[list[Pair], list[Common]]:
    """Pairs of answers of one notebook at or above :data:`THRESHOLD`, most alike first, and
    the cells most of the class wrote like the course's answer (:data:`COMMON_SHARE`), whose
    pairs among those learners are left out.

    :param solution: the course's own notebook (its answers), compared with each learner's.
    :param handed: learner's name as shown -> their notebook file.
    :param handed_out: the learner's version of the notebook (its given lines, boilerplate).
    """
    course = course_of(solution, handed_out)
    own = fingerprints(_read(solution), course, set())
    small = {name for name, found in own.items() if len(found.filtered_code) < MIN_CHARS}
    read = {COURSE: fingerprints(_read(solution), course, small)} if solution else {}
    read.update({who: fingerprints(_read(path), course, small)
                 for who, path in sorted(handed.items())})
    found = _pairs(notebook, read)
    pairs, common = [], []
    for cell in sorted({pair.cell for pair in found}):
        mine = [pair for pair in found if pair.cell == cell]
        near = {pair.second for pair in mine if pair.first == COURSE}
        writers = sum(1 for who, parts in read.items() if who != COURSE and cell in parts)
        if len(near) >= max(COMMON_LEARNERS, COMMON_SHARE * writers):
            common.append(Common(notebook, cell, tuple(sorted(near)), writers))
            near.add(COURSE)
            mine = [pair for pair in mine if not {pair.first, pair.second} <= near]
        pairs += mine
    return sorted(pairs, key=lambda p: (-p.ratio, p.notebook, p.cell, p.first, p.second)), common


def _added(name: str) -> bool:
    """A part only a learner's added cell wrote (no answer's own cell)."""
    return name.endswith(' (an added cell)') or ' part ' in name


def _pairs(notebook: str, read: dict[str, dict[str, Any]]) -> list[Pair]:
    """Every pair at or above :data:`THRESHOLD` (the course's answer first): parts of the
    same name, and each part in an added cell beside every part of the other."""
    found = []
    for (first, a), (second, b) in itertools.combinations(read.items(), 2):
        for cell in sorted(set(a) | set(b)):
            if cell in a and cell in b:
                others = [(a[cell], b[cell])]
            elif _added(cell):
                mine, theirs = (a[cell], b) if cell in a else (b[cell], a)
                others = [(mine, part) for part in theirs.values()]
            else:
                continue
            ratio = max(_ratio(x, y) for x, y in others) if others else 0.0
            if ratio >= THRESHOLD:
                found.append(Pair(notebook, cell, first, second, ratio))
    return found
