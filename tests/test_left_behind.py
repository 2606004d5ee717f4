"""Nothing is left behind: no process of a check its learner stopped, nor of a kernel that
ended, and no temporary folder of a process that no longer runs.

A learner who pressed Stop on a slow check, or restarted or shut down the kernel while it
ran, once left its judge running with no parent, and the judge its subjects; a killed kernel,
judge or grader left its temporary folders for good.  Now the judge ends with its kernel
(Linux's parent-death signal), closing its session on the way (its subjects end, its folder
goes), its fork server with it, each subject with its server; and every temporary folder of
the course is named for its process and swept once that process is gone
(:mod:`ros2nb.temporary`).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import psutil
import pytest

from kernels import Kernel
from ros2nb.temporary import owned_folder, sweep_all, temporary_folder
from waiting import PATIENCE_S, wait_for, wait_until


def _ended_pid() -> int:
    """The id of a process that ran and ended (reaped)."""
    process = subprocess.Popen([sys.executable, '-c', 'pass'])
    process.wait()
    return process.pid


def test_a_folder_of_a_process_that_ended_is_swept_and_one_that_runs_is_kept(tmp_path):
    ended = _ended_pid()
    left = [tmp_path / f'ros2nb-judge-{ended}-abcdefgh', tmp_path / f'ros2nb-mutants-06-{ended}-xy']
    kept = [tmp_path / f'ros2nb-judge-{os.getpid()}-ijklmnop', tmp_path / 'ros2nb-domains',
            tmp_path / 'ros2nb-bench-qrstuvwx']
    for folder in (*left, *kept):
        folder.mkdir()
        (folder / 'a file').write_text('kept or not')
    assert sorted(sweep_all(tmp_path)) == sorted(left)
    assert [folder.is_dir() for folder in kept] == [True] * len(kept)
    made = owned_folder('ros2nb-judge-', tmp_path)  # named for this process: kept by a sweep
    assert made.name.startswith(f'ros2nb-judge-{os.getpid()}-') and sweep_all(tmp_path) == []


def test_a_kernels_temporary_folder_is_named_for_it_and_kept_while_it_runs():
    with temporary_folder('bags') as name:
        assert Path(name).name.startswith(f'ros2nb-bags-{os.getpid()}-')
        sweep_all(Path(name).parent)
        assert Path(name).is_dir()  # this process runs: kept
    assert not Path(name).exists()  # gone with its with-block, as a TemporaryDirectory


#: A sensor whose constructor waits ten minutes: its check waits for the node meanwhile.
SLOW_SENSOR = "        import time\n        time.sleep(600)\n"
STARTED = "        self.get_logger().info('Temperature Sensor Node Started')\n"


def _judge_tree(kernel_pid: int) -> list[psutil.Process]:
    """The kernel's judge and what it started (its fork server, its subjects), once the
    judge has a subject: empty before."""
    for child in psutil.Process(kernel_pid).children():
        if 'ros2nb.judge' in ' '.join(child.cmdline()):
            below = child.children(recursive=True)
            if any('ros2nb.subject' in ' '.join(p.cmdline()) or p.ppid() != child.pid
                   for p in below):
                return [child, *below]
    return []


@pytest.mark.kernel
@pytest.mark.judge
@pytest.mark.parametrize('how', ['stop', 'restart', 'shutdown'])
def test_a_check_stopped_or_its_kernel_ended_leaves_no_process_behind(how, tmp_path):
    kernel = Kernel(tmp_path / 'workspace')
    closed = False
    try:
        kernel_pid = int(kernel.run('import os\nprint(os.getpid())').stdout)
        sensor = kernel.run('import ros2nb\nws = ros2nb.course.catch_up(4)\n'
                            'print(ws / ros2nb.course.PUBLISHER_FILE)')
        path = Path(sensor.stdout.strip().splitlines()[-1])
        path.write_text(path.read_text().replace(STARTED, STARTED + SLOW_SENSOR))
        kernel.client.execute('ros2nb.checks.check_sensor_constructor()')
        tree = wait_for(lambda: _judge_tree(kernel_pid), 'the judge with its subject')
        control = subprocess.Popen(['sleep', '600'], start_new_session=True)  # not the course's
        if how == 'stop':
            kernel.manager.interrupt_kernel()
        elif how == 'restart':
            kernel.restart()
        else:
            kernel.close()
            closed = True
        gone = wait_until(lambda: not any(p.is_running() and p.status() != psutil.STATUS_ZOMBIE
                                          for p in tree), PATIENCE_S)
        assert gone, [(p.pid, p.cmdline()) for p in tree if p.is_running()]
        judge = tree[0].pid
        sweep_all()  # what a judge killed before it could remove its folder left, the next
        assert not list(Path(tempfile.gettempdir()).glob(f'ros2nb-judge-{judge}-*'))  # sweeps
        assert control.poll() is None  # the failure prevented: a process on its own lives on
        control.kill()
        control.wait()
    finally:
        if not closed:
            kernel.close()
