"""What the learner's code reached for while it ran in a subject: notes for the instructor.

Part of the judge (:mod:`ros2nb.judge`).  Each subject's audit hook (:mod:`ros2nb.subject.seen`)
writes a line on the judge's pipe for every event the learner's code caused that reaches into
the course or the process: stack frames, the garbage collector's objects, a function's code,
the course's answer files and modules, code compiled or loaded at run time, raw memory, other
processes, audit hooks of its own; past a kind's first places, its count; and, as the subject
ends, every kind's count.  The judge reads those lines
(:meth:`ros2nb.judge.subjects.SubjectProcess.take_ack`) and makes each a note for the instructor
(``report.html``, the learner's feedback box).

A detector only: no check fails or passes on it, and its silence proves nothing (the hook runs
in the learner's process, where code can read, replace or mute anything).  What decides a
point is observed from outside that process (docs/decisions.md).  A subject that ended on
``quit`` without its last line had its channel closed or redirected: that is a note too.  The
text scan (:mod:`ros2nb.judge.flags`) is a second opinion.
"""

from __future__ import annotations

from typing import Any, NamedTuple, Optional

#: How a line of the audit hook starts on a subject's pipe (:data:`ros2nb.subject.seen.MARK`).
SEEN_PREFIX = b'SEEN\t'
#: Places kept per kind and subject at most (:data:`ros2nb.subject.seen.PER_KIND`).
PER_KIND = 8
#: The second field of a count line and of the last line (:mod:`ros2nb.subject.seen`).
COUNT, END = 'count', 'end'
#: What each kind of event is, in the words of its note.
KINDS: dict[str, str] = {
    'frames': "reads stack frames, the course's among them",
    'objects': "walks the garbage collector's objects, the course's among them",
    'code': "reads a function's compiled code or a frame",
    'answer_file': "opens or lists the course's answer files",
    'answer_module': "imports the course's answer module",
    'compiled': 'compiles or loads code at run time',
    'memory': 'reads or writes memory directly (ctypes)',
    'processes': 'starts another process',
    'hooks': 'adds an audit hook of its own',
}
#: The note for a subject that ended as asked without the hook's last line.
CHANNEL_LOST = ('the process that ran your code ended without its last audit line: something '
                'in it closed or redirected its channel to the grader, so what it reached for '
                'may be missing here')


class Reached(NamedTuple):
    """One event the learner's code caused in a subject.

    :ivar kind: one of :data:`KINDS`.
    :ivar what: the event, e.g. ``gc.get_objects`` or the file opened.
    :ivar where: ``FILE line N`` of the learner's code that caused it ('' when unknown).
    """

    kind: str
    what: str
    where: str


class Counted(NamedTuple):
    """A kind's count so far (``kind`` one of :data:`KINDS`), or, as the last line
    (``kind`` :data:`END`), every kind's count."""

    kind: str
    counts: dict[str, int]


def _fields(line: bytes) -> Optional[tuple[str, str, str]]:
    try:
        mark, first, second, third = line.decode('utf-8', 'replace').split('\t')
    except ValueError:
        return None
    return (first, second, third) if mark + '\t' == SEEN_PREFIX.decode() else None


def parse_seen(line: bytes) -> Optional[Reached]:
    """One event line of the audit hook (``SEEN<TAB>kind<TAB>what<TAB>where``), or None when
    it is not one (the learner's code may write anything on the pipe; an unknown kind is
    dropped)."""
    fields = _fields(line)
    if fields is None or fields[0] not in KINDS:
        return None
    kind, what, where = fields
    return Reached(kind, what[:300], where[:300])


def parse_count(line: bytes) -> Optional[Counted]:
    """A count line (``SEEN<TAB>count<TAB>kind<TAB>N``) or the last line
    (``SEEN<TAB>end<TAB>kind=N,...<TAB>``), or None."""
    fields = _fields(line)
    if fields is None:
        return None
    first, second, third = fields
    if first == COUNT and second in KINDS and third.isdigit():
        return Counted(second, {second: int(third)})
    if first != END:
        return None
    counts = {}
    for part in filter(None, second.split(',')):
        kind, _, number = part.partition('=')
        if kind in KINDS and number.isdigit():
            counts[kind] = int(number)
    return Counted(END, counts)


def flag_of(reached: Reached) -> str:
    """The instructor's note for one event (as :mod:`ros2nb.judge.flags` words its own)."""
    where = _short(reached.where) or 'its code'
    return f'{where}: at run time, {KINDS[reached.kind]} ({reached.what})'


def _short(where: str) -> str:
    """``temperature_publisher.py line 12`` for a path: the learner's file, not the folders."""
    path, _, line = where.rpartition(' line ')
    return f'{path.rsplit("/", 1)[-1]} line {line}' if path else where


class Reaching:
    """What the learner's code reached for in a session's subjects.

    :param subjects: the session's running subjects, by key (read as they go).
    """

    def __init__(self, subjects: dict[tuple[Any, ...], Any]) -> None:
        self._subjects = subjects
        #: Every event seen, with the subject that saw it, in order of reading.
        self.found: list[tuple[Any, Reached]] = []
        #: Each subject's counts (by kind), for the subjects read so far, by id.
        self._counts: dict[int, dict[str, int]] = {}
        #: Subjects that ended as asked without the hook's last line.
        self._lost = 0
        self._noted: dict[int, int] = {}  # id of a subject -> its events already kept

    def keep(self, subject: Any) -> None:
        """Keep what ``subject`` (a :class:`~ros2nb.judge.subjects.SubjectProcess`, running or
        closed) saw since the last time."""
        done = self._noted.get(id(subject), 0)
        self.found.extend((subject, event) for event in subject.seen[done:])
        self._noted[id(subject)] = len(subject.seen)
        self._counts[id(subject)] = dict(getattr(subject, 'seen_counts', {}))
        if getattr(subject, 'channel_lost', False) and not getattr(subject, '_lost_noted', False):
            subject._lost_noted = True
            self._lost += 1

    def _gather(self) -> None:
        """Read what every running subject's audit hook wrote so far."""
        for subject in list(self._subjects.values()):
            subject.take_seen()
            self.keep(subject)

    def flags(self) -> list[str]:
        """Every event seen, as notes for the instructor (each once), each kind's events
        past its places shown counted, and a note for each channel lost."""
        self._gather()
        notes = list(dict.fromkeys(flag_of(event) for _subject, event in self.found))
        shown: dict[str, int] = {}
        for _subject, event in self.found:
            shown[event.kind] = shown.get(event.kind, 0) + 1
        totals: dict[str, int] = {}
        for counts in self._counts.values():
            for kind, total in counts.items():
                totals[kind] = totals.get(kind, 0) + total
        for kind, total in totals.items():
            if total > shown.get(kind, 0) and kind in KINDS:
                notes.append(f'at run time, {KINDS[kind]}: {total} times in all '
                             f'({shown.get(kind, 0)} places shown)')
        notes += [CHANNEL_LOST] * min(self._lost, 1)
        return notes
