"""The judge's inputs drawn for one run, and the one owner of the seed they come from.

Part of :mod:`ros2nb.checks`; runs in the judge (and in the kernel for the ``@direct``
checks, which have no judge).  Every check that feeds the learner's code values keeps its
boundary cases and adds values drawn here, so an answer that holds a table of the course's
inputs (right for exactly those, wrong in general) loses what its honest-wrong twin loses.

The seed is decided here only: a check run in the lab draws a fresh one in the judge's own
process, after its subjects' fork server started (so no subject holds a copy), and takes
none from the kernel that asked for the check (the learner's code runs there); a grading run
has one seed for the class, drawn by the grader (:func:`new_seed`), kept in
``grading/notes.json`` and given to each notebook's judge on its command line
(``python -m ros2nb.judge grade SOURCE SUBMISSION --seed N``), where the subjects, each in a
sandbox with its own PID namespace, cannot read it.  Each check's inputs come from the seed
and the check's own purpose (:func:`chooser`), so a grade reproduces with the same seed
whichever checks ran before it.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs in a judge).
"""

from __future__ import annotations

import random
import secrets
from typing import Any, Optional

from .. import course
from ..errors import Ros2nbError

#: The command-line option that gives a grading run's seed to the judge and to ros2nb-grade.
SEED_OPTION = '--seed'
#: Bits of a new seed: enough that no table of seeds can be learnt.
SEED_BITS = 63
#: Where notebook 03's clamp probes start the walk (°C): just inside the limits; before
#: them, a probe drawn for each run starts this far inside each limit (°C, two decimals).
CLAMP_PROBES_C = (course.MAX_TEMPERATURE_C - 0.05, course.MIN_TEMPERATURE_C + 0.05)
DRAWN_PROBE_INSIDE_C = (0.06, 0.3)
#: How far past a limit a walk without a clamp must go for its run to probe the clamp (°C):
#: more than a Float32 can blur.
LEAVES_BY_C = 0.01


def new_seed() -> int:
    """A fresh seed from the operating system's randomness (a lab check, a grading run)."""
    return secrets.randbits(SEED_BITS)


def parse_seed(text: str) -> int:
    """The seed written on a command line (``--seed N``), a whole number >= 0.

    :raises Ros2nbError: with one line saying what to write instead.
    """
    try:
        seed = int(text)
    except ValueError:
        seed = -1
    if seed < 0:
        raise Ros2nbError(f'{SEED_OPTION} {text!r} is not a seed: give a whole number of 0 or '
                          'more, e.g. the "seed" of an earlier grading\'s notes.json.')
    return seed


def chooser(judge: Optional[Any], purpose: str) -> random.Random:
    """The random source of one check's drawn inputs.

    :param judge: the judge running the check (its ``seed``); None in the kernel: a fresh
        source every time.
    :param purpose: what the values are for, unique among the checks, e.g.
        ``'04 monitor readings'``: the same seed and purpose give the same values.
    """
    seed = getattr(judge, 'seed', None)
    if seed is None:
        return random.Random(new_seed())
    return random.Random(f'{seed}/{purpose}')


def walk_leaves(seed: int, start_c: float, steps: int) -> bool:
    """Whether a walk without a clamp, as the course's callback draws it (one
    ``random.uniform(-MAX_STEP_C, MAX_STEP_C)`` per reading after ``random.seed(seed)``, the
    subject's seeding), goes past a limit within ``steps`` readings from ``start_c``."""
    walk, temperature = random.Random(seed), start_c
    for _ in range(steps):
        temperature += walk.uniform(-course.MAX_STEP_C, course.MAX_STEP_C)
        if not (course.MIN_TEMPERATURE_C - LEAVES_BY_C <= temperature
                <= course.MAX_TEMPERATURE_C + LEAVES_BY_C):
            return True
    return False


def sensor_seed(judge: Optional[Any], purpose: str, start_c: Optional[float] = None,
                seconds: float = 0) -> int:
    """A seed of ``random`` for a run of the learner's sensor (notebook 03), drawn for this
    run; with ``start_c``, one whose walk without a clamp leaves the limits within
    ``seconds`` (simulated), so that the run shows whether the callback clamps."""
    source = chooser(judge, purpose)
    readings = round(seconds / course.PUBLISH_PERIOD_S) - 1  # the run's first may come late
    while True:
        seed = source.randrange(2 ** 31)
        if start_c is None or walk_leaves(seed, start_c, readings):
            return seed


def clamp_probes_c(judge: Optional[Any]) -> list[float]:
    """Where each of notebook 03's clamp probes starts (°C): one drawn inside each limit,
    then :data:`CLAMP_PROBES_C`."""
    source = chooser(judge, '03 clamp probes')
    drawn = [round(course.MAX_TEMPERATURE_C - source.uniform(*DRAWN_PROBE_INSIDE_C), 2),
             round(course.MIN_TEMPERATURE_C + source.uniform(*DRAWN_PROBE_INSIDE_C), 2)]
    return [*drawn, *CLAMP_PROBES_C]
