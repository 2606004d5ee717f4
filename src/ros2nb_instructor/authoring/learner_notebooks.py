"""``ros2nb-learner-notebooks``: the learner notebooks in notebooks/, made from solutions/ \
by nbgrader.

solutions/ is the single source.  ``nbgrader generate_assignment`` replaces every
``### BEGIN SOLUTION`` ... ``### END SOLUTION`` region with a placeholder, removes hidden
tests and clears all outputs.  Never edit notebooks/ by hand: run ``make learner-notebooks``.

Usage: ros2nb-learner-notebooks [--check] [--out DIR]
  --check  exit 1 (naming the notebooks) if notebooks/ differs from freshly generated ones.
"""

from __future__ import annotations

import argparse
import filecmp
import shutil
import sys
from pathlib import Path
from typing import Optional

from ..grading.scores.nbgrader_course import kept_course
from ..paths import ASSIGNMENT, NOTEBOOKS, ROOT


def generate(out: Path) -> list[Path]:
    """Write learner versions of every solutions/*.ipynb into ``out``; return their paths.

    They are the release of the nbgrader course of the current solutions, made once per
    version of the solutions
    (:func:`~ros2nb_instructor.grading.scores.nbgrader_course.kept_course`): the notebooks a
    grading hands out are these very files.

    :raises SystemExit: when nbgrader's ``generate_assignment`` failed.
    """
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for notebook in sorted((kept_course() / 'release' / ASSIGNMENT).glob('*.ipynb')):
        shutil.copy2(notebook, out / notebook.name)
        written.append(out / notebook.name)
    return written


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--check', action='store_true')
    parser.add_argument('--out', type=Path, default=NOTEBOOKS)
    args = parser.parse_args(argv)
    if not args.check:
        for path in generate(args.out):
            print(f'wrote {path.relative_to(ROOT) if ROOT in path.parents else path}')
        return 0
    release = kept_course() / 'release' / ASSIGNMENT
    fresh = {p.name for p in release.glob('*.ipynb')}
    shipped = {p.name for p in NOTEBOOKS.glob('*.ipynb')}
    stale = sorted(name for name in fresh & shipped
                   if not filecmp.cmp(release / name, NOTEBOOKS / name, shallow=False))
    problems = stale + sorted(fresh ^ shipped)
    if problems:
        print('notebooks/ is out of sync with solutions/ for: ' + ', '.join(problems)
              + '. Run `make learner-notebooks` and commit the result.')
        return 1
    print('notebooks/ is in sync with solutions/.')
    return 0


if __name__ == '__main__':
    sys.exit(main())
