"""Honest learners get full marks without the text reader, notebooks 06-10 (see
``corpus_checks.py``)."""

import pytest

from corpus_checks import full_marks_without_the_text_reader, within
from corpus_honest import HONEST

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]
LEARNERS = within(HONEST, '06', '10')


@pytest.mark.parametrize('learner', LEARNERS, ids=[learner.name for learner in LEARNERS])
def test_an_honest_learner_gets_full_marks_without_the_text_reader(learner, tmp_path):
    full_marks_without_the_text_reader(learner, tmp_path)
