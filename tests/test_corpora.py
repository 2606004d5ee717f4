"""Our own learners, graded through the judge's grading path, one notebook each.

- Honest learners (``corpus_honest.py``), in other valid styles, get full marks, and get them
  with the judge's reader of their text replaced by one that knows nothing: no point depends
  on reading the learner's code (:data:`ros2nb.checks.source.TEXT`).
- Wrong learners (``corpus_wrong.py``) lose exactly the part they get wrong.
- Each attack (``corpus_attacks.py``) scores what its honest twin scores, except those the
  wire cannot tell from honest code, which the judge flags for the instructor instead
  (``tests/test_flags.py``).

``python tests/corpora.py`` prints the same scores; run with an older checkout's judge it
gives the "before" column of the closing notes.
"""

from __future__ import annotations

import pytest

from ros2nb.checks import source
from corpora import Learner, expected_score, grade_learner, score
from corpus_attacks import ATTACKS
from corpus_honest import HONEST
from corpus_wrong import WRONG

pytestmark = pytest.mark.timeout(300)


class KnowsNothing(source.TextReader):
    """A reader of the learner's text that never finds anything."""

    def read(self, path):
        return None


def _failed(results: dict) -> dict[str, str]:
    return {gid: r.get('message', '') for gid, r in results.items() if not r['passed']}


@pytest.mark.parametrize('learner', HONEST, ids=[learner.name for learner in HONEST])
def test_an_honest_learner_gets_full_marks_without_the_text_reader(learner: Learner, tmp_path,
                                                                   monkeypatch):
    monkeypatch.setattr(source.TEXT, 'read', KnowsNothing().read)
    results = grade_learner(learner, tmp_path)
    assert _failed(results) == {}, learner.name


@pytest.mark.parametrize('learner', WRONG, ids=[learner.name for learner in WRONG])
def test_a_wrong_learner_loses_exactly_its_part(learner: Learner, tmp_path):
    results = grade_learner(learner, tmp_path)
    failed = _failed(results)
    assert set(failed) == set(learner.loses), failed
    assert all(message and '\n' not in message for message in failed.values()), failed
    assert score(learner, results) == expected_score(learner)


def test_the_text_reader_only_words_failures(tmp_path, monkeypatch):
    """A wrong learner graded with a reader that knows nothing loses the same part: the text
    chose the words of its line, never whether the part passed."""
    learner = WRONG[0]  # the timer as dead code: the reader names it, the judge fails it
    with_text = _failed(grade_learner(learner, tmp_path / 'with'))
    monkeypatch.setattr(source.TEXT, 'read', KnowsNothing().read)
    without = _failed(grade_learner(learner, tmp_path / 'without'))
    assert set(with_text) == set(without) == set(learner.loses)


TWINS = {learner.name: learner for learner in ATTACKS}


#: Attacks the wire can tell from honest code (the rest are flagged: tests/test_flags.py).
WIRE_ATTACKS = [a for a in ATTACKS if a.twin and not a.same_on_the_wire]


@pytest.mark.parametrize('attack', WIRE_ATTACKS, ids=[a.name for a in WIRE_ATTACKS])
def test_an_attack_scores_what_its_twin_scores(attack: Learner, tmp_path):
    twin = TWINS[attack.twin]
    attacked = grade_learner(attack, tmp_path / 'attack')
    honest = grade_learner(twin, tmp_path / 'twin')
    assert set(_failed(honest)) == set(twin.loses)
    assert set(_failed(attacked)) == set(_failed(honest)), _failed(attacked)
    assert score(attack, attacked) == score(twin, honest)
