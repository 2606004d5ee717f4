"""The course's answers, out of reach of the learner's code in a subject.

Part of the subjects (:mod:`ros2nb.subject`); introduced with the stand-ins in
``03-write-the-publisher.ipynb``.  A subject runs the learner's code beside modules that hold
the course's answers: the stand-ins (:mod:`ros2nb.subject.stand_ins`), the course's rules
(:mod:`ros2nb.rules`), the reference nodes, and, in a subject forked from a judge, the
judge's checks.  Before the learner's code is loaded, :func:`shut` takes every one of them
out of ``sys.modules`` and off its package, and puts a finder first on ``sys.meta_path``
that refuses to import them, by any name or way the import system offers (``import``,
``importlib``, ``__import__``, ``ros2nb.rules``).  What must stand in for a
missing part is handed in afterwards (:meth:`Answers.hand_in`) and kept where only the
subject's own objects hold it.  Code that still reaches one (the garbage collector, stack
frames, ``sys.meta_path``) is flagged for the instructor (:mod:`ros2nb.judge.flags`).
"""

from __future__ import annotations

import importlib
import importlib.abc
import sys
from types import ModuleType
from typing import Optional, Sequence

#: Modules (and their submodules) that hold a course answer or the judge's expectations.
ANSWERS = ('ros2nb.reference', 'ros2nb.subject.stand_ins', 'ros2nb.rules', 'ros2nb.checks',
           'ros2nb.judge', 'ros2nb_instructor')
#: The course's stand-ins, handed in once the learner's code is loaded.
STAND_INS = 'ros2nb.subject.stand_ins'
#: The learner's line when their code imports one.
REFUSED = ('{name} holds the course\'s answer: code that is graded cannot import it; write '
           'this part yourself.')


def is_answer(name: str) -> bool:
    """Whether the module ``name`` is one of :data:`ANSWERS` or inside one."""
    return any(name == answer or name.startswith(answer + '.') for answer in ANSWERS)


def purge() -> None:
    """Take every answer module out of ``sys.modules`` and off the package that holds it
    (``ros2nb.checks``, ``ros2nb.subject.stand_ins``), so that no name leads to it."""
    for name in [n for n in list(sys.modules) if is_answer(n)]:
        module = sys.modules.pop(name, None)
        parent, _, last = name.rpartition('.')
        holder = sys.modules.get(parent)
        if holder is not None and getattr(holder, '__dict__', {}).get(last) is module:
            delattr(holder, last)


class Answers(importlib.abc.MetaPathFinder):
    """The finder that refuses the answer modules, first on ``sys.meta_path``; the subject
    keeps the one instance and opens it only while it imports a stand-in itself."""

    def __init__(self) -> None:
        self._open = False
        self._handed: dict[str, ModuleType] = {}

    def find_spec(self, fullname: str, path: Optional[Sequence[str]] = None,
                  target: Optional[ModuleType] = None) -> None:
        """Refuse an answer module while shut; otherwise let the next finder look.

        :raises ModuleNotFoundError: with :data:`REFUSED`'s line, for an answer module.
        """
        if not self._open and is_answer(fullname):
            raise ModuleNotFoundError(REFUSED.format(name=fullname), name=fullname)
        return None

    def hand_in(self, name: str) -> ModuleType:
        """The answer module ``name``, imported for the subject after the learner's code was
        loaded, then taken out of ``sys.modules`` again (this finder keeps it).

        :raises ImportError: when the course's module cannot be imported (a mistake of ours).
        """
        if name not in self._handed:
            self._open = True
            try:
                self._handed[name] = importlib.import_module(name)
            finally:
                self._open = False
                purge()
        return self._handed[name]


def shut() -> Answers:
    """Before the learner's code is loaded: no answer module in ``sys.modules``, and the
    finder that refuses them first on ``sys.meta_path``; return it (for :meth:`hand_in`)."""
    purge()
    finder = Answers()  # any other one stays: each refuses until its own hand_in
    sys.meta_path.insert(0, finder)
    importlib.invalidate_caches()
    return finder
