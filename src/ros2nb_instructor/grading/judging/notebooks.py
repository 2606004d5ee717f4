"""The notebooks around a learner's run: what the sandbox executes, and what nbgrader scores.

Part of the grading (:mod:`ros2nb_instructor.grading`), on the instructor's host.  The
learner's kernel never runs a check whose result counts: the graded cells it executes are only
a comment, and their outputs in the notebook nbgrader scores are the judge's (ros2nb.judge),
who ran the checks on the learner's files in a process of its own.  Whatever the learner wrote
into markdown or outputs is shown in the feedback as text, never as HTML or script.
"""

from __future__ import annotations

import copy
import html
import json
import re
from typing import Any, Mapping, Optional

import nbformat
from nbconvert.preprocessors import CoalesceStreamsPreprocessor
from ros2nb.outcomes import CHECK_FAILED, CheckOutcome
from ros2nb.nbmeta import nbgrader_metadata as nbgrader

#: What the learner's kernel runs in place of a graded cell.
CHECKED_OUTSIDE = '# Checked by the grader, outside this notebook (ros2nb.judge).'
#: Output types shown in feedback as they are; others (HTML, JavaScript, SVG) are dropped.
SAFE_MIME_TYPES = ('text/plain', 'image/png', 'image/jpeg')


#: Largest attachment (a pasted image) kept in a markdown cell.
MAX_ATTACHMENT_BYTES = 5_000_000
#: Attachment types shown in the feedback (as images); others are dropped.
SAFE_ATTACHMENT_TYPES = ('image/png', 'image/jpeg')


def _grade_id(cell: Any) -> Optional[str]:
    """A cell's grade id when it is one (a string); a list or a number is none."""
    grade_id = nbgrader(cell).get('grade_id')
    return grade_id if isinstance(grade_id, str) and grade_id else None


def _by_grade_id(nb: nbformat.NotebookNode) -> dict[str, Any]:
    return {grade_id: c for c in nb.cells if (grade_id := _grade_id(c))}


def _clean(cell: Any) -> None:
    if cell.cell_type == 'code':
        cell.outputs, cell.execution_count = [], None


def _course_cells(nb: nbformat.NotebookNode, course: dict[str, Any]) -> list[Any]:
    """The cells of ``nb`` that are the course's (graded or answer) cells, first of each id.

    Metadata claiming a grade id the course does not have, or one already claimed by an
    earlier cell, is removed; the course's own metadata is put back on the others.
    """
    found, seen = [], set()
    for cell in nb.cells:
        grade_id = _grade_id(cell)
        if grade_id is None:
            cell.metadata.pop('nbgrader', None)
            continue
        if grade_id not in course or grade_id in seen:
            cell.metadata.pop('nbgrader', None)
            continue
        seen.add(grade_id)
        cell.metadata['nbgrader'] = copy.deepcopy(course[grade_id].metadata['nbgrader'])
        found.append(cell)
    return found


#: The note of a notebook in which the learner changed no code.
NOT_ATTEMPTED = ('not attempted: its code cells are as the course handed them out, so it was '
                 'not run; 0 points')


def not_attempted(release: nbformat.NotebookNode, submitted: nbformat.NotebookNode) -> bool:
    """True when ``submitted`` holds the release's code cells, in order, text for text.

    Whitespace at either end of a cell does not count as writing; markdown does not run.
    A learner who changed, added, moved or deleted any code cell attempted the notebook
    (it is run: their work may sit in a cell of their own).  Points come only from what
    the learner wrote, so running a notebook without any could only ever give it 0; not
    running it is grading it as not handed in, so the notebooks after it run on the
    workspace the ones before it left (not on the unwritten parts it would have saved).
    """
    def code(nb: nbformat.NotebookNode) -> list[str]:
        return [cell.source.strip() for cell in nb.cells if cell.cell_type == 'code']

    return code(submitted) == code(release)


