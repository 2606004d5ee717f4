"""The fast lane holds what it promises: lint that can fail, and no test that quietly starts ROS.

``make check`` runs ruff, mypy (shown in tests/test_types.py), then ``pytest --lane check``
(tests/conftest.py).  Each protection is shown failing on a planted mistake, beside its honest
twin passing; the lanes are run on planted tests with pytest's own ``pytester``.
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
def test_the_check_lane_fails_a_test_that_starts_ros_or_a_kernel_unmarked(pytester,
                                                                           monkeypatch):
    """tests/conftest.py runs a planted file in a pytest of its own (its own process: it
    brings ROS up): the unmarked tests that bring ROS up or start a kernel fail and name their
    marker; the marked one is left to the slow lane."""
    pytester.makeconftest((TESTS / 'conftest.py').read_text())
    pytester.makepyfile(test_planted=PLANTED_TESTS)
    pytester.makeini('[pytest]\n')  # none of the course's options: the lane's alone
    monkeypatch.delenv('ROS_DOMAIN_ID', raising=False)  # the lane claims its own
    monkeypatch.setenv('PYTHONPATH', os.pathsep.join([str(TESTS), str(ROOT / 'src')]))
    result = pytester.runpytest_subprocess('-p', 'no:cacheprovider', '-p', 'no:warnings',
                                           '--lane', 'check', timeout=600)
    result.stdout.fnmatch_lines([
        '*test_brings_ros_up_unmarked started ros in the check lane: mark it @pytest.mark.ros*',
        '*test_starts_a_kernel_unmarked started kernel in the check lane: mark it '
        '@pytest.mark.kernel*'], consecutive=False)
    result.assert_outcomes(passed=3, deselected=1, errors=2)
