"""Wrong learners lose exactly their part, notebooks 03-06 (see ``corpus_checks.py``)."""

import pytest

from corpus_checks import loses_exactly_its_part, within
from corpus_wrong import WRONG

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]
LEARNERS = within(WRONG, '03', '06')


@pytest.mark.parametrize('learner', LEARNERS, ids=[learner.name for learner in LEARNERS])
def test_a_wrong_learner_loses_exactly_its_part(learner, tmp_path):
    loses_exactly_its_part(learner, tmp_path)
