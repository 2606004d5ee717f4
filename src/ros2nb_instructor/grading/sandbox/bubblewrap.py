"""Run untrusted code (a learner's notebook, a judged ROS 2 node) in a bubblewrap sandbox.

What a sandbox covers, each with a test in ``tests/test_sandbox.py``:

- Processes: a new PID namespace with its own ``/proc``; the grader, other learners and
  every host process can be neither seen, signalled nor traced.  When the sandboxed
  program ends or is stopped, the namespace's init dies and the kernel kills everything
  left in it, double-forked ``setsid`` daemons included.
- Network: a new network namespace with only ``lo`` (up).  DDS discovery and data never
  leave it, so ROS 2 traffic neither reaches nor comes from anyone else, whatever
  ``ROS_DOMAIN_ID``.  ``share_network=True`` keeps the caller's namespace instead (used by
  a judge's subjects, see :func:`inner_prefix`).
- Files: an empty root with read-only ``/usr``, a minimal ``/etc`` (no ``shadow``), the
  Python installation and the venv, the ``readable`` paths read-only, ``hidden`` paths
  under an empty tmpfs, and writes allowed only in ``writable`` paths and in private
  tmpfs ``/tmp`` and ``/dev/shm`` (memory, gone afterwards).  Environment cleared.
- Identity: no capabilities, ``no_new_privs``, uid 1000 inside.  When the caller is root,
  the sandbox runs as :data:`HOST_UID`, a host uid that owns no file (its ``writable``
  paths are chowned to it first).  Mapped to root instead, a sandbox could write global
  sysctls under ``/proc/sys``, could read every root-only file it is shown, and bubblewrap's
  read-only covers on its ``/proc`` would stop nested sandboxes from mounting a ``/proc``.
- Limits (:class:`Limits`): wall time and CPU time (the whole sandbox is killed), file size
  (``RLIMIT_FSIZE``), and, when a cgroup can be made, number of tasks and memory (tmpfs
  pages included).  CPU time is that of all its processes together, read from the cgroup
  by the caller; without a cgroup, CPU time falls back to a per-process ``RLIMIT_CPU``,
  memory to a per-process ``RLIMIT_AS``, and tasks are not limited;
  :attr:`Running.limits_enforced` says which applied.

Use (``limits_enforced`` of the result says which limits applied)::

    box = Sandbox(readable=[course], writable=[scratch], env={'HOME': str(scratch), ...},
                  cwd=scratch)
    result = box.run(['jupyter', 'execute', ...], Limits(wall_s=600))   # to its end
    with box.start(argv, Limits(), stdin=PIPE, stdout=PIPE) as running:  # talk to it
        ...                                                              # stop() on exit
    judge = Sandbox(..., nested=True)  # its program runs inner_prefix() + subject argv

What it does not cover: the kernel is shared (a kernel exploit escapes, and unprivileged
user namespaces widen the kernel's attack surface); CPU time is limited in total, not in
rate (a busy sandbox slows the others until its limit); disk space in ``writable``
folders is limited per file here, in total only where the caller mounted a size-capped
tmpfs there (the grader does, :mod:`.scratch`), while ``/tmp`` and ``/dev/shm`` hold
:data:`TMPFS_BYTES` each; a sandbox with ``share_network=True`` reaches every port its network
namespace offers (a judge's subjects reach the judge's ports); timing and host-wide
information such as ``/proc/meminfo`` stay visible.  A caller killed with SIGKILL takes its
sandboxes along but leaves empty ``ros2nb-sandbox-*`` cgroups and ``/tmp/ros2nb-stage-*``.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Mapping, Sequence

from ros2nb.temporary import owned_folder

from . import cgroups as cgroups_of
from .running import Limits, MiB, Result, Running, remove

#: The launcher program bwrap is started through (run as a file, by an isolated Python).
LAUNCHER = Path(__file__).resolve().with_name('launcher.py')

#: The uid and gid a sandboxed program sees.
INNER_UID = 1000
#: Host uid and gid of sandboxes started by root: no user, file or process has it.
HOST_UID = 2_000_000_000
#: Bytes a sandbox's own /tmp and /dev/shm may each hold (memory, gone when it ends).
TMPFS_BYTES = 512 * MiB
_SIZE = ['--size', str(TMPFS_BYTES)]
ETC_FILES = ('ld.so.cache', 'ld.so.conf', 'ld.so.conf.d', 'passwd', 'group', 'nsswitch.conf',
             'hosts', 'localtime')


Source = Callable[[Path], str]


def _bind(flag: str, path: Path, source: Source = str) -> list[str]:
    return [flag, source(path), str(path)]


def _python_paths() -> list[Path]:
    """The venv (``sys.prefix``) and the installation it links to, e.g. a pyenv version."""
    return sorted({Path(sys.prefix).resolve(), Path(sys.base_prefix).resolve()})


def _system_args(source: Source) -> list[str]:
    """Read-only system files: /usr, the merged-usr links, a minimal /etc."""
    args = _bind('--ro-bind', Path('/usr'), source)
    for name in ('bin', 'lib', 'lib64', 'sbin'):
        top = Path('/') / name
        if top.is_symlink():
            args += ['--symlink', os.readlink(top), str(top)]
        elif top.is_dir():
            args += _bind('--ro-bind', top, source)
    for name in ETC_FILES:
        if (Path('/etc') / name).exists():
            args += _bind('--ro-bind', Path('/etc') / name, source)
    return args


def _path_args(readable: Sequence[Path], writable: Sequence[Path], hidden: Sequence[Path],
               source: Source = str) -> list[str]:
    """Binds in an order that lets a deeper path override a shallower one."""
    mounts = [(0, Path(p)) for p in readable] + [(1, Path(p)) for p in writable]
    mounts += [(2, Path(p)) for p in hidden]
    args: list[str] = []
    for kind, path in sorted(mounts, key=lambda m: (len(m[1].parts), m[0])):
        if kind == 2 and path.is_file():
            args += ['--ro-bind', '/dev/null', str(path)]
        elif kind == 2:
            args += ['--tmpfs', str(path)]
        else:
            args += _bind('--bind' if kind else '--ro-bind', path, source)
    return args


def _namespace_args(share_network: bool, nested: bool, hostname: str) -> list[str]:
    args = ['--unshare-user', '--uid', str(INNER_UID), '--gid', str(INNER_UID), '--unshare-pid',
            '--unshare-ipc', '--unshare-uts', '--hostname', hostname, '--unshare-cgroup-try',
            '--die-with-parent', '--new-session', '--cap-drop', 'ALL']
    args += [] if share_network else ['--unshare-net']
    return args + ([] if nested else ['--disable-userns'])


def inner_prefix(*, readable: Sequence[Path] = (), writable: Sequence[Path] = (),
                 hidden: Sequence[Path] = (), share_shm: bool = False) -> list[str]:
    """The argv a judge puts in front of a subject's argv to sandbox it inside its own sandbox.

    The judge must run in ``Sandbox(nested=True)``.  The subject shares the judge's network
    namespace (ROS 2 between them works over loopback) and sees the judge's files read-only,
    but has its own PID namespace, ``/proc``, ``/tmp`` and IPC, so it can neither see, signal
    nor trace the judge.  Its empty ``/tmp`` hides everything under the judge's ``/tmp``
    except the venv and Python running this module and the ``readable`` paths.  The judge
    sets the subject's environment and working directory (Popen's ``env`` and ``cwd``).

    Fast DDS and ``/dev/shm``: Fast DDS sends data between processes of one host through
    shared memory.  With a private ``/dev/shm`` (the default), judge and subject only hear
    each other when both have ``FASTDDS_BUILTIN_TRANSPORTS=UDPv4`` and do not set
    ``ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`` (which makes rmw_fastrtps choose its own
    transports); the network namespace isolates them anyway.  ``share_shm=True`` works with
    any settings, but lets the subject write into the judge's Fast DDS segments.

    :param readable: paths under ``/tmp`` (as the judge sees them) the subject may read.
    :param writable: paths (as the judge sees them) the subject may write.
    :param hidden: paths the subject must not see (e.g. the judge's expected answers).
    :param share_shm: give the subject the judge's ``/dev/shm`` instead of an empty one.
    :return: a JSON-serialisable list of strings ending in ``--``.
    """
    shm = ['--bind', '/dev/shm', '/dev/shm'] if share_shm else [*_SIZE, '--tmpfs', '/dev/shm']
    return ['bwrap', *_namespace_args(True, False, 'subject'), '--ro-bind', '/', '/',
            '--proc', '/proc', '--dev', '/dev', *_SIZE, '--tmpfs', '/tmp', *shm,
            *_path_args([*_python_paths(), *readable], writable, hidden), '--']


@dataclass(frozen=True)
class Sandbox:
    """A reusable sandbox description; :meth:`start` or :meth:`run` a program in it.

    :param writable: host paths bound read-write at the same path.  When the caller is root
        they are chowned to :data:`HOST_UID` first: give only folders of this sandbox.
    :param readable: host paths bound read-only at the same path (a live view; when the
        caller is root, only what others may read is readable inside).
    :param hidden: paths inside ``readable`` ones replaced by an empty tmpfs (or empty file);
        ones that do not exist when the sandbox starts are skipped.
    :param env: the program's whole environment (nothing is inherited; not Popen's ``env``).
    :param cwd: working directory inside.
    :param share_network: keep the caller's network namespace instead of a new one.
    :param nested: allow the program to start inner sandboxes (see :func:`inner_prefix`).
    :param python: also bind the venv running this module and its Python installation.
    """

    writable: Sequence[Path] = ()
    readable: Sequence[Path] = ()
    hidden: Sequence[Path] = ()
    env: Mapping[str, str] = field(default_factory=dict)
    cwd: Path = Path('/')
    share_network: bool = False
    nested: bool = False
    python: bool = True

    def command(self, argv: Sequence[str], source: Source = str) -> list[str]:
        """The bwrap argv that runs ``argv`` in this sandbox (no limits, no uid change).

        :param argv: the program and its arguments, as seen inside.
        :param source: maps a bound host path to the path bwrap binds it from.
        :return: ``['bwrap', ..., '--', *argv]``.
        """
        readable = [*(_python_paths() if self.python else ()), *self.readable]
        hidden = [p for p in self.hidden if Path(p).exists()]  # nothing to hide otherwise
        args = ['bwrap', *_namespace_args(self.share_network, self.nested, 'sandbox'),
                *_system_args(source), '--proc', '/proc', '--dev', '/dev', *_SIZE, '--tmpfs',
                '/tmp', *_SIZE, '--tmpfs', '/dev/shm',
                *_path_args(readable, self.writable, hidden, source),
                '--remount-ro', '/', '--clearenv']
        for key, value in self.env.items():
            args += ['--setenv', key, value]
        return args + ['--chdir', str(self.cwd), '--', *argv]

    def start(self, argv: Sequence[str], limits: Limits = Limits(), **popen: Any) -> Running:
        """Start ``argv`` in the sandbox without waiting (talk to it over pipes).

        :param argv: the program and its arguments, as seen inside.
        :param limits: resource limits; the wall-time clock starts now.
        :param popen: passed to :class:`subprocess.Popen` (stdin, stdout, stderr, pass_fds).
        :return: the running sandbox; call :meth:`Running.stop` (or use ``with``) when done.
        :raises OSError: when bwrap cannot be started, a writable path cannot be handed over
            or (when root) a readable path is not readable by others.
        """
        drop = os.geteuid() == 0
        if drop:
            _check_world_readable([*(_python_paths() if self.python else ()), *self.readable])
            for path in self.writable:
                _hand_over(Path(path))
        stage = owned_folder('ros2nb-stage-') if drop else None
        sources: list[str] = []

        def staged(path: Path) -> str:  # HOST_UID cannot look up e.g. /root/.pyenv itself
            sources.append(str(path))
            return f'{stage}/{len(sources) - 1}'

        bwrap = self.command(argv, staged if stage else str)
        return _launched(bwrap, limits, {'env': {'PATH': '/usr/bin:/bin'}, **popen},
                         stage=stage, sources=sources, uid=HOST_UID if drop else None)

    def run(self, argv: Sequence[str], limits: Limits = Limits(), input: Any = None,
            steps: Callable[[str], str | None] | None = None, **popen: Any) -> Result:
        """Run ``argv`` in the sandbox to its end or until ``limits.wall_s`` or ``limits.cpu_s``
        runs out.

        :param argv: the program and its arguments, as seen inside.
        :param limits: resource limits.
        :param input: data for stdin (needs ``stdin=subprocess.PIPE``).
        :param steps: the steps its output lines begin (:func:`run_to_end`).
        :param popen: passed to :class:`subprocess.Popen` (stdout, stderr, pass_fds, text).
        :return: exit code, whether it timed out, which limits were enforced, outputs.
        """
        return run_to_end(self.start(argv, limits, **popen), input, steps)


def watched(argv: Sequence[str], limits: Limits = Limits(), **popen: Any) -> Running:
    """Start ``argv`` outside any sandbox, in cgroups of its own watched as a sandbox's are
    (:class:`Running`: its wall time and the CPU time of all its processes together), where
    the caller cannot sandbox it: a judge graded unsandboxed, the corpora's judges.

    :param popen: passed to :class:`subprocess.Popen` (env, cwd, stdout, stderr, text).
    :raises OSError: when the program cannot be started.
    """
    return _launched(list(argv), limits, popen)


def run_to_end(running: Running, input: Any = None,
               steps: Callable[[str], str | None] | None = None) -> Result:
    """Talk to a started program (``input`` on stdin) until it ends or a limit stops it.

    :param steps: reads each line the program prints on stdout as it comes (it needs
        ``stdout=subprocess.PIPE, text=True`` and no ``input``): the name of the step that
        line begins (:meth:`Running.step`), or None.
    """
    with running:
        if steps is None:
            out, err = running.process.communicate(input)
        else:
            out, err = _read_steps(running, steps)
        code = running.stop()
    return Result(code, running.timed_out, running.limits_enforced, out, err,
                  running.out_of_cpu, running.cpu_s, running.stopped_step)


def _read_steps(running: Running, steps: Callable[[str], str | None]) -> tuple[str, str]:
    """Read the program's stdout line by line, marking its steps, and its stderr beside."""
    process, errors = running.process, []
    reader = threading.Thread(target=lambda: errors.append(process.stderr.read())
                              if process.stderr else None, daemon=True)
    reader.start()
    lines = []
    for line in process.stdout or ():
        lines.append(line)
        step = steps(line)
        if step is not None:
            running.step(step)
    process.wait()
    reader.join()
    return ''.join(lines), ''.join(e for e in errors if e)


