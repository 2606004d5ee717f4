"""The course's answers, out of reach of the learner's code in a subject.

Part of the subjects (:mod:`ros2nb.subject`); introduced with the stand-ins in
``03-write-the-publisher.ipynb``.  The modules that hold the course's answers (the stand-ins,
:mod:`ros2nb.judge.stand_ins`; the course's rules, :mod:`ros2nb.rules`; the reference nodes;
the judge and its checks) are never imported by a subject: nothing a subject runs needs them.
A subject forked from a judge comes from a fork server forked before any of them was imported
(:func:`ros2nb.subject.forked.serve_from_here`), or started afresh.  Before the learner's code
is loaded, :func:`shut` takes any that is still named out of ``sys.modules`` and puts a
finder first on ``sys.meta_path`` that refuses to import them, by any name or way the import
system offers (``import``, ``importlib``, ``__import__``, ``ros2nb.rules``); the finder hands
nothing in.  What must stand in for a part a check does not grade is the judge's: it sends the
code of just those stand-ins, compiled in the subject once the learner's code is loaded
(:mod:`ros2nb.subject.commands`).  While grading, the answer files are not even on the
subject's disk (the grader's sandbox hides them); wherever they are, the subject's audit hook
sees code that opens or imports them (:mod:`.seen`).
"""

from __future__ import annotations

import importlib
import importlib.abc
import sys
from types import ModuleType
from typing import Optional, Sequence

#: Modules (and their submodules) that hold a course answer or the judge's expectations.
ANSWERS = ('ros2nb.reference', 'ros2nb.subject.stand_ins', 'ros2nb.judge.stand_ins',
           'ros2nb.rules', 'ros2nb.checks', 'ros2nb.judge', 'ros2nb_instructor')
#: What a judge's own command line is while it forks its subjects' server: its package and
#: main module, before either imports anything of the judge's (:mod:`ros2nb.judge.__main__`).
JUDGE_MAIN = ('ros2nb.judge', 'ros2nb.judge.__main__')
#: The learner's line when their code imports one.
REFUSED = ('{name} holds the course\'s answer: code that is graded cannot import it; write '
           'this part yourself.')


def is_answer(name: str) -> bool:
    """Whether the module ``name`` is one of :data:`ANSWERS` or inside one."""
    return any(name == answer or name.startswith(answer + '.') for answer in ANSWERS)


def answers_loaded() -> list[str]:
    """The answer modules this process imported (the judge's own command line aside)."""
    return sorted(name for name in list(sys.modules)
                  if is_answer(name) and name not in JUDGE_MAIN)


def purge() -> None:
    """Take every answer module out of ``sys.modules`` and off the package that holds it, so
    that no name leads to it."""
    for name in [n for n in list(sys.modules) if is_answer(n)]:
        module = sys.modules.pop(name, None)
        parent, _, last = name.rpartition('.')
        holder = sys.modules.get(parent)
        if holder is not None and getattr(holder, '__dict__', {}).get(last) is module:
            delattr(holder, last)


class Answers(importlib.abc.MetaPathFinder):
    """The finder that refuses the answer modules, first on ``sys.meta_path``."""

    def find_spec(self, fullname: str, path: Optional[Sequence[str]] = None,
                  target: Optional[ModuleType] = None) -> None:
        """Refuse an answer module; otherwise let the next finder look.

        :raises ModuleNotFoundError: with :data:`REFUSED`'s line, for an answer module.
        """
        if is_answer(fullname):
            raise ModuleNotFoundError(REFUSED.format(name=fullname), name=fullname)
        return None


def shut() -> None:
    """Before the learner's code is loaded: no answer module in ``sys.modules``, and the
    finder that refuses them first on ``sys.meta_path``."""
    purge()
    sys.meta_path.insert(0, Answers())
    importlib.invalidate_caches()
