"""Attacks beside their twins, and the text reader that only words failures.

The honest and wrong corpora are graded in ``test_corpus_honest_*.py`` and
``test_corpus_wrong_*.py`` (see ``corpus_checks.py``).  Each attack (``corpus_attacks.py``)
scores what its honest twin scores, except those the wire cannot tell from honest code, which
the judge flags for the instructor instead (``tests/test_flags.py``).

``python tests/corpora.py`` prints every learner's score; run with an older checkout's judge it
gives the "before" column of the closing notes.
"""

from __future__ import annotations

import pytest

from ros2nb.checks import source
from corpora import grade_learner
from corpus_attacks import ATTACKS
from corpus_checks import KnowsNothing, failed, scores_what_its_twin_scores, within
from corpus_wrong import WRONG

pytestmark = pytest.mark.timeout(300)


def test_the_text_reader_only_words_failures(tmp_path, monkeypatch):
    """A wrong learner graded with a reader that knows nothing loses the same part as with
    the reader: the text chose the words of its line, never whether the part passed.  With
    the reader it is graded in ``test_corpus_wrong_03_06.py``, which asserts the same parts
    (grading it a second time here cost a worker 25 s, 100 s beside two CPU burners)."""
    learner = WRONG[0]  # the timer as dead code: the reader names it, the judge fails it
    assert learner in within(WRONG, '03', '06')
    monkeypatch.setattr(source.TEXT, 'read', KnowsNothing().read)
    without = failed(grade_learner(learner, tmp_path / 'without'))
    assert set(without) == set(learner.loses), without


TWINS = {learner.name: learner for learner in ATTACKS}
#: Attacks the wire can tell from honest code (the rest are flagged: tests/test_flags.py).
WIRE_ATTACKS = [a for a in ATTACKS if a.twin and not a.same_on_the_wire]


@pytest.mark.parametrize('attack', WIRE_ATTACKS, ids=[a.name for a in WIRE_ATTACKS])
def test_an_attack_scores_what_its_twin_scores(attack, tmp_path):
    scores_what_its_twin_scores(attack, TWINS[attack.twin], tmp_path)
