"""The sandbox launcher: ``python -I -S launcher.py --launch SPEC -- bwrap ...``.

Part of :mod:`.bubblewrap`, run as a file by the isolated interpreter (no site-packages, so
nothing of the course or the venv is imported): it joins the sandbox's cgroups, sets its
rlimits, stages the bind sources in a private mount namespace, drops root and execs
bubblewrap.
"""

from __future__ import annotations

import ctypes
import json
import os
import resource
import sys
from pathlib import Path
from typing import Any


def _launch(spec: dict[str, Any], bwrap: list[str]) -> None:
    """Runs as ``python -I -S launcher.py --launch SPEC -- bwrap ...``: join the cgroups, set
    rlimits, stage the bind sources in a private mount namespace, drop root, exec bwrap."""
    for procs in spec['procs']:
        Path(procs).write_text(str(os.getpid()))
    resource.setrlimit(resource.RLIMIT_FSIZE, (spec['fsize'], spec['fsize']))
    if spec['as']:
        resource.setrlimit(resource.RLIMIT_AS, (spec['as'], spec['as']))
    if spec['cpu']:  # SIGXCPU at the limit (it ends a process that does not handle it)
        resource.setrlimit(resource.RLIMIT_CPU, (spec['cpu'], spec['cpu'] + 1))
    if spec['stage']:
        _mount_sources(spec['sources'], Path(spec['stage']))
    if spec['uid'] is not None:
        os.setgroups([])
        os.setresgid(spec['uid'], spec['uid'], spec['uid'])
        os.setresuid(spec['uid'], spec['uid'], spec['uid'])
    os.execvp(bwrap[0], bwrap)


def _mount_sources(sources: list[str], stage: Path) -> None:
    libc = ctypes.CDLL(None, use_errno=True)
    ms_bind, ms_rec, ms_private, clone_newns = 4096, 16384, 1 << 18, 0x20000

    def check(result: int, what: str) -> None:
        if result != 0:
            raise OSError(ctypes.get_errno(), f'{what}: {os.strerror(ctypes.get_errno())}')

    check(libc.unshare(clone_newns), 'unshare(CLONE_NEWNS)')
    check(libc.mount(b'none', b'/', None, ms_rec | ms_private, None), 'make / private')
    check(libc.mount(b'tmpfs', bytes(stage), b'tmpfs', 0, b'mode=0755'), f'tmpfs on {stage}')
    for n, source in enumerate(sources):
        target = stage / str(n)
        target.mkdir() if os.path.isdir(source) else target.touch()
        check(libc.mount(source.encode(), bytes(target), None, ms_bind | ms_rec, None),
              f'bind {source}')


if __name__ == '__main__' and sys.argv[1:2] == ['--launch']:
    try:
        _launch(json.loads(sys.argv[2]), sys.argv[4:])
    except OSError as error:
        print(f'sandbox launcher: {error}', file=sys.stderr)
        sys.exit(125)
