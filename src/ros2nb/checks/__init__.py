"""The checks behind every part you write: each says in one line what is still wrong.

A check passes with one ``Check passed: ...`` line, or raises :class:`CheckFailed` whose
one line names your value, the expected one and what to change; when your own code
raised, you see its traceback (your lines only) instead.  Checks test behaviour (what a
node publishes and logs, what a function returns, how a process exits on Ctrl+C); they
never print the answer's code.

Checks of your files (notebooks 03-07) run in a judge process of their own
(:mod:`ros2nb.judge`, started by name), on a ROS domain of their own, so the nodes
running in your kernel neither disturb them nor are disturbed.  The grader runs the very
same functions, in the same way, on your submitted work; the points come from there, never
from your kernel.  Checks of a function or class you defined in a cell (notebooks 00-02)
call it right here in the kernel; the grader runs those from the source of your answer cell.

One module per lesson (``lesson00`` ... ``lesson10``) on a small shared vocabulary:
``base`` (a check's registration and parts), ``dispatch`` (kernel to judge and back),
``verdicts``, ``answers`` (answer cells), ``nodes`` (a node from a file), ``mains``
(``main()`` and Ctrl+C).  A new lesson adds a module and its names here.  Each check
registers itself by its own name (:func:`.base.judged`, :func:`.base.direct`); the judge
runs one with :func:`run_check`.
"""

from __future__ import annotations

import contextlib
import io
import sys
from typing import Any, Optional

from .. import graded_parts, working
from ..errors import CheckFailed, Ros2nbError
from ..hand_ins import HandInError, due_line, standing
from ..judge_interface import Judge
from ..on_first_use import loader
from . import evidence

#: Each lesson's checks, by the module that holds them.  A module loads on first use of one
#: of its names (PEP 562): a notebook's kernel and its judge load their own lesson's
#: checks, not every lesson's libraries (catkin_pkg for 02, rosbags for 10).
LESSONS = {
    'lesson00': ('check_endpoint',),
    'lesson01': ('check_expanded_path',),
    'lesson02': ('check_dependencies', 'package_dependencies'),
    'lesson03': ('check_publisher_samples', 'check_sensor_callback', 'check_sensor_constructor',
                 'check_sensor_hour', 'check_sensor_main'),
    'lesson04': ('check_monitor_callback', 'check_monitor_constructor', 'check_monitor_main',
                 'check_monitor_readings'),
    'lesson05': ('check_entry_points', 'check_package_runs', 'check_setup_cfg'),
    'lesson06': ('check_counting_monitor', 'check_fan_controller', 'check_fan_main',
                 'check_room_arguments'),
    'lesson06_worker': ('check_responsive_worker',),
    'lesson07': ('check_plot_callback',),
    'lesson08': ('check_monitor_parameters', 'check_threshold_callback'),
    'lesson09': ('check_latched_thresholds', 'check_newest_only', 'check_sensor_subscription'),
    'lesson10': ('check_readings', 'check_recording', 'check_replay'),
}
_MODULE_OF = {name: module for module, names in LESSONS.items() for name in names}


__getattr__, __dir__ = loader(globals(), _MODULE_OF)


def run_check(name: str, judge: Optional[Judge], *args: Any, **kwargs: Any) -> None:
    """Run the body of the check ``name`` with ``judge`` and print its passed line; once,
    or again while it could not decide (:func:`.base.decided`; the judge's subjects end
    between tries).

    The judge's one way into the checks (:mod:`ros2nb.judge`): its lesson's module loads on
    first use, and the body registered under ``name`` runs with the judge's session.

    :param name: e.g. ``'check_sensor_constructor'``.
    :param args: the call's arguments after the judge (the learner's answer cells as
        :class:`~ros2nb.judge_interface.AnswerRef`).
    :raises ValueError: for a name no lesson registers (a mistake of the course's).
    :raises CheckFailed: (or :class:`~ros2nb.errors.LearnerCodeError`) with the verdict.
    :raises NotDecided: when no try could decide (its line says so, and why).
    """
    from .base import CHECKS, decided, passed
    if name in _MODULE_OF:
        getattr(sys.modules[__name__], name)  # loads its lesson's module, which registers it
    if name not in CHECKS:
        raise ValueError(f'no check is named {name!r}')
    again = judge.drop_all if judge is not None else (lambda: None)
    passed(decided(lambda: _run_once(CHECKS[name], judge, args, kwargs), again))


