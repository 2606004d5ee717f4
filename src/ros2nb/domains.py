"""One ROS 2 world per kernel: each course kernel claims a ROS domain no other one holds.

Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.start`).

ROS 2 nodes on one machine and one domain see each other, whatever notebook or user they
belong to (``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` only keeps other machines out).
So, unless ``ROS_DOMAIN_ID`` is set, the first ROS call of a kernel claims a free domain:
an exclusive ``flock`` on ``<lock folder>/<domain>.lock``.  The kernel holds the lock
until it ends; the operating system releases it even when the kernel is killed.  Every
process the kernel starts inherits the domain through ``ROS_DOMAIN_ID``.

The lock folder (``$ROS2NB_DOMAIN_LOCKS``, default ``ros2nb-domains`` in the temporary
folder: ``$TMPDIR``, usually ``/tmp``) must be the same for all course kernels on the
machine, also those of other users on one JupyterHub: kernels that see different
``TMPDIR`` values need ``ROS2NB_DOMAIN_LOCKS`` set.  It is created world-writable with the
sticky bit, like ``/tmp``.

Every process of the course finds its peers with the course's Fast DDS profile
(:data:`DISCOVERY_PROFILE`, put into the environment by :func:`use_discovery_profile`, which
:func:`domain_id` and the runtime call before ROS comes up): a new node appears in the graph
of the processes already running within about a second, not at Fast DDS's default
announcement every 3 s.  No ROS import here.
"""

from __future__ import annotations

import errno
import fcntl
import os
import socket
import tempfile
from pathlib import Path
from typing import Optional

from .errors import DomainsExhaustedError, Ros2nbError

#: Domain ids that are safe on Linux (higher ones clash with ephemeral ports).
SAFE_DOMAINS = range(0, 102)
#: The order in which free domains are tried: 0, the default of every ROS program
#: started without the course, comes last.
CLAIM_ORDER = (*range(1, 102), 0)
LOCKS_ENV = 'ROS2NB_DOMAIN_LOCKS'
DOMAIN_ENV = 'ROS_DOMAIN_ID'
#: Fast DDS's unicast discovery port of participant p on domain d is PORT_BASE +
#: PORT_PER_DOMAIN * d + 10 + 2 * p (RTPS port mapping); any of them in use means some ROS
#: process already lives on domain d.  A participant takes the first free index, so one
#: started while index 0 was taken keeps index 1 after index 0's process has ended.
PORT_BASE, PORT_PER_DOMAIN = 7400, 250
#: Participant indexes probed per domain (one per ROS process on this machine).
PARTICIPANTS_PROBED = 16
#: Where Fast DDS (2.x, Jazzy's) reads the default profile of every participant it makes.
PROFILE_ENV = 'FASTRTPS_DEFAULT_PROFILES_FILE'
#: The course's profile: each participant announces itself every second, not every 3 s
#: (the file says why); nothing else changes.
DISCOVERY_PROFILE = Path(__file__).with_name('fastdds_profile.xml')

_claimed: Optional[tuple[int, int]] = None  # (domain, fd holding its lock)


def lock_folder() -> Path:
    """Return the folder of domain locks shared by every course kernel on this machine."""
    configured = os.environ.get(LOCKS_ENV)
    return Path(configured) if configured else Path(tempfile.gettempdir()) / 'ros2nb-domains'


def _ensure_folder(folder: Path) -> None:
    if folder.is_dir():
        return
    try:
        folder.mkdir(parents=True, exist_ok=True)
        folder.chmod(0o1777)  # every user's kernels lock here, none can delete others' files
    except OSError as error:
        raise Ros2nbError(f'Cannot create the domain lock folder {folder} ({error.strerror}): '
                          f'set {LOCKS_ENV} to a folder all course kernels can write to, or '
                          f'set {DOMAIN_ENV} yourself.') from None


