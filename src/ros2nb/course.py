"""Catch up on earlier notebooks, so any notebook can be run on its own.

Introduced in ``01-create-a-workspace.ipynb``.

Each step creates only what is missing and never changes a file you wrote; the code it
writes is the course's reference code (the tutorial's, with its mistakes fixed), kept in
``ros2nb/reference/``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from .pkg_create import pkg_create
from .workspace import create_workspace, default_workspace, shown, write_file

PACKAGE = 'sensor_simulator'
DEPENDENCIES = ('rclpy', 'std_msgs')
#: Maintainer used in the notebooks, so package.xml is the same on every machine.
MAINTAINER_NAME = 'learner'
MAINTAINER_EMAIL = 'learner@example.com'
#: Notebook number -> what must exist before it starts.
STEPS = {1: (), 2: ('workspace',), 3: ('workspace', 'package'),
         4: ('workspace', 'package', 'publisher'),
         5: ('workspace', 'package', 'publisher', 'subscriber')}


def reference_source(name: str) -> str:
    """Return a reference file's text, e.g. ``'temperature_publisher.py'``."""
    return resources.files('ros2nb.reference').joinpath(name).read_text()


def package_path(workspace: Path) -> Path:
    """Return ``<workspace>/src/sensor_simulator``."""
    return workspace / 'src' / PACKAGE


def catch_up(notebook: int) -> Path:
    """Create whatever earlier notebooks would have made, if it is missing.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param notebook: the number of the notebook about to run (1-5).
    :return: the workspace path.
    :raises ValueError: for a notebook number without steps.
    """
    if notebook not in STEPS:
        raise ValueError(f'notebook must be one of {sorted(STEPS)} (got {notebook}).')
    steps = STEPS[notebook]
    done = []
    if 'workspace' in steps and not default_workspace().is_dir():
        done.append(shown(default_workspace()))
    ws = create_workspace()  # also re-creates any missing sub-folder, like mkdir -p
    package = package_path(ws)
    if 'package' in steps and not package.exists():
        pkg_create(PACKAGE, destination=ws / 'src', dependencies=list(DEPENDENCIES),
                   maintainer_name=MAINTAINER_NAME, maintainer_email=MAINTAINER_EMAIL)
        done.append(shown(package))
    for step in ('publisher', 'subscriber'):
        target = package / PACKAGE / f'temperature_{step}.py'
        if step in steps and not target.exists():
            write_file(target, reference_source(target.name))
            target.chmod(0o755)
            done.append(shown(target))
    print('Caught up: created ' + ', '.join(done) if done else
          f'Nothing to catch up: {shown(ws)} has what notebook {notebook:02d} needs.')
    return ws