def _launched(argv: list[str], limits: Limits, popen: dict[str, Any], *, stage: Path | None = None,
              sources: Sequence[str] = (), uid: int | None = None) -> Running:
    """``argv`` started through the launcher in fresh cgroups (its limits, or rlimits where no
    cgroup could be made), watched by a :class:`Running`."""
    cgroups, enforced = cgroups_of.make_cgroups(limits.pids, limits.memory_bytes,
                                                limits.cpu_share)
    memory_rlimit = None if 'memory(cgroup)' in enforced else limits.memory_bytes
    counted = cgroups_of.cpu_seconds(cgroups) is not None
    cpu_rlimit = None if counted or limits.cpu_s is None else max(1, round(limits.cpu_s))
    spec = {'procs': [str(c / 'cgroup.procs') for c in cgroups], 'stage': stage and str(stage),
            'sources': list(sources), 'uid': uid, 'fsize': limits.file_size_bytes,
            'as': memory_rlimit, 'cpu': cpu_rlimit}
    launcher = [sys.executable, '-I', '-S', str(LAUNCHER), '--launch', json.dumps(spec), '--',
                *argv]
    enforced = ['wall', 'file-size', *enforced]
    enforced += ['cpu(cgroup)'] if counted and limits.cpu_s is not None else []
    enforced += ['cpu(rlimit-cpu, per process)'] if cpu_rlimit else []
    enforced += ['memory(rlimit-as, per process)'] if memory_rlimit else []
    try:
        process = subprocess.Popen(launcher, **popen)
    except OSError:
        remove(cgroups, stage)
        raise
    return Running(process, tuple(enforced), cgroups, stage, limits)


