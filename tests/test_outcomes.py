"""A check's outcome is one value from the judge to the kernel and the grader, read back
field by field where it crosses a process (``ros2nb.outcomes``).

The judge prints it as JSON; the learner's kernel (``checks.dispatch``) and the grader
(``grading.judging.judges``) decode it with ``ros2nb.typed_json``: what does not fit is refused with
one line naming the field, never read by key into a learner's score or feedback.  No ROS here.
"""

from __future__ import annotations

import dataclasses
import json

import pytest

from ros2nb.errors import CheckFailed, LearnerCodeError, NotDecided
from ros2nb.judge_interface import UNFINISHED, captured, show_result
from ros2nb.outcomes import (CHECK_FAILED, LEARNER_CODE_ERROR, NOT_DECIDED, CellChecked,
                             CheckOutcome, NotebookChecked)
from ros2nb.typed_json import Unreadable, decoded
from ros2nb_instructor.grading.judging.judges import _read_verdict, stopped_verdict


def check_that(error: Exception | None):
    """A check's body that prints a line and then raises ``error`` (or passes)."""
    def body() -> None:
        print('Looked at your node.')
        if error is not None:
            raise error
    return body


CASES = [(None, True, None), (CheckFailed('No reading came.'), False, CHECK_FAILED),
         (NotDecided('The graph never showed it.'), False, NOT_DECIDED),
         (LearnerCodeError('ZeroDivisionError: division by zero', ['  File "x.py", line 3']),
          False, LEARNER_CODE_ERROR),
         (KeyError('reply'), False, CHECK_FAILED)]


@pytest.mark.parametrize('error, passed, kind', CASES,
                         ids=['passed', 'failed', 'not decided', 'learner error', 'unexpected'])
def test_an_outcome_crosses_to_the_kernel_as_it_was_decided(error, passed, kind):
    """Captured in the judge, sent as its JSON line, decoded in the kernel: the same value,
    and the kernel shows it as the check would have (its lines, or the same error)."""
    outcome = captured(check_that(error))
    assert (outcome.passed, outcome.type) == (passed, kind)
    assert outcome.lines == ('Looked at your node.',)
    if isinstance(error, KeyError):
        assert outcome.message == UNFINISHED.format(error="KeyError: 'reply'")
    read = decoded(CheckOutcome, json.loads(json.dumps(dataclasses.asdict(outcome))))
    assert read == outcome
    if passed:
        show_result(read)
        return
    with pytest.raises(type(error) if not isinstance(error, KeyError) else CheckFailed) as raised:
        show_result(read)
    assert str(raised.value) == outcome.message
    if isinstance(error, LearnerCodeError):
        assert raised.value.traceback_lines == ['  File "x.py", line 3']


def answer(results: dict) -> str:
    """A grading judge's last line with ``results`` (as JSON data)."""
    return json.dumps({'results': results, 'flags': ['answer cell 03-x line 2: reads frames']})


def test_the_grader_reads_the_judges_answer_or_says_which_field_did_not_fit():
    """The honest answer becomes the verdict's outcomes; an outcome whose ``passed`` is not a
    bool (before: read by key, a truthy string passed the cell in the report) is refused:
    nothing is scored from it, and the note names the field."""
    honest = answer({'03-sensor-hour': {'passed': True, 'lines': ['Check passed: an hour']}})
    verdict = _read_verdict(honest, '', 0)
    assert verdict.problem is None
    assert verdict.results == {'03-sensor-hour': CheckOutcome(True, ('Check passed: an hour',))}
    assert verdict.flags == ('answer cell 03-x line 2: reads frames',)
    planted = answer({'03-sensor-hour': {'passed': 'yes', 'lines': []}})
    refused = _read_verdict(planted, '', 0)
    assert refused.results == {}
    assert refused.problem is not None and "NotebookChecked.results['03-sensor-hour'].passed" \
        in refused.problem and '\n' not in refused.problem, refused.problem


def test_a_judge_stopped_at_a_limit_scores_the_cells_it_had_decided(tmp_path):
    """The lines a judge printed as each cell was decided count; one that does not fit, and
    every other line it printed, do not."""
    source = tmp_path / 'source.ipynb'
    source.write_text(json.dumps({'cells': [
        {'cell_type': 'code', 'source': 'ros2nb.checks.check_a()', 'outputs': [],
         'metadata': {'nbgrader': {'grade': True, 'grade_id': gid, 'points': 1}}}
        for gid in ('03-a', '03-b', '03-c')], 'metadata': {}, 'nbformat': 4,
        'nbformat_minor': 5}))
    lines = [json.dumps({'begin': '03-a'}),
             json.dumps(dataclasses.asdict(CellChecked('03-a', CheckOutcome(True), 1.5))),
             json.dumps({'cell': '03-b', 'result': {'passed': 1}, 'cpu_s': 2.0}),
             'a line that is no JSON']
    verdict = stopped_verdict('\n'.join(lines), source, 60.0, '03-c')
    assert verdict.results == {'03-a': CheckOutcome(True)}
    assert '03-b, 03-c were not checked' in (verdict.problem or ''), verdict.problem


def test_a_notebook_answer_is_refused_whole_when_a_field_is_missing():
    with pytest.raises(Unreadable, match='flags'):
        decoded(NotebookChecked, {'results': {}})
