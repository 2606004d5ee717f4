"""Wrong learners lose exactly their part, and no other (see ``corpus_checks.py``)."""

import pytest

from corpora import time_limit_s
from corpus_checks import loses_exactly_its_part
from corpus_wrong import WRONG

pytestmark = [pytest.mark.judge, pytest.mark.timeout(time_limit_s(1))]


@pytest.mark.parametrize('learner', WRONG, ids=[learner.name for learner in WRONG])
def test_a_wrong_learner_loses_exactly_its_part(learner, tmp_path):
    loses_exactly_its_part(learner, tmp_path)
