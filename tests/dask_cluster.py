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
def local_cluster(folder: Path, workers: int = 2,
                  env: Optional[dict] = None) -> Iterator[LocalCluster]:
    """``dask scheduler`` on 127.0.0.1 (a free port, its environment ``env``) and ``workers``
    workers, all connected."""
    folder.mkdir(parents=True, exist_ok=True)
    info = folder / 'scheduler.json'
    log = open(folder / 'scheduler.log', 'w')
    scheduler = subprocess.Popen(
        [DASK, 'scheduler', '--host', '127.0.0.1', '--port', '0', '--no-dashboard',
         '--scheduler-file', str(info)], stdout=log, stderr=subprocess.STDOUT,
        start_new_session=True, env=env or os.environ.copy())
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


def _executing(dask_worker) -> list:
    """Run on a worker: the keys of the tasks it runs now."""
    return [task.key for task in dask_worker.state.executing]


def in_a_sandbox(pid: int) -> bool:
    """True when a process below ``pid`` is a bubblewrap sandbox (a learner's notebook or
    judge running: the worker holds that learner mid-grading)."""
    from ros2nb.patience import child_pids

    below = list(child_pids(pid))
    while below:
        child = below.pop()
        with contextlib.suppress(OSError):
            if Path(f'/proc/{child}/cmdline').read_bytes().startswith(b'bwrap'):
                return True
        below += child_pids(child)
    return False


def kill_when_grading(address: str, name: str, learner: str = '', alone: bool = False) -> dict:
    """SIGKILL the process of the worker named ``name`` once it runs a learner's task (whose
    key holds ``learner``) and a sandbox of that learner's runs (:func:`in_a_sandbox`).  With
    ``alone``, only once that task is all the worker holds (a task queued on a worker that
    dies is counted as killed there too).  Return its address, pid and the keys it ran."""
    import cloudpickle
    from distributed import Client

    cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers lack tests/ on sys.path
    with Client(address, set_as_default=False, timeout=60) as client:
        def holding():
            workers = client.scheduler_info(n_workers=-1)['workers']
            worker = next((a for a, w in workers.items() if w.get('name') == name), None)
            if worker is None:
                return None
            keys = client.run(_executing, workers=[worker]).get(worker)
            if not keys or not any(learner in str(key) for key in keys):
                return None
            if alone and len(client.processing(workers=[worker]).get(worker, ())) > 1:
                return None
            pid = client.run(os.getpid, workers=[worker])[worker]
            return in_a_sandbox(pid) and {'worker': worker, 'pid': pid, 'keys': keys}

        held = wait_for(holding, f'worker {name} grading {learner or "a learner"}',
                        interval=0.2)
        os.kill(held['pid'], signal.SIGKILL)
        return held
