"""What every check is made of: its registration, its one line, and a call of the learner's.

Part of :mod:`ros2nb.checks`.  A check's body takes the judge that runs it
(:class:`~ros2nb.judge_interface.Judge`, None in the kernel) and the learner's things, and
returns the ``Check passed`` sentence or raises :class:`CheckFailed` with one line.  One of
two decorators registers it under its own name (:data:`CHECKS`) and makes the function the
notebook calls:

- :func:`judged`: the body runs only in a judge; the notebook's call asks a judge process
  to run it (:func:`~ros2nb.checks.dispatch.ask_judge`) and shows its verdict;
- :func:`direct`: the body runs where it is called; in the kernel on the learner's objects
  (no judge), in the judge on their answer cells (:class:`~ros2nb.judge_interface.AnswerRef`).

The judge looks a body up by name (:func:`ros2nb.checks.run_check`) and runs it with its
session, once: no check is called twice or dispatched again.
"""

from __future__ import annotations

import contextlib
import functools
import inspect
import io
import os
import sys
import traceback
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Concatenate, Iterator, Mapping, Optional, \
    ParamSpec, Sequence, cast

from .. import course, graded_parts, working
from ..errors import CheckFailed, NotDecided, Ros2nbError
from ..explain.exceptions import describe_error
from ..judge_interface import learner_error
from ..subject_replies import LearnerError
from ..terminal.workspace import current_workspace
from . import evidence
from .dispatch import INTERRUPTED, ask_judge

if TYPE_CHECKING:
    from ..judge_interface import Judge

#: A check's body, as the judge looks it up by name: ``body(judge, *learner_things) -> the
#: passed sentence`` (each decorator below types its own kind exactly).
Body = Callable[..., str]
#: The learner's things a direct check's body takes after the judge: the notebook's
#: function takes the same.
P = ParamSpec('P')


#: The body of every check of the lessons loaded so far, by the check's name.
CHECKS: dict[str, Body] = {}
#: The notebook of the direct check running in the kernel (for the line of an unfinished file).
_running: list[int] = []
#: The names of the checks that run in a judge (loaded so far).
JUDGED: set[str] = set()


@contextlib.contextmanager
def _progress_kept(check: str, notebook: int = 0, args: Sequence[Any] = ()) -> Iterator[None]:
    """In the kernel: keep the check's outcome in the learner's progress
    (:mod:`ros2nb.graded_parts`), with what it ran on (:mod:`.evidence`: the ``notebook``'s
    files, the learner's ``args``), and end with its line there.  A check that could not
    run, or was interrupted, keeps nothing; while grading nothing is kept."""
    if os.environ.get(course.GRADING_ENV):
        yield
        return
    out = io.StringIO()
    try:
        with contextlib.redirect_stdout(_Tee(out)):
            yield
    except CheckFailed as failure:
        if not str(failure).startswith(INTERRUPTED):
            _kept(check, False, str(failure), evidence.taken(notebook, args))
        raise
    lines = out.getvalue().strip().splitlines()
    _kept(check, True, lines[-1] if lines else '', evidence.taken(notebook, args))


def _kept(check: str, ok: bool, line: str, ran_on: Mapping[str, Any]) -> None:
    graded_parts.remember(check, ok, line, evidence=ran_on)
    try:
        said = graded_parts.outcome_line(check, ok, graded_parts.parts())
    except OSError:  # the course's notebooks are not beside ros2nb: no table to point at
        said = None
    if said and (ok or not _after_this_cell(said)):
        print(said)


def _after_this_cell(line: str) -> bool:
    """Print ``line`` once the running cell has ended (IPython's ``post_run_cell`` event), so
    that a failed check's own line, shown when its error leaves the cell, is the first the
    learner reads and the progress line follows it; False outside IPython (print it now)."""
    loaded = sys.modules.get('IPython')
    shell = loaded.get_ipython() if loaded is not None else None
    if shell is None:
        return False

    def once(_result: object = None) -> None:
        shell.events.unregister('post_run_cell', once)
        print(line)

    shell.events.register('post_run_cell', once)
    return True


class _Tee(io.TextIOBase):
    """Writes to the current stdout and keeps a copy (the check's passed line)."""

    def __init__(self, copy: io.StringIO) -> None:
        self._copy, self._out = copy, sys.stdout

    def write(self, text: str) -> int:
        self._copy.write(text)
        return self._out.write(text)

    def flush(self) -> None:
        self._out.flush()


def _register(body: Body, call: Callable[..., None]) -> Callable[..., None]:
    name = body.__name__
    if name in CHECKS:
        raise RuntimeError(f'two checks are named {name}')  # a mistake of the course's
    CHECKS[name] = body
    functools.update_wrapper(call, body)
    del call.__wrapped__  # type: ignore[attr-defined]  # update_wrapper set it; no type has it
    # What the notebook calls: the body's parameters without the judge, and no return value.
    parameters = list(inspect.signature(body).parameters.values())[1:]
    call.__signature__ = inspect.Signature(  # type: ignore[attr-defined]  # inspect reads it
        parameters, return_annotation=None)
    call.__annotations__ = {**{name: hint for name, hint in body.__annotations__.items()
                               if name not in ('judge', 'return')}, 'return': 'None'}
    return call


