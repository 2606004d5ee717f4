"""What the learner's code sends beyond any node of the course: a flood, counted on the
judge's clock and ended at once.

Part of the judge (:mod:`ros2nb.judge`).  A loop that logs or publishes without waiting (a
thread started in a constructor, a ``while True`` in a callback) sends more than the judge
can read: it waited for all of it, and a class waited with it.  The judge's observer counts
what it hears per logger on ``/rosout`` and per topic it watches, and the subject's word of
what it sent (:meth:`Floods.announced`), in windows of one second of the judge's clock (or
while it stands still); past :data:`FLOOD_LIMIT` the judge keeps no more of it, ends the
processes that run the learner's code and fails the check with one line
(:class:`~ros2nb.judge_interface.Flooded`).  So does more in one check than any node of the
course sends in the longest check (:data:`CHECK_FLOOD_LIMIT`): a loop that logs hundreds of
lines for each reading stays under the window's limit, and its cost grows with every
simulated second a check runs; counted in messages, not CPU seconds, it is found in the same
check however busy the machine.  What those processes had sent and the judge had
not read yet arrives later, and belongs to them, not to the next check: once they are reaped,
a message stamped by its sender (on the machine's one clock) before that moment is dropped
(:meth:`Floods.stale`), however long the judge takes to read it.  Introduced in
``03-write-the-publisher.ipynb``.
"""

from __future__ import annotations

import time
from typing import Any, Callable, Optional

from ..judge_interface import Flooded

#: Lines one logger may send to /rosout, and messages a watched topic may carry, within one
#: second of the judge's clock (or while it stands still): the course's nodes send one a
#: reading or a tick, notebook 10's replay sixty in a step, notebook 04's checks feed thirty
#: readings while the clock stands still.
FLOOD_LIMIT = 500
FLOOD_WINDOW_NS = 1_000_000_000
#: Lines one logger may send, and messages a watched topic may carry, within one check: the
#: longest checks hear an hour of the sensor (3,600 readings, a line each) and notebook 10's
#: recording its monitor's 3,600 statuses beside; a fifth of what a judge can hear within the
#: CPU limit of one check (``ros2nb_instructor.grading.judging.settings.JUDGE_CPU_S``).
CHECK_FLOOD_LIMIT = 20_000


