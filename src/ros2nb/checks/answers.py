"""The learner's answer cells (notebooks 00-02, 09), called in a subject: what comes back.

Part of :mod:`ros2nb.checks`.  Only plain values travel back from the learner's function
(a path, a list of names, a number); anything else is known by its type and its repr.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ..errors import CheckFailed
from ..judge_interface import AnswerRef, Judge, learner_error
from ..subject_interface import Call
from ..subject_replies import Called, Encoded, Output, QosMade


def defined_verdict(reply: Called | QosMade, name: str) -> None:
    """Raise when a subject's reply says the answer cells define no ``name``.

    :raises CheckFailed: telling the learner to define it in their answer cell.
    """
    if reply.undefined:
        raise CheckFailed(f'{name} is not defined in your answer cell: define it there '
                          '(and run the cell) without renaming it.')


def answer_results(judge: Judge, ref: AnswerRef, inputs: list[list[Any]]) -> list[Output]:
    """Call the learner's function ``ref`` (from their answer cell) in a subject of ``judge``'s.

    :param inputs: one list of arguments per call.
    :return: one output per call (:func:`decoded` reads it).
    """
    subject = judge.answer_subject(ref)
    reply = subject.request(Call(name=ref.name, inputs=inputs))
    defined_verdict(reply, ref.name)
    return reply.outputs


_PLAIN = ('str', 'float', 'int', 'bool', 'NoneType')


def result_of(output: Output, label: str) -> Encoded:
    """What one call of the learner's function (``label``) returned.

    :raises CheckFailed: (or :class:`~ros2nb.errors.LearnerCodeError`) for what it raised.
    """
    if output.error is not None:
        raise learner_error(label, output.error)
    if output.result is None:
        raise CheckFailed(f'{label} gave the grader nothing it could read: run this check again.')
    return output.result


def decoded(output: Output, label: str) -> Any:
    """One output of :func:`answer_results` as a Python value; a raised error is raised."""
    result = result_of(output, label)
    if result.type == 'Path':
        return Path(str(result.value))
    if isinstance(result.value, list):
        return [item.value if item.type in _PLAIN else Opaque(item.type, str(item.value))
                for item in result.value]
    if result.type in _PLAIN:
        return result.value
    return Opaque(result.type, str(result.value))


class Opaque:
    """A value of a type the judge does not rebuild; only its type and repr travel."""

    def __init__(self, type_name: str, text: str) -> None:
        self.type_name, self.text = type_name, text

    def __repr__(self) -> str:
        return self.text


def type_name_of(value: Any) -> str:
    """The type's name of a value from :func:`decoded` (an :class:`Opaque` keeps its own)."""
    return value.type_name if isinstance(value, Opaque) else type(value).__name__

