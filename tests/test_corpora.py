"""Attacks beside their twins, and the text reader that only words failures.

The honest and wrong corpora are graded in ``test_corpus_honest.py`` and
``test_corpus_wrong.py`` (see ``corpus_checks.py``).  Each attack (``corpus_attacks.py``)
scores what its honest twin scores, except those the wire cannot tell from honest code, which
the judge flags for the instructor instead (``tests/test_flags.py``).

``python tests/corpora.py`` prints every learner's score; run with an older checkout's judge it
gives the "before" column of the closing notes.
"""

from __future__ import annotations

import pytest

from corpora import grade_learner
from corpus_attacks import ATTACKS
from corpus_checks import failed, scores_what_its_twin_scores

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]
TWINS = {learner.name: learner for learner in ATTACKS}


def test_the_text_reader_only_words_failures(tmp_path):
    """A learner graded with a reader of their text that knows nothing loses the same part as
    with the reader: the text chose the words of its line, never whether the part passed.
    The sensor without a timer: the reader names what is missing, and without it the line
    says only what the judge saw (which also shows the reader was replaced in the judge)."""
    learner = TWINS['03 twin: no timer']
    lost = {knows_nothing: failed(grade_learner(learner, tmp_path / str(knows_nothing),
                                                knows_nothing=knows_nothing))
            for knows_nothing in (False, True)}
    assert set(lost[False]) == set(lost[True]) == set(learner.loses), lost
    assert 'TemperatureSensor has no timer' in lost[False]['sensor-constructor'], lost
    assert 'has no timer' not in lost[True]['sensor-constructor'], lost


#: Attacks the wire can tell from honest code (the rest are flagged: tests/test_flags.py).
WIRE_ATTACKS = [a for a in ATTACKS if a.twin and not a.same_on_the_wire]


@pytest.mark.parametrize('attack', WIRE_ATTACKS, ids=[a.name for a in WIRE_ATTACKS])
def test_an_attack_scores_what_its_twin_scores(attack, tmp_path):
    scores_what_its_twin_scores(attack, TWINS[attack.twin], tmp_path)