def _run_once(body: Any, judge: Optional[Judge], args: tuple[Any, ...],
              kwargs: dict[str, Any]) -> str:
    """One run of a check's body; its passed line."""
    observer = getattr(judge, 'observer', None)
    if observer is None:
        return body(judge, *args, **kwargs)
    # A flood of the learner's code fails the check it happened in, whatever the check made
    # of what was left (the judge ended the flooding processes): its line says what happened.
    # (What the subjects' audit hooks saw is only noted for the instructor: no check relies
    # on it, ros2nb.judge.reaching.)
    observer.floods.forget()
    try:
        message = body(judge, *args, **kwargs)
    except BaseException:
        observer.floods.raise_any()
        raise
    observer.floods.raise_any()
    return message


#: Checks that ``progress(check=True)`` leaves out although they need no argument: each
#: builds the package with colcon (tens of seconds on a busy machine).
NOT_QUICK = ('check_entry_points', 'check_setup_cfg', 'check_package_runs')


def progress(check: bool = False) -> None:
    """Show your progress: every graded part of the 11 notebooks, passed, failed or not yet,
    with its points, from the checks you ran in this lab (kept in your work folder,
    :mod:`ros2nb.graded_parts`).  Only a guide: the grader runs every check itself.  A pass
    whose file changed since (or whose code the notebook, as saved, no longer holds) says
    ``passed, then changed``: run its check again.  On the course's hub it also shows when
    each notebook is due (your extension's date, if you have one), when you handed it in
    (``ros2nb.hand_in``), and a link to your feedback once it is released.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param check: first run again the quick checks of your files (those that need no
        argument and build nothing; a check that takes your function runs in its own
        notebook), so the table says how your files stand now.  Each takes a few seconds.
    :raises OSError: when the course's notebooks cannot be read (ros2nb outside the course).
    """
    all_parts = graded_parts.parts()
    if check:
        _check_again(all_parts)
    recorded = graded_parts.outcomes()
    work = graded_parts.record_path().parent
    states = {}
    for part in all_parts:
        states[part.grade_id] = graded_parts.state(part, recorded)
        if states[part.grade_id] == graded_parts.PASSED and evidence.changed(
                part, recorded[str(part.check)], work):
            states[part.grade_id] = graded_parts.STALE
    notes: dict[str, str] = {}
    link, caption = None, 'Your progress in this lab (the grader runs every check itself)'
    try:
        hub = standing()
    except HandInError as error:
        hub, caption = None, f'{caption}; {error}'
    if hub is not None:
        notes = {status.notebook: due_line(status) for status in hub.notebooks}
        released = [status.notebook for status in hub.notebooks if status.feedback]
        if released:
            pages = f'{len(released)} page{"" if len(released) == 1 else "s"}'
            link = (f'Your feedback ({pages}, one per notebook)', hub.feedback_url)
    graded_parts.show_table(graded_parts.rows(all_parts, states, notes), caption, link)


def _check_again(all_parts: list[graded_parts.Part]) -> None:
    """Run again the quick checks of the learner's files (:func:`progress`'s ``check``)."""
    from . import base
    calls = {}
    for part in all_parts:
        if part.check in _MODULE_OF and part.check not in NOT_QUICK:
            try:
                calls[part] = getattr(sys.modules[__name__], part.check)
            except ImportError:  # a lesson whose library this Python lacks (rosbags)
                continue
    quick = [part for part in calls if part.check in base.JUDGED]
    with working.shown('progress(check=True)') as work:
        for index, part in enumerate(quick, start=1):
            work.say(f'{part.number} · {part.label} ({index} of {len(quick)})')
            with contextlib.redirect_stdout(io.StringIO()):
                try:
                    calls[part]()
                except (CheckFailed, Ros2nbError):  # its line is kept with its outcome
                    pass


__all__ = ['CheckFailed', *sorted(_MODULE_OF), 'progress']
