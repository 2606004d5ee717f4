"""How a subject process describes what the learner's code returned or raised, as JSON.

Part of :mod:`ros2nb.subject` (introduced in ``03-write-the-publisher.ipynb``).  A reply only
names a mistake for the judge; it never earns a point.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any


def encode(value: Any) -> Any:
    """Return a JSON-safe description of a value the learner's code returned."""
    if value is None or isinstance(value, (bool, int, str)):
        return {'type': type(value).__name__, 'value': value}
    if isinstance(value, float):
        return {'type': 'float', 'value': value if math.isfinite(value) else repr(value)}
    if isinstance(value, Path):
        return {'type': 'Path', 'value': str(value)}
    if isinstance(value, (list, tuple)):
        return {'type': type(value).__name__, 'value': [encode(v) for v in value]}
    return {'type': type(value).__name__, 'value': repr(value)[:200]}


def decode_argument(value: Any) -> Any:
    """Turn a command's argument into a Python value (``{"path": p}`` becomes a Path)."""
    if isinstance(value, dict) and set(value) == {'path'}:
        return Path(value['path'])
    return value

