"""A notebook whose run keeps a CPU busy without waiting is stopped at its CPU limit, with a
note that says so, instead of burning on until the cell and notebook limits.

The learner is notebook 03 written as the solution, but with a sensor whose constructor
starts a thread that logs as fast as it can (``benchmarks/flood_class.py`` grades it beside
two complete learners).  Its run once kept its kernel busy for over 300 CPU-seconds, two
cells running into the 120-s cell limit; the judge's side of such a flood is
``tests/test_floods.py``.
"""

import pytest

from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.judging.runs import run_note, run_notebook
from ros2nb_instructor.grading.sandboxed.runner import RunStatus
from ros2nb_instructor.grading.sandbox.scratch import Scratch
from ros2nb_instructor.grading.judging.settings import Settings
from ros2nb_instructor.grading.intake.submissions import Learner

from test_floods import flooder_notebook

pytestmark = [pytest.mark.sandbox, pytest.mark.kernel, pytest.mark.ros,
              pytest.mark.skipif(bubblewrap.problem() is not None,
                                 reason=str(bubblewrap.problem())),
              pytest.mark.timeout(400)]

NOTEBOOK = '03-write-the-publisher'


def flooder_run(tmp_path, settings: Settings, monkeypatch
                ) -> tuple[RunStatus, str, bubblewrap.Result]:
    """The flooder's 03 run in its sandbox, as the grader runs it: the runner's status, the
    note the learner gets, and how the sandbox ended (its CPU seconds)."""
    import nbformat
    notebook = nbformat.from_dict(flooder_notebook('rosout'))
    ended = []
    run = bubblewrap.Sandbox.run
    monkeypatch.setattr(bubblewrap.Sandbox, 'run', lambda *a, **kw: ended.append(run(*a, **kw))
                        or ended[-1])
    tmp_path.mkdir()
    scratch = Scratch(tmp_path, Learner('flooder', 'flooder'))
    try:
        done = run_notebook(scratch, NOTEBOOK, notebook, settings)
    finally:
        scratch.remove()
    return done.status, run_note(done) or '', ended[-1]


def test_a_kernel_that_floods_is_stopped_at_its_cpu_limit(tmp_path, monkeypatch):
    status, note, ended = flooder_run(
        tmp_path / 'limited', Settings(120, 600, True, notebook_cpu=10), monkeypatch)
    assert ended.out_of_cpu and ended.cpu_s >= 10 and not status.finished, (ended, status)
    assert note.startswith('its run reached the limit of 10 CPU-seconds for running a '
                           'notebook'), note
    # It names the cells that did not run and where the points come from, and blames no one:
    # an honest notebook that explores at length is stopped with the same words.
    ran, cells = status.ran, status.cells
    assert f'cells {ran + 1}-{cells} did not run' in note, (note, status)
    assert "its points come from the grader's checks" in note, note
    assert not any(word in note for word in ('loop', 'runaway', 'as fast as')), note
    # The control: with twice the limit the same run burns on to that one too, where the
    # course's own 03 uses under 10 CPU-seconds in all (benchmarks/notebook_cpu.py).  CPU
    # time, not wall time: it holds however busy the machine is.
    _status, note, ended = flooder_run(
        tmp_path / 'doubled', Settings(120, 600, True, notebook_cpu=20), monkeypatch)
    assert ended.out_of_cpu and ended.cpu_s >= 20, ended