def _try_lock(folder: Path, domain: int) -> Optional[int]:
    """Return an fd holding the lock of ``domain``, or None when another process holds it."""
    try:
        fd = os.open(folder / f'{domain}.lock', os.O_RDONLY | os.O_CREAT | os.O_CLOEXEC, 0o644)
    except OSError:
        return None  # e.g. created by another user without read permission: treat as taken
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as error:
        os.close(fd)
        if error.errno in (errno.EWOULDBLOCK, errno.EAGAIN):
            return None
        raise
    return fd


def _used_by_other_ros(domain: int) -> bool:
    """True when a ROS process outside the course already has a participant on ``domain``."""
    for participant in range(PARTICIPANTS_PROBED):
        port = PORT_BASE + PORT_PER_DOMAIN * domain + 10 + 2 * participant
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
            try:
                probe.bind(('127.0.0.1', port))
            except OSError:
                return True
    return False


def claimed_domain() -> Optional[int]:
    """Return the domain this process claimed, or None if it claimed none."""
    return _claimed[0] if _claimed else None


def _parse(value: str) -> int:
    try:
        domain = int(value)
    except ValueError:
        domain = -1
    if not 0 <= domain <= 232:
        raise Ros2nbError(f'{DOMAIN_ENV}={value!r} is not a domain id: use a whole number '
                          'from 0 to 101, or unset it and let ros2nb choose one.')
    return domain


def use_discovery_profile() -> None:
    """Give this process, and every process it starts, the course's Fast DDS profile
    (:data:`DISCOVERY_PROFILE`), unless ``FASTRTPS_DEFAULT_PROFILES_FILE`` names one already
    (set but empty, Fast DDS would print an error for each process: it counts as unset).

    Fast DDS reads the profile when the process makes its first participant: call this
    before ROS comes up (:func:`domain_id` does).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.start`).
    """
    if not os.environ.get(PROFILE_ENV):
        os.environ[PROFILE_ENV] = str(DISCOVERY_PROFILE)


def domain_id() -> int:
    """Return this kernel's ROS domain, claiming a free one the first time.

    ``ROS_DOMAIN_ID`` set in the environment (by you, or by the process that started this
    one) is used as it is.  Otherwise a domain no other live course kernel on this
    machine holds is claimed for the life of this process and put into
    ``os.environ['ROS_DOMAIN_ID']``, so that everything started from here inherits it.
    Either way the course's discovery profile goes there too (:func:`use_discovery_profile`).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (through :func:`ros2nb.start`).

    :return: the domain id (0-232; claimed ones are 0-101).
    :raises DomainsExhaustedError: when every safe domain (0-101) is taken.
    :raises Ros2nbError: when ``ROS_DOMAIN_ID`` is not a number, or no lock can be made.
    """
    global _claimed
    use_discovery_profile()
    if _claimed is not None:
        return _claimed[0]
    value = os.environ.get(DOMAIN_ENV, '').strip()
    if value:
        return _parse(value)
    folder = lock_folder()
    _ensure_folder(folder)
    for domain in CLAIM_ORDER:
        fd = _try_lock(folder, domain)
        if fd is None:
            continue
        if _used_by_other_ros(domain):
            os.close(fd)
            continue
        _claimed = (domain, fd)
        os.environ[DOMAIN_ENV] = str(domain)
        return domain
    raise DomainsExhaustedError(
        f'All {len(SAFE_DOMAINS)} safe ROS domains (0-101) on this machine are taken by other '
        'course kernels or ROS programs: shut down kernels you no longer use (Kernel > Shut '
        f'Down Kernel), or set {DOMAIN_ENV} yourself.')


def release() -> None:
    """Give the claimed domain back (normally the end of the process does this)."""
    global _claimed
    if _claimed is not None:
        domain, fd = _claimed
        _claimed = None
        os.close(fd)
        if os.environ.get(DOMAIN_ENV) == str(domain):
            del os.environ[DOMAIN_ENV]