class Floods:
    """The flood counts of one judge's observer (``observer.now_ns``, ``observer.changed``).

    :ivar line: the first flood's one line since :meth:`forget`, or None.
    :ivar on_flood: ends and reaps the processes that may be flooding (the session's
        subjects and programs); called by :meth:`raise_any`, never in the observer's spin
        thread.
    :ivar stopped_ns: the machine's time (``time.time_ns()``) when those processes were last
        reaped: what was sent before it came from them (:meth:`stale`).
    """

    def __init__(self, observer: Any) -> None:
        self._observer = observer
        self.line: Optional[str] = None
        self.on_flood: Callable[[], None] = lambda: None
        self.stopped_ns = 0
        self._windows: dict[tuple[str, str, str], list[int]] = {}
        self._totals: dict[tuple[str, str, str], int] = {}
        self._said: dict[tuple[int, str, str], int] = {}

    def count(self, where: str, who: str, count: int = 1, source: str = 'heard') -> bool:
        """Count ``count`` messages of ``who`` on ``where`` (``source``: heard by the judge,
        or ``said`` by a subject) in their window of the judge's clock and in this check; True
        (keep them not) once the window holds more than :data:`FLOOD_LIMIT`, or the check
        more than :data:`CHECK_FLOOD_LIMIT`.  The caller holds ``observer.changed``."""
        now, key = self._observer.now_ns, (source, where, who)
        window = self._windows.setdefault(key, [now, 0])
        if now - window[0] >= FLOOD_WINDOW_NS:
            window[:] = [now, 0]
        window[1] += count
        self._totals[key] = total = self._totals.get(key, 0) + count
        if window[1] <= FLOOD_LIMIT and total <= CHECK_FLOOD_LIMIT:
            return False
        if self.line is None:
            self.line = flood_line(where, who, now - window[0]) if window[1] > FLOOD_LIMIT \
                else check_flood_line(where, who)
            self._observer.changed.notify_all()
        return True

    def announced(self, subject: int, where: str, who: str, total: int) -> None:
        """A subject's word (``subject``: its process id) that ``who`` sent ``total``
        messages on ``where`` since it started: what it added since its last word counts
        towards a flood.  Its word may only fail it: the judge waits for no more than it hears."""
        with self._observer.changed:
            last = self._said.get((subject, where, who))
            self._said[(subject, where, who)] = total
            if last is not None and total > last:
                self.count(where, who, total - last, 'said')

    def forget(self) -> None:
        """Count afresh (a new check, or a flood raised): no flood, every window empty."""
        with self._observer.changed:
            self.line = None
            self._windows.clear()
            self._totals.clear()

    def stale(self, info: Any) -> bool:
        """True for a message (its rmw message info) its sender stamped before the flooding
        processes were reaped: theirs, arriving late, which no check counts or keeps."""
        sent = info.get('source_timestamp') if isinstance(info, dict) else None
        return isinstance(sent, int) and 0 < sent < self.stopped_ns

    def raise_any(self) -> None:
        """Raise :class:`~ros2nb.judge_interface.Flooded` with the flood's line when there
        was one, once the processes that may flood are ended and reaped (:attr:`on_flood`)
        and what the judge's subscriptions hold of theirs is taken away (the observer's
        ``take_stale``); what is still on its way is dropped on arrival (:meth:`stale`),
        however long it takes; then count afresh."""
        line = self.line
        if line is None:
            return
        line = self._both() or line
        self.on_flood()
        self.ended()
        raise Flooded(line)

    def ended(self) -> None:
        """The processes that may flood were ended and reaped (by a flood, or a check that
        ran a program once): what they sent before now is theirs, taken away and dropped on
        arrival (:meth:`stale`), never counted in the next run's windows; count afresh.  A
        program runs on the machine's clock while the judge's stands still, so its lines
        share one window: counted per run, what one run sends never fails the next."""
        with self._observer.changed:
            self.stopped_ns = time.time_ns()
        self._observer.take_stale()
        self.forget()

    def _both(self) -> Optional[str]:
        """The line of a node that floods a topic and /rosout together (each call publishes
        and logs): which of the two passed the limit first is a race, so the line names both
        once each is past half of it."""
        with self._observer.changed:
            busy = [(where, who, self._observer.now_ns - start)
                    for (_source, where, who), (start, count) in self._windows.items()
                    if count > FLOOD_LIMIT // 2]
        logs = [b for b in busy if b[0] == '/rosout']
        topics = [b for b in busy if b[0] != '/rosout']
        if not logs or not topics:
            return None
        return flood_line(topics[0][1], logs[0][1], max(logs[0][2], topics[0][2]), both=True)


def flood_line(where: str, who: str, span_ns: int, both: bool = False) -> str:
    """The one line of a flood of ``who`` on ``where`` (``/rosout``: ``who`` is the logger),
    counted over ``span_ns`` of the judge's clock; with ``both``, of the logger ``who``
    flooding the topic ``where`` and /rosout."""
    when = (f'in {span_ns / 1e9:g} s of the grader\'s clock' if span_ns else
            'while the grader\'s clock stood still')
    if both:  # where: the topic, who: the logger
        return (f'Your node {who} published on {where} and logged to /rosout over '
                f'{FLOOD_LIMIT:,} messages {when} (a node of the course does each once per '
                'reading or tick): look for a loop, or a timer made in a callback, that '
                'publishes and logs without waiting for a timer.')
    if where == '/rosout':
        return (f'Your node {who} logged over {FLOOD_LIMIT:,} lines to /rosout {when} (a node '
                'of the course logs one line per reading or tick): look for a loop that logs '
                'without waiting for a timer.')
    return (f'Your code published over {FLOOD_LIMIT:,} messages on {who} {when} (the sensor '
            'publishes one a second): look for a loop that publishes without waiting for a '
            'timer.')


def check_flood_line(where: str, who: str) -> str:
    """The one line of a flood of ``who`` on ``where`` over one check
    (:data:`CHECK_FLOOD_LIMIT`)."""
    if where == '/rosout':
        return (f'Your node {who} logged over {CHECK_FLOOD_LIMIT:,} lines to /rosout in one '
                'check (a node of the course logs one line per reading or tick, 3,600 in an '
                'hour): look for a loop that logs many lines for each reading.')
    return (f'Your code published over {CHECK_FLOOD_LIMIT:,} messages on {who} in one check (the '
            'sensor publishes one a second, 3,600 in an hour): look for a loop that publishes '
            'many messages for each reading.')
