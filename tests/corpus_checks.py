"""What the corpora's tests assert, one function per corpus, one test file per meaning
(``test_corpus_honest.py``, ``test_corpus_wrong.py``, ``test_corpora.py`` for the attacks).

- An honest learner (``corpus_honest.py``) gets full marks, and gets them with the judge's
  reader of their text replaced by one that knows nothing: no point depends on reading the
  learner's code (:data:`ros2nb.checks.source.TEXT`); and the judge flags nothing, neither
  in their text nor as their code runs (the subjects' audit hooks).
- A wrong learner (``corpus_wrong.py``) loses exactly the part it gets wrong, each with a
  one-line message.
- An attack (``corpus_attacks.py``) scores no more than its honest twin: it loses every
  part its twin loses.  The twin itself is a wrong learner, graded once a run with the wrong
  corpus (``test_corpus_wrong.py``), which shows that it loses exactly those parts: the
  attack is held to them, not graded beside it again.
"""

from __future__ import annotations

from pathlib import Path

from corpora import Learner, expected_score, grade_learner, judged, score
from ros2nb.outcomes import CheckOutcome


def failed(results: dict[str, CheckOutcome]) -> dict[str, str]:
    """grade id -> message, of the parts that failed."""
    return {gid: r.message or '' for gid, r in results.items() if not r.passed}


def full_marks_without_the_text_reader(learner: Learner, root: Path) -> None:
    results, flags, _cpu_s = judged(learner, root, knows_nothing=True)
    assert failed(results) == {}, (learner.name, failed(results))
    assert flags == [], (learner.name, flags)


def loses_exactly_its_part(learner: Learner, root: Path) -> None:
    results = grade_learner(learner, root)
    lost = failed(results)
    assert set(lost) == set(learner.loses), lost
    assert all(message and '\n' not in message for message in lost.values()), lost
    assert score(learner, results) == expected_score(learner)


def scores_what_its_twin_scores(attack: Learner, twin: Learner, root: Path) -> None:
    attacked = grade_learner(attack, root)
    # The protection is that an attack gains nothing: it loses every part its twin loses.
    # It may lose more: a flood logged outside the runtime (not spun on the judge's clock,
    # so never acknowledged) can still be arriving when a later part of the same notebook
    # listens, and then that part hears it too.
    assert set(failed(attacked)) >= set(twin.loses), failed(attacked)
    assert score(attack, attacked) <= expected_score(twin)
