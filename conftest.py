"""Test-session set-up shared by the unit tests and nbval runs (``make test``).

- No ``ROS_DOMAIN_ID`` is set: every process that brings ROS up (this pytest process,
  each nbval kernel, each judge) claims a free domain of its own (ros2nb.domains), so two
  runs never see each other's topics. Discovery stays on this machine, with the course's
  Fast DDS profile (ros2nb.domains.DISCOVERY_PROFILE).
- The course workspace goes to a temporary folder removed at the end, so tests never
  touch a learner's ``workspace/``.  So do the files every kernel writes (IPython's
  history, Jupyter's connection files, the learner's progress): tests run side by side
  (pytest-xdist, one process per worker, each with this set-up of its own), and while one
  of them checks
  that grading leaves the repository byte-identical no other may write into it.
- Cells tagged ``learner-check`` (a Challenge's check) must raise ``CheckFailed`` with its
  friendly message in ``notebooks/`` (the challenge is unsolved there) and must pass in
  ``solutions/``.
"""

from __future__ import annotations

import os
import shutil
import signal
import sys
from pathlib import Path

import pytest

from ros2nb import domains
from ros2nb.temporary import owned_folder

# A shell's background job (`make test &` in a script) starts with Ctrl+C ignored, and every
# process started from it inherits that: the tests that press Ctrl+C (for a node process, for
# a spin) would then see it ignored. A person at a terminal never runs with it ignored.
if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
os.environ.pop('ROS_DOMAIN_ID', None)
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
domains.use_discovery_profile()  # the tests' own nodes find peers as the course's processes do
# Named for this process (each xdist worker makes its own): a killed run's is swept later.
_SCRATCH = owned_folder('ros2nb-test-')
os.environ['ROS2NB_WORKSPACE'] = str(_SCRATCH / 'ROS2_and_RL_Tutorials')
os.environ['IPYTHONDIR'] = str(_SCRATCH / 'ipython')
os.environ['JUPYTER_RUNTIME_DIR'] = str(_SCRATCH / 'jupyter-runtime')
os.environ['ROS2NB_PROGRESS'] = str(_SCRATCH / 'progress.json')  # never in the notebooks' folder

LEARNER_CHECK_TAG = 'learner-check'


def pytest_sessionfinish(session, exitstatus) -> None:
    shutil.rmtree(_SCRATCH, ignore_errors=True)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_call(item):
    outcome = yield
    cell = getattr(item, 'cell', None)
    if cell is None or LEARNER_CHECK_TAG not in cell.get('metadata', {}).get('tags', []):
        return
    errors = [o for o in (item.test_outputs or []) if o.get('output_type') == 'error']
    learner_version = 'notebooks' in Path(str(item.fspath)).parts
    if learner_version:
        if not errors or errors[0].get('ename') != 'CheckFailed':
            outcome.force_exception(AssertionError(
                f'{item.name}: an unsolved challenge check must raise CheckFailed with a '
                f'message for the learner; got {[e.get("ename") for e in errors] or "no error"}'))
    elif errors:
        outcome.force_exception(AssertionError(
            f'{item.name}: the solution does not pass its own check: '
            f'{errors[0].get("ename")}: {errors[0].get("evalue")}'))


#: Test files that take longest, started first so that pytest-xdist's workers finish together
#: (scheduling only: no test depends on it); ``benchmarks/test_profile.py`` measures each
#: file alone.  Files that mostly wait (a hub, a message that never comes, an image build) go
#: early too: beside the CPU-bound work they cost nothing, while at the end they left the CPUs
#: idle.
#: make test passes --no-loadscope-reorder: xdist otherwise sorts files by their number of
#: tests, whatever this order says.
LONGEST_FIRST = ('test_grading.py', 'test_corpus_honest.py', 'test_corpus_wrong.py',
                 'test_mutants.py',
                 'test_jupyterhub.py', 'test_checks_forged.py', 'test_image.py',
                 'test_checks.py', 'test_lessons_06_07.py', 'test_corpora.py',
                 'test_checks_parameters.py',
                 'test_checks_qos.py', 'test_checks_bag_judge.py', 'test_isolation.py',
                 'test_sandbox.py', 'test_grading_cli.py', 'test_checks_bag_kernel.py',
                 'test_runtime.py', 'test_workspace.py', 'test_subjects.py')


#: Notebooks that need a newer Python than the course's oldest (3.10): 10 reads and writes
#: bags with rosbags, whose apsw needs 3.11. Their first cell says so in one line.
NEEDS_PYTHON = {'10-record-and-replay.ipynb': (3, 11)}


def pytest_collection_modifyitems(config, items) -> None:
    def rank(item) -> int:
        name = Path(str(item.fspath)).name
        return LONGEST_FIRST.index(name) if name in LONGEST_FIRST else len(LONGEST_FIRST)
    items.sort(key=rank)  # stable: the order inside a file is kept
    for item in items:
        needed = NEEDS_PYTHON.get(Path(str(item.fspath)).name)
        if needed and sys.version_info[:2] < needed:
            item.add_marker(pytest.mark.skip(
                reason=f'needs Python {needed[0]}.{needed[1]} or newer (rosbags needs apsw)'))
