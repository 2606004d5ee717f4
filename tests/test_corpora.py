"""Attacks held to their twins, and the text reader that only words failures.

The honest and wrong corpora are graded in ``test_corpus_honest.py`` and
``test_corpus_wrong.py`` (see ``corpus_checks.py``), the attacks' honest twins with the wrong
corpus: each twin loses exactly its parts.  Each attack (``corpus_attacks.py``) loses every
part its twin loses, except those the wire cannot tell from honest code, which the judge
flags for the instructor instead (``tests/test_flags.py``).  The attacks that reach into the
process they run in (``corpus_reaching.py``) are graded as the grader grades them (the judge and
each subject sandboxed), with seeds of the drawn inputs new in every run: the sixth hostile
class's with two (each must score exactly its twin's score with both), the earlier ones with
one (a second doubled their cost: docs/decisions.md).  Each loses its twin's parts, its lost
parts say why in one line, and those the subject's audit hook sees (``seen``) are noted at
run time, never a verdict.

``python tests/corpora.py`` prints every learner's score; run with an older checkout's judge it
gives the "before" column of the closing notes.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

from corpora import (BESIDE_JUDGES_S, expected_score, grade_learner, judged_in_sandbox, score,
                     time_limit_s)
from corpus_attacks import ATTACKS
from corpus_checks import failed, scores_what_its_twin_scores
from corpus_honest import HONEST
from corpus_reaching import REACHING, SEVENTH_TWINS
from ros2nb.checks.drawn import new_seed
from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.judging.settings import JUDGE_TIMEOUT_S as SANDBOXED_JUDGE_S

#: Each test grades one learner.
pytestmark = [pytest.mark.judge, pytest.mark.timeout(time_limit_s(1))]
TWINS = {learner.name: learner for learner in [*ATTACKS, *HONEST, *SEVENTH_TWINS]}
#: The seeds of this run's gradings of the reaching attacks (each pytest-xdist worker draws
#: its own: a new pair every run); the sixth class's attacks are graded with both.
SEEDS = (new_seed(), new_seed())
#: (attack, which seed): the sixth class's twice, the earlier attacks once.
REACHING_RUNS = [pytest.param(attack, run, marks=[pytest.mark.xfail(
    strict=True, reason=attack.extra['xfail'])] if 'xfail' in attack.extra else [],
    id=f'{attack.name}-seed {run + 1}') for attack in REACHING
    for run in ((0, 1) if attack.extra.get('sixth') or attack.extra.get('seventh') else (0,))]
#: Where a grader whose temporary folder is not /tmp keeps its learners' folders (the seventh
#: class's ``outside_tmp``): a subject's sandbox puts a tmpfs of its own on /tmp alone.
OUTSIDE_TMP = Path('/var/tmp')


@pytest.mark.parametrize('knows_nothing', [False, True],
                         ids=['with the reader', 'with a reader that knows nothing'])
def test_the_text_reader_only_words_failures(knows_nothing, tmp_path):
    """Graded with the judge's reader of their text or with one that knows nothing, a learner
    loses the same part: the text chose the words of its line, never whether the part passed.
    The sensor without a timer: the reader names what is missing, and without it the line
    says only what the judge saw (which also shows the reader was replaced in the judge).
    One grading a test, so that each has the whole of its judge's time limit."""
    learner = TWINS['03 twin: no timer']
    lost = failed(grade_learner(learner, tmp_path, knows_nothing=knows_nothing))
    assert set(lost) == set(learner.loses), lost
    if knows_nothing:
        assert 'has no timer' not in lost['sensor-constructor'], lost
    else:
        assert 'TemperatureSensor has no timer' in lost['sensor-constructor'], lost


#: Attacks the wire can tell from honest code (the rest are flagged: tests/test_flags.py).
WIRE_ATTACKS = [a for a in ATTACKS if a.twin and not a.same_on_the_wire]


@pytest.mark.parametrize('attack', WIRE_ATTACKS, ids=[a.name for a in WIRE_ATTACKS])
def test_an_attack_scores_what_its_twin_scores(attack, tmp_path):
    scores_what_its_twin_scores(attack, TWINS[attack.twin], tmp_path)


@pytest.mark.sandbox
@pytest.mark.skipif(bubblewrap.problem() is not None, reason=str(bubblewrap.problem()))
@pytest.mark.timeout(SANDBOXED_JUDGE_S + BESIDE_JUDGES_S)  # one grading, the grader's way
@pytest.mark.parametrize('attack, run', REACHING_RUNS)
def test_reaching_in_scores_at_most_its_twin_and_says_so(attack, run, tmp_path):
    """Graded as the grader grades: in its sandboxes the course's answers are not on a
    subject's disk and no subject reads what another wrote, and no verdict comes from what
    the audit hooks saw (they only note it)."""
    seed, twin = SEEDS[run], TWINS[attack.twin]
    if attack.extra.get('outside_tmp'):
        with tempfile.TemporaryDirectory(prefix='ros2nb-corpus-', dir=OUTSIDE_TMP) as root:
            Path(root).chmod(0o711)  # the sandboxes' own user passes, as through tmp_path
            attacked, flags = judged_in_sandbox(attack, Path(root), seed=seed)
    else:
        attacked, flags = judged_in_sandbox(attack, tmp_path, seed=seed)
    lost = failed(attacked)
    context = (seed, lost, flags)
    assert set(lost) >= set(twin.loses), context
    assert score(attack, attacked) <= expected_score(twin), context
    if attack.extra.get('sixth') or attack.extra.get('seventh'):
        assert score(attack, attacked) == expected_score(twin), context
    assert all(message and '\n' not in message for message in lost.values()), context
    assert any('at run time' in flag for flag in flags) == attack.seen, context
