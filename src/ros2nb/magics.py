"""IPython cell magic ``%%part FILE N``: write a source file part by part.

Introduced in ``03-write-the-publisher.ipynb``.  Load it with ``%load_ext ros2nb``.
"""

from __future__ import annotations

import shlex

from .workspace import write_part


def part(line: str, cell: str) -> None:
    """``%%part FILE N [--overwrite]``: save this cell as part N of FILE.

    :raises ValueError: if the line is not ``FILE N``.
    """
    words = shlex.split(line)
    overwrite = '--overwrite' in words
    words = [w for w in words if w != '--overwrite']
    if len(words) != 2 or not words[1].isdigit():
        raise ValueError('Usage: %%part FILE N [--overwrite], e.g. '
                         '%%part src/sensor_simulator/sensor_simulator/temperature_publisher.py 1')
    write_part(words[0], int(words[1]), cell, overwrite=overwrite)


def load_ipython_extension(ipython) -> None:
    """Register ``%%part`` (called by ``%load_ext ros2nb``)."""
    ipython.register_magic_function(part, magic_kind='cell', magic_name='part')
