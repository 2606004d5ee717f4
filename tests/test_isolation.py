"""Every kernel is its own ROS world: three course kernels at once, each prints its stored outputs.

The scenarios a learner meets in JupyterLab: notebook 03's kernel still up with its sensor
added while notebook 04 runs, and two kernels of notebook 04 at once (two learners on one
server, or nbgrader's Validate next to the learner's own kernel). No ROS_DOMAIN_ID is set:
each kernel claims its own domain. The companion test forces one shared domain, as every
kernel had before, and shows the cross-talk this prevents.
"""

import copy

import nbformat
import pytest

from notebook_outputs import ROOT, differences, kernel_env, run_at_once

pytestmark = [pytest.mark.kernel, pytest.mark.timeout(900)]

NB03 = ROOT / 'solutions' / '03-write-the-publisher.ipynb'
NB04 = ROOT / 'solutions' / '04-write-the-subscriber.ipynb'


def without_final_stop(nb: nbformat.NotebookNode) -> nbformat.NotebookNode:
    """The notebook without its last code cell (``ros2nb.stop()``): its nodes stay up."""
    nb = copy.deepcopy(nb)
    last = max(i for i, c in enumerate(nb.cells) if c.cell_type == 'code')
    assert 'ros2nb.stop()' in nb.cells[last].source
    del nb.cells[last:]
    return nb


def up_to(nb: nbformat.NotebookNode, marker: str) -> nbformat.NotebookNode:
    """The notebook up to and including the first cell that contains ``marker``."""
    nb = copy.deepcopy(nb)
    end = next(i for i, c in enumerate(nb.cells) if marker in c.source)
    del nb.cells[end + 1:]
    return nb


def test_three_course_kernels_at_once_each_print_their_stored_outputs(tmp_path):
    stored03, stored04 = (nbformat.read(p, as_version=4) for p in (NB03, NB04))
    runs = [without_final_stop(stored03), copy.deepcopy(stored04), copy.deepcopy(stored04)]
    run_at_once([(nb, kernel_env(tmp_path)) for nb in runs])
    assert differences(without_final_stop(stored03), runs[0]) == []
    assert differences(stored04, runs[1]) == []
    assert differences(stored04, runs[2]) == []


def test_companion_one_shared_domain_shows_the_cross_talk(tmp_path):
    """Before: every kernel on one domain. Two kernels of 04 then hear each other."""
    stored = up_to(nbformat.read(NB04, as_version=4), "times_s, temps_c = ros2nb.record(")
    runs = [copy.deepcopy(stored), copy.deepcopy(stored)]
    run_at_once([(nb, kernel_env(tmp_path, domain=77)) for nb in runs])
    changed = differences(stored, runs[0]) + differences(stored, runs[1])
    assert changed, 'two kernels on one domain printed exactly their stored outputs'
