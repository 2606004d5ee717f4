"""What a term adds to grading a class: due dates, extensions, the roster, one learner again.

Runs on the instructor's host, for ``ros2nb-grade`` (:mod:`.cli`): ``--settings`` (the course's
``course.toml``, :mod:`.course_settings`), ``--extensions`` (:mod:`.extensions`), ``--export
canvas|moodle|csv`` with ``--roster`` (:mod:`.roster`; the export itself is :mod:`.exporting`'s),
and ``--learner NAME``: that learner graded again into an earlier grading, the others kept as
they were (``learners.json``, what grading made of each learner before nbgrader scored them).
"""

from __future__ import annotations

import argparse
import dataclasses
import datetime
import json
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

from nbgrader.api import Gradebook, MissingEntry
from ros2nb.outcomes import CheckOutcome
from ros2nb.typed_json import Unreadable, decoded

from ...paths import ASSIGNMENT, SETTINGS, gradebook_url
from .course_settings import read_settings
from .deadlines import NO_DEADLINES, CourseSettings, SettingsProblem
from .extensions import EXTENSIONS, NONE, Extensions, ExtensionsProblem, read_extensions
from .roster import PLATFORMS, RosterProblem, RosterRow, read_roster
from .submissions import Learner, shown

#: What grading made of each learner before nbgrader scored them, kept for ``--learner``.
STATE = 'learners.json'


@dataclass(frozen=True, kw_only=True)
class LearnerState:
    """One learner in ``learners.json``, under their folder's name, as grading left them
    before nbgrader scored them: written by one ``ros2nb-grade`` (:func:`save_state`) and read
    by a later one (``--learner``, ``--export``: :func:`load_state`, with
    :func:`ros2nb.typed_json.decoded`), both on the instructor's host.

    :ivar id: the id nbgrader knows the learner by.
    :ivar files: notebook -> the file graded for it (a path, as text).
    :ivar notes: notebook (or ``_folder``) -> what happened, in a sentence.
    :ivar results: notebook -> the judge's outcomes (grade id -> its outcome).
    :ivar flags: notebook -> the judge's flags.
    :ivar handed_in: notebook -> (when it was handed in, ISO 8601 with its zone; where that
        comes from).
    """

    id: str
    files: dict[str, str]
    notes: dict[str, str]
    results: dict[str, dict[str, CheckOutcome]]
    flags: dict[str, list[str]]
    handed_in: dict[str, tuple[str, str]]


def add_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument('--settings', type=Path, default=SETTINGS,
                        help='the course settings file: due dates and the late policy')
    parser.add_argument('--extensions', type=Path,
                        help='per learner and notebook, a later due date (default: '
                             f'{EXTENSIONS} beside --settings)')
    parser.add_argument('--export', choices=PLATFORMS,
                        help='also write grading/export/<choice>.csv for a learning platform')
    parser.add_argument('--roster', type=Path,
                        help='CSV mapping learner names to the platform\'s ids (for --export)')
    parser.add_argument('--learner', metavar='NAME',
                        help='grade this learner again into the earlier grading in --out')


@dataclass(frozen=True)
class Term:
    """The term's settings for one grading: due dates, the roster (of an export, or to take
    in Canvas's zip), and, once the learners are known, their extensions."""

    deadlines: CourseSettings
    export: Optional[str]
    roster: Optional[dict[str, RosterRow]]
    extensions: Extensions = NONE

    def canvas_learners(self) -> Optional[dict[str, str]]:
        """Canvas user id (the roster's ``lms_id``) -> learner, for Canvas's zip."""
        if self.roster is None:
            return None
        return {row.lms_id: name for name, row in self.roster.items() if row.lms_id}


def read_term(args: argparse.Namespace, notebooks: list[str]) -> tuple[Optional[Term], list[str]]:
    """The settings file and roster ``args`` name, or the lines that say what is wrong."""
    lines = []
    try:
        deadlines = read_settings(args.settings, notebooks)
    except SettingsProblem as problem:
        deadlines, lines = NO_DEADLINES, list(problem.lines)
    roster = None
    if args.roster is not None:
        try:
            roster = read_roster(args.roster, args.export or 'csv')
        except RosterProblem as problem:
            lines += problem.lines
    elif args.export in ('canvas', 'moodle'):
        lines.append(f'EXPORT={args.export} needs a roster of the platform\'s ids: '
                     'ROSTER=roster.csv (docs/instructors.md, "A term, step by step")')
    return (None, lines) if lines else (Term(deadlines, args.export, roster), [])


