"""The checks of notebook 10 as the grader runs them: this process is the judge.

Each answer cell runs from source in a real subject process; the judge listens to the real
replay over DDS and reads the real bag the subject wrote. The kernel's half is
``test_checks_bag_kernel.py``; the cases are ``bag_cases.py``'s.
"""

import re
import sys

import pytest

pytestmark = [pytest.mark.judge,
              pytest.mark.timeout(600),
              pytest.mark.skipif(sys.version_info < (3, 11),
                                 reason='bags need Python 3.11 or newer (rosbags needs apsw)')]

from ros2nb.judge_interface import AnswerRef  # noqa: E402
from ros2nb.errors import CheckFailed  # noqa: E402
from ros2nb.judge.session import Session  # noqa: E402

import ros2nb  # noqa: E402
from bag_cases import (ANSWERS, CHECKS, CONTEXT, MISTAKE_IDS, MISTAKES, edited,  # noqa: E402
                       recording_length, with_hour)


#: The judge session's workspace is caught up to notebook 10 (tests/conftest.py: session).
CAUGHT_UP_TO = 10


def judge(session: Session, name: str, answer: str, context: str = CONTEXT) -> None:
    """Run the check of ``name`` on the answer's source, in a subject of this judge."""
    ref = AnswerRef(name, (context, answer))
    try:
        ros2nb.checks.run_check(CHECKS[name].__name__, session, ref)
    finally:
        session.drop(('cells', ref.sources))  # one subject at a time


def test_the_solutions_pass(session, capsys):
    for name, answer in ANSWERS.items():
        judge(session, name, answer)
    assert capsys.readouterr().out.count('Check passed:') == 3


@pytest.mark.parametrize('name, label, old, new, pattern', MISTAKES, ids=MISTAKE_IDS)
def test_a_mistake_gets_one_line(session, name, label, old, new, pattern, monkeypatch):
    seconds = recording_length(name, old)
    if seconds is not None:
        monkeypatch.setattr(ros2nb.course, 'RECORD_S', float(seconds))
    with pytest.raises(CheckFailed) as caught:
        judge(session, name, edited(name, old, new), with_hour(CONTEXT, seconds))
    message = str(caught.value)
    assert '\n' not in message and re.search(pattern, message), message
