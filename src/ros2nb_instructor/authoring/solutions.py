"""``ros2nb-solutions``: run solutions/*.ipynb in place, in order, so their stored
outputs are fresh.

The notebooks run as nbval runs them in ``make test``: one kernel each, in order, sharing
one temporary workspace (``ros2nb-test-*``, which tests/sanitize.cfg masks), each kernel
on a ROS domain of its own.  Then ``make learner-notebooks`` regenerates notebooks/.

Usage: ros2nb-solutions [NOTEBOOK ...]   (default: every solution notebook; ``make solutions``)
"""

from __future__ import annotations

import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import Optional

import nbformat
from nbclient import NotebookClient
from ros2nb.terminal.workspace import WORKSPACE_NAME

from ..paths import ROOT, SOLUTIONS

#: Seconds one cell may take (an hour of simulated time and the judge's checks included).
CELL_TIMEOUT_S = 600


def execute(path: Path, workspace: Path) -> None:
    """Execute one notebook in place; cells tagged ``raises-exception`` may fail."""
    nb = nbformat.read(path, as_version=4)
    env = {k: v for k, v in os.environ.items() if k != 'ROS_DOMAIN_ID'}
    env['ROS2NB_WORKSPACE'] = str(workspace)
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
    nbformat.write(nb, path)
    print(f'executed {path.relative_to(ROOT)}')


def main(argv: Optional[list[str]] = None) -> int:
    """Execute the given solution notebooks (default all), in order, in place."""
    argv = sys.argv[1:] if argv is None else argv
    paths = [Path(a).resolve() for a in argv] or sorted(SOLUTIONS.glob('*.ipynb'))
    scratch = Path(tempfile.mkdtemp(prefix='ros2nb-test-'))
    try:
        for path in paths:
            execute(path, scratch / WORKSPACE_NAME)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
