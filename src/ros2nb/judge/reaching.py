"""What the learner's code reached for while it ran in a subject, and what the judge makes of it.

Part of the judge (:mod:`ros2nb.judge`).  Each subject's audit hook (:mod:`ros2nb.subject.seen`)
writes a line on the judge's pipe for every event the learner's code caused that reaches into
the course or the process: stack frames, the garbage collector's objects, a function's code,
the course's answer files and modules, code compiled or loaded at run time, raw memory, other
processes.  The judge reads those lines (:meth:`ros2nb.judge.subjects.SubjectProcess.take_ack`)
and decides here what each means:

- every one is a flag for the instructor (``report.html``, the learner's feedback box);
- the kinds that can only serve cheating fail the check that ran the code, with one line
  (:meth:`Reaching.raise_any`, called by :func:`ros2nb.checks.run_check` after each check).

A line only ever costs the learner: their code can write more of them, never take one back
(each is written the moment the event happens).  The text scan (:mod:`ros2nb.judge.flags`)
stays a second opinion.
"""

from __future__ import annotations

from typing import Any, NamedTuple, Optional

from ..errors import CheckFailed

#: How a line of the audit hook starts on a subject's pipe (:data:`ros2nb.subject.seen.MARK`).
SEEN_PREFIX = b'SEEN\t'
#: Lines kept per subject at most (the hook writes at most 64).
MAX_SEEN = 64
#: What each kind of event means: the words of its flag, and whether it can only serve
#: cheating (then the check fails).  Reading compiled code or frames, walking the garbage
#: collector, opening or importing the course's answers, compiling or loading code at run
#: time and raw memory lead to what the course keeps from the learner's code; starting
#: other processes and adding an audit hook are only shown.
KINDS: dict[str, tuple[str, bool]] = {
    'frames': ("reads stack frames, the course's among them", True),
    'objects': ("walks the garbage collector's objects, the course's among them", True),
    'code': ("reads a function's compiled code or a frame", True),
    'answer_file': ("opens or lists the course's answer files", True),
    'answer_module': ("imports the course's answer module", True),
    'compiled': ('compiles or loads code at run time', True),
    'memory': ('reads or writes memory directly (ctypes)', True),
    'processes': ('starts another process', False),
    'hooks': ('adds an audit hook of its own', False),
}
#: The line of a check whose subject saw the learner's code do something that can only serve
#: cheating: what it did, where, and that the instructor sees it.
REFUSED = ('Your code {does} ({what}, {where}) while the grader ran it: a graded part may use '
           'only what the lessons teach, so this check earns nothing; your instructor sees '
           'this in the report.')


class Reached(NamedTuple):
    """One event the learner's code caused in a subject.

    :ivar kind: one of :data:`KINDS`.
    :ivar what: the event, e.g. ``gc.get_objects`` or the file opened.
    :ivar where: ``FILE line N`` of the learner's code that caused it ('' when unknown).
    """

    kind: str
    what: str
    where: str


def parse_seen(line: bytes) -> Optional[Reached]:
    """One line of the audit hook (``SEEN<TAB>kind<TAB>what<TAB>where``), or None when it is
    not one (the learner's code may write anything on the pipe; an unknown kind is dropped)."""
    try:
        mark, kind, what, where = line.decode('utf-8', 'replace').split('\t')
    except ValueError:
        return None
    if mark + '\t' != SEEN_PREFIX.decode() or kind not in KINDS:
        return None
    return Reached(kind, what[:300], where[:300])


def flag_of(reached: Reached) -> str:
    """The instructor's flag for one event (as :mod:`ros2nb.judge.flags` words its own)."""
    where = _short(reached.where) or 'its code'
    return f'{where}: at run time, {KINDS[reached.kind][0]} ({reached.what})'


def _short(where: str) -> str:
    """``temperature_publisher.py line 12`` for a path: the learner's file, not the folders."""
    path, _, line = where.rpartition(' line ')
    return f'{path.rsplit("/", 1)[-1]} line {line}' if path else where


class Reaching:
    """What the learner's code reached for in a session's subjects, and which checks used
    the subjects that saw it.

    :param subjects: the session's running subjects, by key (read as they go).
    """

    def __init__(self, subjects: dict[tuple, Any]) -> None:
        self._subjects = subjects
        #: Every event seen, with the subject that saw it, in order of reading.
        self.found: list[tuple[Any, Reached]] = []
        #: The subjects the current check used (:meth:`forget` empties it).
        self.used: list[Any] = []
        self._mark = 0
        self._noted: dict[int, int] = {}  # id of a subject -> its events already kept

    def use(self, subject: Any) -> None:
        """The current check uses ``subject``: what it saw counts against the check."""
        if all(subject is not other for other in self.used):
            self.used.append(subject)

    def keep(self, subject: Any) -> None:
        """Keep what ``subject`` (a :class:`~ros2nb.judge.subjects.SubjectProcess`, running or
        closed) saw since the last time."""
        done = self._noted.get(id(subject), 0)
        self.found.extend((subject, event) for event in subject.seen[done:])
        self._noted[id(subject)] = len(subject.seen)

    def _gather(self) -> None:
        """Read what every running subject's audit hook wrote so far."""
        for subject in list(self._subjects.values()):
            subject.take_seen()
            self.keep(subject)

    def forget(self) -> None:
        """A check begins: what came before it counts against it only through the subjects
        it uses."""
        self._gather()
        self._mark = len(self.found)
        self.used.clear()

    def raise_any(self) -> None:
        """Raise for the first event that can only serve cheating, seen during this check or
        in a subject it used.

        :raises CheckFailed: with :data:`REFUSED`'s line.
        """
        self._gather()
        for index, (subject, event) in enumerate(self.found):
            if KINDS[event.kind][1] and (index >= self._mark or
                                         any(subject is used for used in self.used)):
                what = '/'.join(event.what.split('/')[-2:])  # a file of the course's: its name
                raise CheckFailed(REFUSED.format(does=KINDS[event.kind][0], what=what,
                                                 where=_short(event.where) or 'in your code'))

    def flags(self) -> list[str]:
        """Every event seen, as flags for the instructor (each once)."""
        self._gather()
        return list(dict.fromkeys(flag_of(event) for _subject, event in self.found))
