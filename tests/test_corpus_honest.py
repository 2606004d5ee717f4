"""Honest learners, in every style, get full marks without the text reader (see
``corpus_checks.py``)."""

import pytest

from corpora import time_limit_s
from corpus_checks import full_marks_without_the_text_reader
from corpus_honest import HONEST

pytestmark = [pytest.mark.judge, pytest.mark.timeout(time_limit_s(1))]


@pytest.mark.parametrize('learner', HONEST, ids=[learner.name for learner in HONEST])
def test_an_honest_learner_gets_full_marks_without_the_text_reader(learner, tmp_path):
    full_marks_without_the_text_reader(learner, tmp_path)
