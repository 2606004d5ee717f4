"""What the learner calls in a notebook to run ROS: the verbs, and the kernel's additions.

Runs in the learner's kernel, which runs their code and trusts nothing.  ``verbs``:
``start``, ``add``, ``stop``, ``spin``, ``shutdown`` on the kernel's one runtime
(:mod:`ros2nb.runtime`); ``ipython``: ``%%part``, one-line errors and log lines in their
cell, through IPython's own machinery.
"""

from .ipython import install
from .verbs import add, shutdown, spin, start, stop

__all__ = ['add', 'install', 'shutdown', 'spin', 'start', 'stop']
