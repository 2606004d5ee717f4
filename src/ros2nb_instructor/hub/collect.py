"""``ros2nb-hub-collect``: collect the learners' notebooks from the course's JupyterHub.

Runs on the classroom server (``make hub-collect CLASS=DIR``), as root.

By default it collects what each learner handed in (``ros2nb.hand_in("03")``): the hub's
hand-in store (:mod:`.hand_in_store`, root's alone) holds each learner's notebooks as last
handed in and the time of each by the hand-in service's clock.  ``DIR/alice/`` gets alice's
notebooks and ``handed-in.json``, those times: the layout ``make grade SUBMISSIONS=DIR``
reads, each notebook graded by its own hand-in time.

With ``--from-homes`` (``HOMES=1``) it collects the notebooks as they are in the learners'
work folders instead (``~alice/ros2-course/notebooks/``; for a class that does not hand in),
with no times: the late policy's ``without_time`` decides.  For every member of the hub's
Unix group (``ROS2_COURSE_HUB_GROUP``, default ``ros2-course``) a file is then copied only if
it is a regular file (a symbolic link is refused, never followed), owned by that learner and
at most ``MAX_NOTEBOOK_BYTES`` long: nobody hands in someone else's notebook or a file of the
system.  Exit code 0 when the collection worked, whatever was missing.
"""

from __future__ import annotations

import argparse
import grp
import os
import pwd
import re
import stat
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from ..grading.intake.hand_in_times import HANDED_IN, record_text
from ..paths import NOTEBOOKS, ROOT
from .hand_in_store import Store

#: Where the hub keeps what learners hand in (the hub's config passes the same to the
#: service): in the hub's state folder, root's alone.
DEFAULT_STORE = ROOT / '.cache' / 'hub' / 'handed-in'

#: Each learner's notebooks, relative to their home (see environment/jupyterhub_config.py).
LEARNER_NOTEBOOKS = Path('ros2-course') / 'notebooks'
#: The notebooks' names, as shipped in notebooks/.
COURSE_NOTEBOOKS = NOTEBOOKS
DEFAULT_GROUP = 'ros2-course'
#: A course notebook with outputs is well under 1 MB; anything far larger is not one.
MAX_NOTEBOOK_BYTES = 20 * 1024 * 1024
#: The learner ids ros2nb-grade accepts (they become folder names).
LEARNER_ID = re.compile(r'^[A-Za-z0-9][A-Za-z0-9_.-]*$')


class CollectError(RuntimeError):
    """The collection cannot start; the message says what to do."""


@dataclass(frozen=True)
class Learner:
    """A learner of the hub: their user name (the learner id), home folder and user id."""

    name: str
    home: Path
    uid: int


@dataclass
class Collected:
    """What was collected for one learner.

    :ivar copied: names of the notebooks copied.
    :ivar refused: ``name: reason`` for each file that was not copied.
    """

    copied: list[str] = field(default_factory=list)
    refused: list[str] = field(default_factory=list)


def group_learners(group: str) -> list[Learner]:
    """Return the members of a Unix group (listed members and those whose main group it is).

    :raises CollectError: if the group does not exist.
    """
    try:
        entry = grp.getgrnam(group)
    except KeyError:
        raise CollectError(f'There is no Unix group {group!r}: set ROS2_COURSE_HUB_GROUP to '
                           "the hub's group (see docs/classroom-server.md).") from None
    names = set(entry.gr_mem) | {u.pw_name for u in pwd.getpwall() if u.pw_gid == entry.gr_gid}
    users = (pwd.getpwnam(name) for name in sorted(names))
    return [Learner(u.pw_name, Path(u.pw_dir), u.pw_uid) for u in users]


def read_own_file(path: Path, uid: int) -> bytes:
    """Return a file's bytes if it is a regular file owned by ``uid`` and not too long.

    :raises ValueError: with the reason when it is not such a file.
    """
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as error:
        reason = 'a symbolic link' if path.is_symlink() else error.strerror
        raise ValueError(reason) from None
    with os.fdopen(fd, 'rb') as file:
        info = os.fstat(file.fileno())
        if not stat.S_ISREG(info.st_mode):
            raise ValueError('not a regular file')
        if info.st_uid != uid:
            raise ValueError('not owned by the learner')
        if info.st_size > MAX_NOTEBOOK_BYTES:
            raise ValueError(f'too large ({info.st_size} bytes; at most {MAX_NOTEBOOK_BYTES})')
        return file.read(MAX_NOTEBOOK_BYTES + 1)


