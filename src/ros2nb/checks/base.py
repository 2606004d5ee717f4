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

import functools
import inspect
from typing import Any, Callable

from ..errors import CheckFailed, Ros2nbError
from ..explain.exceptions import describe_error
from ..judge_interface import learner_error
from ..subject_replies import LearnerError
from .dispatch import ask_judge

#: A check's body: ``body(judge, *learner_things) -> the passed sentence``.
Body = Callable[..., str]


#: The body of every check of the lessons loaded so far, by the check's name.
CHECKS: dict[str, Body] = {}


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


def judged(body: Body) -> Callable[[], None]:
    """Register ``body(judge)`` as a check that runs only in a judge; return the notebook's
    function, which asks a judge process to run it by name."""
    def call() -> None:
        ask_judge(body.__name__)

    return _register(body, call)


def direct(body: Body) -> Callable[..., None]:
    """Register ``body(judge, *args)`` as a check that runs where it is called; return the
    notebook's function, which runs it in the kernel (no judge) and prints its line."""
    def call(*args: Any, **kwargs: Any) -> None:
        passed(body(None, *args, **kwargs))

    return _register(body, call)


def passed(message: str) -> None:
    """Print the line a passing check shows."""
    print(f'Check passed: {message}')


def call_learner(function: Callable[..., Any], *args: Any) -> Any:
    """Call the learner's function in the kernel: NotImplementedError becomes one line, and
    any other error the learner's code raised a failure through their own frames only (or
    the one line of a known mistake), never a traceback through the check, rclpy or rosbags.

    :raises CheckFailed: (or :class:`LearnerCodeError`) for an error in the learner's code.
    """
    try:
        return function(*args)
    except NotImplementedError:
        raise CheckFailed(f'{function.__name__}() still raises NotImplementedError: replace '
                          '"raise NotImplementedError()" with your code and run its cell '
                          'again.') from None
    except (CheckFailed, Ros2nbError):  # ros2nb's own line, raised in their code's call
        raise
    except Exception as error:  # their frames only, or the one line of a known mistake
        raise learner_error(f'{function.__name__}()', LearnerError(**describe_error(error))
                            ) from None
