"""A fixed sample of the mutation test (``make mistakes``): two mutants of every answer cell.

Each mutant runs as ``benchmarks/mistakes.py`` runs it (``mutation_runs.py``): in a real
kernel as the learner meets it, and through the grader's path; its answer must not be bad
(``mutation_verdicts.py``): one line at the learner's line or naming its effect, with what to
do.  The sample was chosen from a full run: the two cheapest mutants of each answer cell, of
two operators.  A planted bad explanation (the learner's traceback in place of the line,
as checks answered before issue 65) fails the same assertion.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from ros2nb import judge_interface
from ros2nb.errors import LearnerCodeError

from mutation_runs import run_notebook
from mutation_verdicts import verdict

pytestmark = [pytest.mark.kernel, pytest.mark.judge, pytest.mark.ros, pytest.mark.timeout(1800)]

#: Two mutants of every answer cell, by notebook (idents as ``make mistakes`` names them).
SAMPLE: dict[str, list[str]] = {}


def answered_well(outcomes: list[dict]) -> None:
    """Fail, showing the answer, for any mutant answered badly or let through as weak."""
    wrong = [(o['ident'], kind, why, (o['lab']['error'] or o['lab']['lines'])[-3:])
             for o in outcomes for kind, why in [verdict(o)]
             if kind not in ('killed well', 'survived (equivalent)')]
    assert wrong == [], wrong


@pytest.mark.parametrize('number', sorted(SAMPLE))
def test_a_sample_of_mutants_is_answered_well(number, tmp_path):
    outcomes = run_notebook(number, tmp_path / 'outcomes.jsonl', set(SAMPLE[number]),
                            baseline=False)
    assert {o['ident'] for o in outcomes} == set(SAMPLE[number])  # none lost on the way
    answered_well(outcomes)


#: The planted mutant: a name one letter off in 03's constructor, which the check answers in
#: one line at the learner's line.
PLANTED = '03-sensor-constructor | name one edit away | TOPIC -> TOIC (line 12)'


def test_a_planted_bad_explanation_fails_the_sample(tmp_path, monkeypatch):
    """The judge words the learner's error as it did before issue 65 (their traceback, four
    lines and more): the sample's assertion fails, naming the mutant."""
    def traceback_instead(what: str, error: dict, *, context: str = '') -> Exception:
        return LearnerCodeError(f'{what} raised{context}: {error["type"]}: {error["message"]}',
                                error.get('traceback', []))

    original = judge_interface.learner_error
    for module in list(sys.modules.values()):
        if module.__name__.startswith('ros2nb') and \
                getattr(module, 'learner_error', None) is original:
            monkeypatch.setattr(module, 'learner_error', traceback_instead)
    outcomes = run_notebook('03', Path(tmp_path) / 'planted.jsonl', {PLANTED}, baseline=False)
    with pytest.raises(AssertionError, match='TOIC'):
        answered_well(outcomes)