def for_the_run(release: nbformat.NotebookNode,
                submitted: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The learner's notebook as the sandbox runs it.

    The learner's own cells as they are; every locked cell of the course as the course
    released it; graded cells reduced to a comment; outputs cleared.  Metadata that
    claims a grade id the course does not have (or claims one twice) is removed.
    """
    nb = copy.deepcopy(submitted)
    course = _by_grade_id(release)
    for cell in _course_cells(nb, course):
        grade_id = _grade_id(cell)
        assert grade_id is not None  # _course_cells gives the course's graded cells only
        original = course[grade_id]
        if nbgrader(original).get('locked'):
            cell.source, cell.cell_type = original.source, original.cell_type
        if nbgrader(original).get('grade'):
            cell.source = CHECKED_OUTSIDE
    for cell in nb.cells:
        _clean(cell)
    return nb


def result_outputs(result: Optional[CheckOutcome], problem: Optional[str]
                   ) -> list[nbformat.NotebookNode]:
    """The outputs of a graded cell: the judge's lines, and its verdict when it failed."""
    if result is None:
        reason = problem or 'the grader could not check this cell'
        return [nbformat.v4.new_output('error', ename='GradingError', evalue=reason,
                                       traceback=[f'GradingError: {reason}'])]
    outputs = []
    if result.lines:
        outputs.append(nbformat.v4.new_output('stream', name='stdout',
                                              text='\n'.join(result.lines) + '\n'))
    if not result.passed:
        name, message = result.type or CHECK_FAILED, result.message or ''
        outputs.append(nbformat.v4.new_output(
            'error', ename=name, evalue=message,
            traceback=[*result.traceback, f'{name}: {message}']))
    return outputs


def _escape_markdown(source: str) -> str:
    """Markdown whose HTML shows as text: ``<`` and ``&`` escaped, markdown itself kept."""
    return source.replace('&', '&amp;').replace('<', '&lt;')


def _safe_outputs(outputs: list[nbformat.NotebookNode]) -> list[nbformat.NotebookNode]:
    """Outputs of the safe types only, without their metadata (nbconvert writes an image's
    width and height into the page unquoted: metadata could add an attribute)."""
    kept = []
    for output in outputs:
        if output.get('output_type') in ('display_data', 'execute_result'):
            output['data'] = {k: v for k, v in output.get('data', {}).items()
                              if k in SAFE_MIME_TYPES}
            output['metadata'] = {}
            if not output['data']:
                continue
        kept.append(output)
    return kept


def _safe_attachments(cell: Any) -> None:
    """Keep a markdown cell's pasted PNG and JPEG images; a reference to any other
    attachment becomes a link to nowhere (nbconvert stops at a missing attachment)."""
    kept = {}
    found = cell.get('attachments')
    for name, bundle in (found.items() if isinstance(found, dict) else ()):
        data = {k: v for k, v in bundle.items() if k in SAFE_ATTACHMENT_TYPES
                and isinstance(v, str)} if isinstance(bundle, dict) else {}
        if data and isinstance(name, str):
            kept[name] = data
    cell.pop('attachments', None)
    if kept:
        cell['attachments'] = kept
    cell.source = re.sub(r'attachment:([^\s)"\'>]*)', lambda m: m.group(0) if m.group(1) in kept
                         else '#attachment-not-kept', cell.source)


def drop_large_attachments(nb: nbformat.NotebookNode) -> list[str]:
    """Drop attachments over :data:`MAX_ATTACHMENT_BYTES` from ``nb``; one note for each."""
    notes = []
    for number, cell in enumerate(nb.cells, start=1):
        attachments = cell.get('attachments')
        if not isinstance(attachments, dict):
            continue
        for name, bundle in list(attachments.items()):
            size = len(json.dumps(bundle))
            if size > MAX_ATTACHMENT_BYTES:
                del attachments[name]
                notes.append(f'an attachment of {size // 1_000_000} MB ({str(name)[:60]} in '
                             f'cell {number}) was not kept: attachments over '
                             f'{MAX_ATTACHMENT_BYTES // 1_000_000} MB are dropped')
    return notes


#: Most characters of one markdown cell of the learner's shown in the feedback, and of all
#: of a notebook's: nbconvert's markdown rendering can take time quadratic in a cell's
#: length (docs/decisions.md), and it runs on the host for the whole class.
MAX_MARKDOWN_CELL = 20_000
MAX_MARKDOWN_TOTAL = 100_000
#: Most characters of a code cell of the learner's shown in the feedback (what is graded
#: is the judge's reading of the notebook handed in, never this copy).
MAX_CODE_SHOWN = 50_000
#: Most bytes of outputs (as JSON, images included) shown in a notebook's feedback; the
#: cells after that show a line saying so.
MAX_OUTPUTS_SHOWN = 10_000_000


def bound_markdown(release: nbformat.NotebookNode, nb: nbformat.NotebookNode) -> list[str]:
    """Cut the learner's markdown in ``nb`` to what the host renders in bounded time: each
    cell (markdown or raw) that is not the course's to :data:`MAX_MARKDOWN_CELL` characters,
    all of them to :data:`MAX_MARKDOWN_TOTAL`; one note for each cell cut, with the limit."""
    course = {c.get('id'): c.source for c in release.cells}
    notes, total = [], 0
    for number, cell in enumerate(nb.cells, start=1):
        if cell.cell_type not in ('markdown', 'raw') or course.get(cell.get('id')) == cell.source:
            continue
        room = max(0, min(MAX_MARKDOWN_CELL, MAX_MARKDOWN_TOTAL - total))
        if len(cell.source) > room:
            notes.append(f'markdown cell {number} ({len(cell.source) // 1000} kB) was cut to '
                         f'{room // 1000} kB in the feedback (the grader shows at most '
                         f'{MAX_MARKDOWN_CELL // 1000} kB of a cell, '
                         f'{MAX_MARKDOWN_TOTAL // 1000} kB of a notebook\'s own markdown)')
            cell.source = cell.source[:room] + '\n\n[cut by the grader]'
        total += min(len(cell.source), room)
    return notes


def for_scoring(release: nbformat.NotebookNode, executed: nbformat.NotebookNode,
                results: Mapping[str, CheckOutcome], problem: Optional[str] = None
                ) -> nbformat.NotebookNode:
    """The notebook nbgrader scores and turns into feedback.

    Every graded cell of the course is there exactly once (a deleted one is put back
    where it belongs), with the judge's result as its outputs; the learner's markdown
    and outputs are made safe to show as HTML.

    :param release: the course's released notebook (its graded cells, their metadata).
    :param executed: the learner's notebook as the sandbox ran it.
    :param results: ``{grade_id: outcome}`` from ros2nb.judge.
    :param problem: why nothing could be checked, if so (every graded cell shows it).
    """
    # A kernel sends what a cell prints in as many pieces as its flushes happened to make
    # (more of them on a busy machine): merged, as JupyterLab shows them, the feedback of a
    # notebook is the same wherever and whenever it ran.
    nb, _ = CoalesceStreamsPreprocessor().preprocess(copy.deepcopy(executed), {})
    course_cells = {c.get('id'): c for c in release.cells}
    present = {_grade_id(c): c for c in _course_cells(nb, _by_grade_id(release))}
    previous = None
    for original in release.cells:
        grade_id = _grade_id(original)
        if grade_id is None:
            continue
        cell = present.get(grade_id)
        if cell is None:  # deleted: put the course's cell back after its predecessor
            cell = copy.deepcopy(original)
            _clean(cell)
            index = nb.cells.index(previous) + 1 if previous is not None else 0
            nb.cells.insert(index, cell)
        if nbgrader(original).get('grade'):
            cell.source = original.source
            cell.outputs = result_outputs(results.get(grade_id), problem)
            cell.execution_count = 1
        previous = cell
    shown = 0  # bytes of outputs kept so far
    for index, cell in enumerate(nb.cells):
        if cell.cell_type == 'raw':  # shown as text, never as the HTML it may claim to be
            cell = nb.cells[index] = nbformat.v4.new_markdown_cell(cell.source)
        original = course_cells.get(cell.get('id'))
        theirs = original is None or original.source != cell.source
        if cell.cell_type == 'markdown':
            if theirs:
                cell.source = _escape_markdown(cell.source)
            _safe_attachments(cell)
        elif cell.cell_type == 'code' and not nbgrader(cell).get('grade'):
            if theirs and len(cell.source) > MAX_CODE_SHOWN:
                cell.source = (f'{cell.source[:MAX_CODE_SHOWN]}\n# [the grader shows the first '
                               f'{MAX_CODE_SHOWN // 1000} kB of a cell]')
            cell.outputs = _safe_outputs(cell.get('outputs', []))
            shown += len(json.dumps(cell.outputs))
            if shown > MAX_OUTPUTS_SHOWN:
                cell.outputs = [nbformat.v4.new_output('stream', name='stdout', text=(
                    f'[outputs not shown: the feedback shows {MAX_OUTPUTS_SHOWN // 1_000_000} '
                    'MB of a notebook\'s outputs]'))]
    return nb


def note_notebook(release: nbformat.NotebookNode, reason: str) -> nbformat.NotebookNode:
    """The released notebook with ``reason`` in every graded cell: 0 points, and why."""
    nb = copy.deepcopy(release)
    nb.cells.insert(0, nbformat.v4.new_markdown_cell(
        f'**Grading note:** {html.escape(reason)}'))
    return for_scoring(release, nb, {}, reason)