def collect_learner(learner: Learner, names: list[str], destination: Path) -> Collected:
    """Copy ``learner``'s notebooks named in ``names`` into ``destination/<learner>/``."""
    done = Collected()
    folder = learner.home / LEARNER_NOTEBOOKS
    for name in names:
        source = folder / name
        if not source.exists() and not source.is_symlink():
            continue
        try:
            data = read_own_file(source, learner.uid)
        except ValueError as reason:
            done.refused.append(f'{name}: {reason}')
            continue
        target = destination / learner.name / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(data)
        done.copied.append(name)
    return done


def _new_folder(destination: Path) -> None:
    """Make ``destination`` for a collection.

    :raises CollectError: if it holds files already.
    """
    if destination.exists() and any(destination.iterdir()):
        raise CollectError(f'{destination} is not empty: collect into a new folder.')
    destination.mkdir(parents=True, exist_ok=True)


def collect_handed_in(store: Store, destination: Path) -> dict[str, Collected]:
    """Copy every learner's handed-in notebooks from ``store`` into ``destination/<learner>/``
    with ``handed-in.json``, the time of each hand-in.

    :raises CollectError: if ``destination`` holds files already.
    """
    _new_folder(destination)
    results = {}
    for learner in store.learners():
        times = store.handed_in(learner)
        target = destination / learner
        target.mkdir()
        for notebook in times:
            data = (store.folder(learner) / f'{notebook}.ipynb').read_bytes()
            (target / f'{notebook}.ipynb').write_bytes(data)
        (target / HANDED_IN).write_text(record_text(times))
        results[learner] = Collected(copied=[f'{n}.ipynb' for n in times])
    return results


def collect(learners: list[Learner], destination: Path) -> dict[str, Collected]:
    """Collect every learner's notebooks from their work folders into ``destination``
    (which must be new or empty), with no hand-in times.

    :raises CollectError: if ``destination`` holds files already.
    """
    _new_folder(destination)
    names = sorted(p.name for p in COURSE_NOTEBOOKS.glob('*.ipynb'))
    results = {}
    for learner in learners:
        if LEARNER_ID.match(learner.name):
            results[learner.name] = collect_learner(learner, names, destination)
        else:
            results[learner.name] = Collected(refused=['every notebook: the user name is not '
                                                       'a learner id make grade accepts'])
    return results


def summary(name: str, done: Collected) -> str:
    """One line per learner: how many notebooks, and what was refused."""
    line = f'{name}: {len(done.copied)} notebook(s)'
    return line + (f'; refused {", ".join(done.refused)}' if done.refused else '')


def main(argv: Optional[list[str]] = None) -> int:
    """Collect every learner's notebooks into the destination folder; say what was missing."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('destination', type=Path, help='new folder for DIR/<learner>/NN-*.ipynb')
    parser.add_argument('--group', default=os.environ.get('ROS2_COURSE_HUB_GROUP', DEFAULT_GROUP),
                        help="the hub's Unix group, for --from-homes (default: "
                             f'$ROS2_COURSE_HUB_GROUP or {DEFAULT_GROUP})')
    parser.add_argument('--store', type=Path,
                        default=Path(os.environ.get('ROS2_COURSE_HUB_HANDED_IN', DEFAULT_STORE)),
                        help='the hub\'s hand-in store (default: $ROS2_COURSE_HUB_HANDED_IN or '
                             f'{DEFAULT_STORE})')
    parser.add_argument('--from-homes', action='store_true',
                        help='collect the work folders as they are, not what was handed in')
    options = parser.parse_args(argv)
    try:
        if options.from_homes:
            results = collect(group_learners(options.group), options.destination)
        elif not options.store.is_dir():
            raise CollectError(f'{options.store} holds no hand-ins (nobody ran ros2nb.hand_in, '
                               'or the hub keeps them elsewhere: STORE=folder); to collect the '
                               'work folders as they are, add HOMES=1.')
        else:
            results = collect_handed_in(Store(options.store), options.destination)
    except CollectError as error:
        print(error, file=sys.stderr)
        return 2
    for name, done in results.items():
        print(summary(name, done))
    print(f'Now grade them: make grade SUBMISSIONS={options.destination}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
