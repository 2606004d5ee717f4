"""The fast lane holds what it promises: lint that can fail, and no test that quietly starts ROS.

``make check`` runs ruff, then ``pytest --lane check`` (tests/conftest.py).  Each protection
is shown failing on a planted mistake, beside its honest twin passing.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TESTS = ROOT / 'tests'
RUFF = Path(sys.executable).with_name('ruff')

PLANTED_LINT = 'import os\n\n\ndef unused_import():\n    return 1\n'
HONEST_LINT = 'import os\n\n\ndef used_import():\n    return os.sep\n'


@pytest.mark.parametrize('source, fails', [(PLANTED_LINT, True), (HONEST_LINT, False)],
                         ids=['a planted unused import', 'its honest twin'])
def test_the_lint_fails_on_a_planted_error_only(tmp_path, source, fails):
    planted = tmp_path / 'planted.py'
    planted.write_text(source)
    done = subprocess.run([str(RUFF), 'check', '--config', str(ROOT / 'pyproject.toml'),
                           str(planted)], capture_output=True, text=True, cwd=ROOT)
    assert (done.returncode != 0, 'F401' in done.stdout) == (fails, fails), done.stdout


PLANTED_TESTS = '''
import pytest
import ros2nb
from jupyter_client.manager import start_new_kernel


def test_pure():
    assert sum(range(4)) == 6


def test_brings_ros_up_unmarked():
    ros2nb.start()
    ros2nb.shutdown()


def test_starts_a_kernel_unmarked():
    manager, client = start_new_kernel()
    client.stop_channels()
    manager.shutdown_kernel(now=True)


@pytest.mark.ros
def test_brings_ros_up_marked():
    ros2nb.start()
    ros2nb.shutdown()
'''


@pytest.mark.ros
@pytest.mark.kernel
def test_the_check_lane_fails_a_test_that_starts_ros_or_a_kernel_unmarked(tmp_path):
    """A copy of tests/conftest.py runs a planted file: the unmarked tests that bring ROS up
    or start a kernel fail and name their marker; the marked one is left to the slow lane."""
    (tmp_path / 'conftest.py').write_text((TESTS / 'conftest.py').read_text())
    (tmp_path / 'test_planted.py').write_text(PLANTED_TESTS)
    (tmp_path / 'pytest.ini').write_text('[pytest]\n')
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}  # the lane's own
    env['PYTHONPATH'] = os.pathsep.join([str(TESTS), str(ROOT / 'src')])
    done = subprocess.run([sys.executable, '-m', 'pytest', '-p', 'no:cacheprovider', '-p',
                           'no:warnings', '-q',
                           '-c', str(tmp_path / 'pytest.ini'), '--rootdir', str(tmp_path),
                           '--lane', 'check', str(tmp_path / 'test_planted.py')],
                          capture_output=True, text=True, env=env, cwd=tmp_path, timeout=600)
    out = done.stdout
    assert done.returncode == 1, out[-3000:]
    assert 'test_brings_ros_up_unmarked started ros in the check lane: mark it ' \
           '@pytest.mark.ros' in out, out[-3000:]
    assert 'test_starts_a_kernel_unmarked started kernel in the check lane: mark it ' \
           '@pytest.mark.kernel' in out, out[-3000:]
    assert '3 passed, 1 deselected, 2 errors' in out, out[-3000:]
