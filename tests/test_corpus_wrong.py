"""Wrong learners lose exactly their part, and no other (see ``corpus_checks.py``): the wrong
corpus, and every attack's honest twin (``corpus_attacks.py``, ``corpus_reaching.py``), which
the attacks are held to."""

import pytest

from corpora import every_learner, time_limit_s
from corpus_checks import loses_exactly_its_part
from corpus_wrong import WRONG

pytestmark = [pytest.mark.judge, pytest.mark.timeout(time_limit_s(1))]
#: The twins of the attacks: wrong learners too, each graded here once a run.
TWINS = [every_learner()[name] for name in sorted({learner.twin for learner in
                                                   every_learner().values() if learner.twin})]


@pytest.mark.parametrize('learner', WRONG + TWINS, ids=[learner.name for learner in WRONG + TWINS])
def test_a_wrong_learner_loses_exactly_its_part(learner, tmp_path):
    loses_exactly_its_part(learner, tmp_path)
