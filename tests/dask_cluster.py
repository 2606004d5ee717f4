"""A real Dask cluster on loopback for the tests: ``dask scheduler`` and ``dask worker`` processes.

Started with Dask's own command line, as an instructor starts them (docs/classroom-server.md);
nothing is mocked.  Readiness is polled (the scheduler's file, then ``wait_for_workers``).
"""

from __future__ import annotations

import contextlib
import json
import os
import signal
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator, Optional

from waiting import wait_for

DASK = str(Path(sys.executable).with_name('dask'))


@dataclass
class LocalCluster:
    """A scheduler and its workers, each a process group of its own."""

    address: str
    folder: Path
    scheduler: subprocess.Popen
    workers: list[subprocess.Popen] = field(default_factory=list)

    def add_worker(self, name: str, env: Optional[dict] = None,
                   cwd: Optional[Path] = None) -> subprocess.Popen:
        """Start ``dask worker --nworkers 1 --nthreads 1`` on loopback, named ``name``."""
        log = open(self.folder / f'worker-{name}.log', 'w')
        worker = subprocess.Popen(
            [DASK, 'worker', self.address, '--nworkers', '1', '--nthreads', '1',
             '--host', '127.0.0.1', '--name', name, '--no-dashboard',
             '--local-directory', str(self.folder / f'worker-{name}')],
            stdout=log, stderr=subprocess.STDOUT, start_new_session=True,
            env=env or os.environ.copy(), cwd=cwd)
        log.close()
        self.workers.append(worker)
        return worker

    def wait_for_workers(self, count: int) -> None:
        """Return once ``count`` workers are connected to the scheduler."""
        from distributed import Client
        with Client(self.address, set_as_default=False, timeout=60) as client:
            wait_for(lambda: len(client.scheduler_info(n_workers=-1)['workers']) >= count,
                     f'{count} Dask workers connected',
                     seen=lambda: self.log_tails())

    def log_tails(self) -> str:
        return ' | '.join(f'{p.name}: {p.read_text()[-300:]}'
                          for p in sorted(self.folder.glob('*.log')))


def _stop(process: subprocess.Popen) -> None:
    with contextlib.suppress(ProcessLookupError):
        os.killpg(process.pid, signal.SIGTERM)
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait()


@contextlib.contextmanager
def local_cluster(folder: Path, workers: int = 2) -> Iterator[LocalCluster]:
    """``dask scheduler`` on 127.0.0.1 (a free port) and ``workers`` workers, all connected."""
    folder.mkdir(parents=True, exist_ok=True)
    info = folder / 'scheduler.json'
    log = open(folder / 'scheduler.log', 'w')
    scheduler = subprocess.Popen(
        [DASK, 'scheduler', '--host', '127.0.0.1', '--port', '0', '--no-dashboard',
         '--scheduler-file', str(info)], stdout=log, stderr=subprocess.STDOUT,
        start_new_session=True)
    log.close()
    cluster = None
    try:
        address = wait_for(lambda: info.is_file() and json.loads(info.read_text() or '{}')
                           .get('address'), 'the Dask scheduler\'s address',
                           seen=lambda: (folder / 'scheduler.log').read_text()[-500:])
        cluster = LocalCluster(address, folder, scheduler)
        for number in range(workers):
            cluster.add_worker(f'w{number}')
        cluster.wait_for_workers(workers)
        yield cluster
    finally:
        for worker in (cluster.workers if cluster else []):
            _stop(worker)
        _stop(scheduler)
