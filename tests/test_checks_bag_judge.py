"""The checks of notebook 10 as the grader runs them: this process is the judge.

Each answer cell runs from source in a real subject process; the judge listens to the real
replay over DDS and reads the real bag the subject wrote. The kernel's half is
``test_checks_bag_kernel.py``; the cases are ``bag_cases.py``'s.
"""

import os
import re
import sys

import pytest

pytestmark = [pytest.mark.timeout(600),
              pytest.mark.skipif(sys.version_info < (3, 11),
                                 reason='bags need Python 3.11 or newer (rosbags needs apsw)')]

from ros2nb.checks.base import AnswerRef, bind_judge  # noqa: E402
from ros2nb.checks.dispatch import IN_JUDGE_ENV  # noqa: E402
from ros2nb.errors import CheckFailed  # noqa: E402
from ros2nb.judge.session import Session  # noqa: E402

from bag_cases import (ANSWERS, CHECKS, CONTEXT, MISTAKE_IDS, MISTAKES, edited,  # noqa: E402
                       workspace)  # noqa: F401 - workspace is a fixture


@pytest.fixture(scope='module')
def session(workspace):
    """A judge session, bound as the checks' judge: this process is the judge."""
    saved = os.environ.get(IN_JUDGE_ENV)
    os.environ[IN_JUDGE_ENV] = '1'
    session = Session(workspace)
    bind_judge(session)
    yield session
    bind_judge(None)
    session.close()
    if saved is None:
        os.environ.pop(IN_JUDGE_ENV, None)
    else:
        os.environ[IN_JUDGE_ENV] = saved


def judge(session: Session, name: str, answer: str) -> None:
    """Run the check of ``name`` on the answer's source, in a subject of this judge."""
    ref = AnswerRef(name, (CONTEXT, answer))
    try:
        CHECKS[name](ref)
    finally:
        session.drop(('cells', ref.sources))  # one subject at a time


def test_the_solutions_pass(session, capsys):
    for name, answer in ANSWERS.items():
        judge(session, name, answer)
    assert capsys.readouterr().out.count('Check passed:') == 3


@pytest.mark.parametrize('name, label, old, new, pattern', MISTAKES, ids=MISTAKE_IDS)
def test_a_mistake_gets_one_line(session, name, label, old, new, pattern):
    with pytest.raises(CheckFailed) as caught:
        judge(session, name, edited(name, old, new))
    message = str(caught.value)
    assert '\n' not in message and re.search(pattern, message), message
