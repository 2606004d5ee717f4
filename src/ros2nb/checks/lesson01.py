"""Checks of notebook 01, create a workspace: a path that ``~`` really expands into the home folder.

Part of :mod:`ros2nb.checks`.  The learner's function is called in the kernel there; the
judge calls it from the learner's answer cell in a subject (:mod:`.answers`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Optional

from ..errors import CheckFailed
from .answers import answer_results, decoded, type_name_of
from ..judge_interface import AnswerRef, Judge
from .base import call_learner, direct


@direct
def check_expanded_path(judge: Optional[Judge], make_path: Any, *, ends_with: str) -> str:
    """Check the path a function returns is absolute, inside home and ends with ``ends_with``.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param make_path: the learner's function (called with no arguments).
    :param ends_with: how the path must end, e.g. ``'Documents/ROS2_and_RL_Tutorials'``.
    :raises CheckFailed: e.g. for the tutorial's ``/Documents/...`` (no ``~``).
    """
    if isinstance(make_path, AnswerRef) and judge is not None:  # their subject's home
        home = judge.answer_home(make_path)  # the subject that answers: its own home
        path = decoded(answer_results(judge, make_path, [[]])[0], f'{make_path.name}()')
        shown = '~'  # the grader's folder for it: its name would differ from run to run
    else:
        path, home = call_learner(make_path), Path.home()
        shown = str(home)
    if not isinstance(path, Path):
        raise CheckFailed(f'{make_path.__name__}() returned {type_name_of(path)} {path!r}; return '
                          'a pathlib.Path.')
    if '~' in str(path):
        raise CheckFailed(f'{path} still contains "~": Python does not expand it, call '
                          '.expanduser().')
    if home not in path.parents:
        raise CheckFailed(f'{path} is not inside your home folder {shown}: a path that '
                          'starts with "/" starts at the root of the disk.')
    if shown == '~':  # as the grader shows it: the subject's folder is named anew each run
        path = Path('~') / path.relative_to(home)
    if not str(path).endswith(ends_with):
        raise CheckFailed(f'{path} should end with {ends_with}.')
    return f'{path} is inside your home folder.'