def extensions_file(args: argparse.Namespace) -> Path:
    """The extensions file ``args`` name: ``--extensions``, else beside ``--settings``."""
    return args.extensions or args.settings.parent / EXTENSIONS


def with_extensions(term: Term, args: argparse.Namespace, notebooks: list[str],
                    learners: list[Learner]) -> tuple[Optional[Term], list[str]]:
    """``term`` with the extensions file ``args`` names, checked against the class's due
    dates and ``learners`` (and the roster's), or the lines that say what is wrong."""
    names = {learner.name for learner in learners} | set(term.roster or ())
    try:
        extensions = read_extensions(extensions_file(args), term.deadlines, notebooks, names)
    except ExtensionsProblem as problem:
        return None, problem.lines
    return dataclasses.replace(term, extensions=extensions), []


def with_roster(learners: list[Learner], roster: Optional[dict[str, RosterRow]]
                ) -> list[Learner]:
    """``learners`` and, for each roster learner with no folder, a learner with nothing handed
    in (0 on every notebook, and a note saying so)."""
    if not roster:
        return learners
    taken = {learner.id for learner in learners}
    found = {learner.name for learner in learners}
    for number, name in enumerate(sorted(set(roster) - found), start=1):
        absent = Learner(name, name if name not in taken and name.isidentifier()
                         else f'roster-{number:03d}')
        absent.note('_folder', 'in the roster, nothing handed in: 0 points')
        learners.append(absent)
    return sorted(learners, key=lambda learner: learner.name)


def save_state(out: Path, learners: list[Learner]) -> None:
    """``learners.json``: each learner's files, notes, results, flags and hand-in times, as
    grading left them before nbgrader scored them (``--learner`` starts from it).  JSON's
    ASCII escapes keep a folder name that is not UTF-8 (a Windows zip's) exactly as it is."""
    (out / STATE).write_text(json.dumps({learner.name: dataclasses.asdict(LearnerState(
        id=learner.id, files={n: str(p) for n, p in learner.files.items()},
        notes=learner.notes, results=learner.results, flags=learner.flags,
        handed_in={n: (t.isoformat(), s) for n, (t, s) in learner.handed_in.items()}))
        for learner in learners}, indent=1) + '\n')


def load_state(out: Path) -> list[Learner]:
    """The learners ``learners.json`` kept (:func:`save_state`).

    :raises ros2nb.typed_json.Unreadable: for a learner whose entry does not fit
        :class:`LearnerState` (the line names the learner and the field).
    """
    kept = json.loads((out / STATE).read_text())
    if not isinstance(kept, dict):
        raise Unreadable(f'{out / STATE} is not a JSON object')
    learners = []
    for name, entry in kept.items():
        try:
            state: LearnerState = decoded(LearnerState, entry)
        except Unreadable as error:
            raise Unreadable(f'{out / STATE}, learner {shown(name)}: {error}') from None
        learner = Learner(name, state.id, {n: Path(p) for n, p in state.files.items()},
                          dict(state.notes), dict(state.results), dict(state.flags))
        learner.handed_in = {n: (datetime.datetime.fromisoformat(t), s)
                             for n, (t, s) in state.handed_in.items()}
        learners.append(learner)
    return learners


def forget(course: Path, learner: Learner) -> None:
    """Remove what nbgrader holds of ``learner`` (their submission, its scores and feedback)
    from ``course``, to grade them again."""
    with Gradebook(gradebook_url(course)) as gradebook:
        try:
            gradebook.remove_submission(ASSIGNMENT, learner.id)
        except MissingEntry:
            pass
    for step in ('submitted', 'autograded', 'feedback'):
        shutil.rmtree(course / step / learner.id, ignore_errors=True)
