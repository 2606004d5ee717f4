"""How a subject process describes what the learner's code returned or raised.

Part of :mod:`ros2nb.subject` (introduced in ``03-write-the-publisher.ipynb``).  The
descriptions are the typed values of :mod:`ros2nb.subject_replies`; a reply only names a
mistake for the judge, it never earns a point.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..explain.exceptions import describe_error
from ..subject_replies import Encoded, LearnerError


def encode(value: Any) -> Encoded:
    """A JSON-safe description of a value the learner's code returned."""
    if value is None or isinstance(value, (bool, int, str)):
        return Encoded(type=type(value).__name__, value=value)
    if isinstance(value, float):
        return Encoded(type='float', value=value if math.isfinite(value) else repr(value))
    if isinstance(value, Path):
        return Encoded(type='Path', value=str(value))
    if isinstance(value, (list, tuple)):
        return Encoded(type=type(value).__name__, value=[encode(v) for v in value])
    return Encoded(type=type(value).__name__, value=repr(value)[:200])


def described(error: BaseException) -> LearnerError:
    """An exception the learner's code raised, as the judge reads it
    (:func:`ros2nb.explain.exceptions.describe_error`'s facts)."""
    return LearnerError(**describe_error(error))


def decode_argument(value: Any) -> Any:
    """Turn a command's argument into a Python value (``{"path": p}`` becomes a Path)."""
    if isinstance(value, dict) and set(value) == {'path'}:
        return Path(value['path'])
    return value