def _check_world_readable(paths: Sequence[Path]) -> None:
    for path in map(Path, paths):
        need = 0o005 if path.is_dir() else 0o004
        if path.exists() and path.stat().st_mode & need != need:
            raise PermissionError(f'{path} is not readable by others, so not inside a sandbox '
                                  f'started by root: chmod o+rX it (or copy it)')


def _hand_over(path: Path) -> None:
    """Chown ``path`` and everything under it to HOST_UID, never following symlinks."""
    os.lchown(path, HOST_UID, HOST_UID)
    for root, dirs, files in os.walk(path):
        for name in dirs + files:
            os.lchown(os.path.join(root, name), HOST_UID, HOST_UID)


def problem() -> str | None:
    """Why no sandbox can be made here, in one line saying what to do; None when it can.

    Starts a trivial sandbox (``true``) the same way :meth:`Sandbox.run` does.
    """
    if shutil.which('bwrap') is None:
        return 'bubblewrap is not installed: apt-get install bubblewrap'
    try:
        result = Sandbox().run(['true'], Limits(wall_s=30), stderr=subprocess.PIPE, text=True)
    except OSError as error:
        return f'cannot start bubblewrap ({error}): check that /usr/bin/bwrap runs'
    if result.returncode == 0:
        return None
    why = (result.stderr.strip().splitlines() or ['no message'])[-1]
    if 'namespace' in why.lower():
        return (f'{why}: allow unprivileged user namespaces '
                '(sysctl kernel.unprivileged_userns_clone=1 and user.max_user_namespaces>0)')
    return f'a trivial sandbox failed: {why}'
