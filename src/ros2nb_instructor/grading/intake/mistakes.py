"""One kind of refusal for an instructor's input: one line per mistake, all of them at once.

Runs on the instructor's host.  A settings file, an extensions file, a roster or a folder of
submissions the grader will not use raises a subclass of :class:`Mistakes` whose ``lines``
each say what is wrong and what to write instead; the command prints them and changes
nothing.
"""

from __future__ import annotations

from typing import Iterable


class Mistakes(Exception):
    """An input the grader will not use: ``lines`` holds one line per mistake."""

    def __init__(self, lines: Iterable[str]) -> None:
        self.lines = list(lines)
        super().__init__('\n'.join(self.lines))
