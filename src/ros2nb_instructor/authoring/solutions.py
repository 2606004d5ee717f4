"""``ros2nb-solutions``: run solutions/*.ipynb in place, in order, so their stored
outputs are fresh.

The notebooks run as nbval runs them in ``make test``: one kernel each, in order, sharing
one temporary workspace (``ros2nb-test-*``, which tests/sanitize.cfg masks) and one record of
the checks' outcomes beside it, each kernel on a ROS domain of its own.  The displays that
long work emptied when it ended are dropped (:func:`drop_empty_displays`).  Then
``make learner-notebooks`` regenerates notebooks/.

Usage: ros2nb-solutions [NOTEBOOK ...]   (default: every solution notebook; ``make solutions``)
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from pathlib import Path
from typing import Optional

import nbformat
from nbclient import NotebookClient
from ros2nb.graded_parts import RECORD_ENV
from ros2nb.temporary import owned_folder
from ros2nb.terminal.workspace import WORKSPACE_NAME

from ..paths import ROOT, SOLUTIONS

#: Seconds one cell may take (an hour of simulated time and the judge's checks included).
CELL_TIMEOUT_S = 600


def execute(path: Path, workspace: Path) -> None:
    """Execute one notebook in place; cells tagged ``raises-exception`` may fail."""
    nb = nbformat.read(path, as_version=4)
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
    env['ROS2NB_WORKSPACE'] = str(workspace)
    env[RECORD_ENV] = str(workspace.parent / 'progress.json')  # never in solutions/
    client = NotebookClient(nb, timeout=CELL_TIMEOUT_S, kernel_name='python3',
                            resources={'metadata': {'path': str(path.parent)}},
                            allow_error_names=[], record_timing=False)
    for cell in nb.cells:  # nbclient honours the raises-exception tag itself
        cell.metadata.pop('execution', None)
    saved = dict(os.environ)
    os.environ.clear()
    os.environ.update(env)
    try:
        client.execute()
    finally:
        os.environ.clear()
        os.environ.update(saved)
    drop_empty_displays(nb)
    nbformat.write(nb, path)
    print(f'executed {path.relative_to(ROOT)}')


def drop_empty_displays(nb: nbformat.NotebookNode) -> None:
    """Drop the displays a cell's long work emptied when it ended (:mod:`ros2nb.working`):
    whether one was made depends on how long the work took, never on what it printed."""
    for cell in nb.cells:
        if cell.cell_type == 'code':
            cell.outputs = [o for o in cell.outputs
                            if not (o.output_type == 'display_data' and not o.get('data'))]


def main(argv: Optional[list[str]] = None) -> int:
    """Execute the given solution notebooks (default all), in order, in place.

    :return: 0, or 2 (with one line on stderr) for a notebook that is not in solutions/.
    """
    parser = argparse.ArgumentParser(
        prog='ros2nb-solutions',
        description='Run solutions/*.ipynb in place, in course order, so their stored outputs '
                    'are fresh; then run make learner-notebooks.')
    parser.add_argument('notebooks', nargs='*', type=Path, metavar='NOTEBOOK',
                        help='solution notebooks to run (default: all of solutions/)')
    given = parser.parse_args(argv)
    paths = sorted(p.resolve() for p in given.notebooks) or sorted(SOLUTIONS.glob('*.ipynb'))
    for path in paths:
        if path.parent != SOLUTIONS.resolve() or not path.is_file():
            parser.error(f'{path} is not a notebook of {SOLUTIONS}: name one of '
                         'solutions/*.ipynb')
    scratch = owned_folder('ros2nb-test-')
    try:
        for path in paths:
            execute(path, scratch / WORKSPACE_NAME)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0

if __name__ == '__main__':
    sys.exit(main())