def judged(body: Callable[['Judge'], str]) -> Callable[[], None]:
    """Register ``body(judge)`` as a check that runs only in a judge; return the notebook's
    function, which asks a judge process to run it by name."""
    notebook = int(body.__module__.rpartition('lesson')[2][:2] or 0)

    def call() -> None:
        with _progress_kept(body.__name__, notebook):
            ask_judge(body.__name__)

    JUDGED.add(body.__name__)

    return _register(body, call)


def direct(body: Callable[Concatenate[Optional['Judge'], P], str]) -> Callable[P, None]:
    """Register ``body(judge, *args)`` as a check that runs where it is called; return the
    notebook's function, which runs it in the kernel (no judge) and prints its line."""
    notebook = int(body.__module__.rpartition('lesson')[2][:2] or 0)

    def call(*args: P.args, **kwargs: P.kwargs) -> None:
        _running.append(notebook)
        try:
            with _progress_kept(body.__name__, notebook, args):
                with working.shown(body.__name__):
                    message = decided(lambda: body(None, *args, **kwargs), lambda: None)
                passed(message)
        finally:
            _running.pop()

    return cast(Callable[P, None], _register(body, call))


#: Times a check runs before it says it could not decide (:class:`~ros2nb.errors.NotDecided`):
#: what it waited for from the grader's own side came in none of them.
NOT_DECIDED_TRIES = 3
#: The line of a check that could not decide, after its last try.
NOT_DECIDED = ('Not decided, nothing is wrong with your code yet: {reason} ({tries} tries, on a '
               'machine too busy to bring it). Run this check again; if it says this again, '
               'tell your instructor.')


def decided(run_once: Callable[[], str], between: Callable[[], None]) -> str:
    """A check's passed line: ``run_once()``, run again (after ``between()``) while it could
    not decide, :data:`NOT_DECIDED_TRIES` times in all.

    :raises NotDecided: when no try could decide (:data:`NOT_DECIDED`, with the last reason).
    """
    for tries in range(1, NOT_DECIDED_TRIES + 1):
        try:
            return run_once()
        except NotDecided as why:
            if tries == NOT_DECIDED_TRIES:
                raise NotDecided(NOT_DECIDED.format(reason=str(why).rstrip('.'),
                                                    tries=tries)) from None
            between()
    raise AssertionError('unreachable')  # pragma: no cover - the loop returns or raises


def passed(message: str) -> None:
    """Print the line a passing check shows."""
    print(f'Check passed: {message}')


def call_learner(function: Callable[..., Any], *args: Any, label: str = '') -> Any:
    """Call the learner's function in the kernel: NotImplementedError becomes one line, and
    any other error the learner's code raised a failure through their own frames only (or
    the one line of a known mistake), never a traceback through the check, rclpy or rosbags.

    :param label: the call as the line names it; :func:`called_as` when empty.
    :raises CheckFailed: (or :class:`LearnerCodeError`) for an error in the learner's code.
    """
    try:
        return function(*args)
    except (CheckFailed, Ros2nbError):  # ros2nb's own line, raised in their code's call
        raise
    except Exception as error:
        _unfinished_file(error)  # raised in a node file an earlier notebook left unfinished
        if isinstance(error, NotImplementedError):
            raise CheckFailed(f'{function.__name__}() still raises NotImplementedError: '
                              'replace "raise NotImplementedError()" with your code and run its '
                              'cell again.') from None
        # their frames only, or the one line of a known mistake
        raise learner_error(label or called_as(function),
                            LearnerError(**describe_error(error))) from None


def called_as(function: Callable[..., Any]) -> str:
    """``NAME(PARAMETERS)``: a learner's function as a check's line names its call
    (``package_dependencies(package_xml)``), in the kernel as from the grader."""
    try:
        names = ', '.join(inspect.signature(function).parameters)
    except (TypeError, ValueError):
        names = ''
    return f'{getattr(function, "__name__", "the function")}({names})'


#: What a part an earlier notebook left unwritten raises where it is used.
UNWRITTEN_SIGNS = ('AttributeError', 'NameError', 'NotImplementedError',
                   'ParameterNotDeclaredException')


def _unfinished_file(error: BaseException) -> None:
    """Raise the one line of a node file an earlier notebook left unfinished
    (:func:`ros2nb.course.unfinished_line`) when ``error`` came through it and is what an
    unwritten part raises (:data:`UNWRITTEN_SIGNS`)."""
    if type(error).__name__ not in UNWRITTEN_SIGNS:
        return
    workspace = current_workspace().resolve()
    files = {Path(frame.f_code.co_filename).resolve() for frame, _line in
             traceback.walk_tb(error.__traceback__)}
    for relative in course.WRITTEN_IN:
        if workspace / relative in files:
            line = course.unfinished_line(workspace, relative, _running[-1] if _running else 10)
            if line:
                raise CheckFailed(line) from None
