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
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Optional

from ..programs import nbgrader_argv
from ..paths import ASSIGNMENT, NOTEBOOKS, ROOT, SOLUTIONS, gradebook_url


def generate(out: Path) -> list[Path]:
    """Write learner versions of every solutions/*.ipynb into ``out``; return their paths."""
    with tempfile.TemporaryDirectory(prefix='ros2nb-nbgrader-') as tmp:
        course = Path(tmp)
        source = course / 'source' / ASSIGNMENT
        source.mkdir(parents=True)
        for notebook in sorted(SOLUTIONS.glob('*.ipynb')):
            shutil.copy2(notebook, source / notebook.name)
        # nbgrader runs `alembic` by name: the venv's bin/ must come first on PATH.
        env = dict(os.environ, JUPYTER_CONFIG_DIR=str(course / 'config'),
                   JUPYTER_DATA_DIR=str(course / 'data'),
                   PATH=os.pathsep.join([str(Path(sys.executable).parent), os.environ['PATH']]))
        done = subprocess.run(
            nbgrader_argv('generate_assignment', ASSIGNMENT,
                          f'--CourseDirectory.root={course}', '--force', '--log-level=ERROR',
                          f'--CourseDirectory.db_url={gradebook_url(course)}'),
            cwd=course, env=env, capture_output=True, text=True)
        if done.returncode != 0:
            sys.exit(f'nbgrader generate_assignment failed:\n{done.stdout}{done.stderr}')
        out.mkdir(parents=True, exist_ok=True)
        written = []
        for notebook in sorted((course / 'release' / ASSIGNMENT).glob('*.ipynb')):
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
    with tempfile.TemporaryDirectory() as tmp:
        fresh = {p.name for p in generate(Path(tmp))}
        shipped = {p.name for p in NOTEBOOKS.glob('*.ipynb')}
        stale = sorted(name for name in fresh & shipped
                       if not filecmp.cmp(Path(tmp) / name, NOTEBOOKS / name, shallow=False))
        problems = stale + sorted(fresh ^ shipped)
    if problems:
        print('notebooks/ is out of sync with solutions/ for: ' + ', '.join(problems)
              + '. Run `make learner-notebooks` and commit the result.')
        return 1
    print('notebooks/ is in sync with solutions/.')
    return 0


if __name__ == '__main__':
    sys.exit(main())
