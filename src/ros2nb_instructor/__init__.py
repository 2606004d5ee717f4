"""The instructor's side of the course: grading a class, authoring the notebooks, the hub.

Runs on the instructor's host (as root while grading), never in a learner's kernel.
``grading`` runs every learner's notebook in a sandbox, has ros2nb's judge decide in a
second one, and has nbgrader score what the judge decided; it reads back only what it
asked for, after the sandbox ended, and trusts nothing else a sandbox wrote or said.
``authoring`` makes the learner notebooks from the solutions; ``hub`` starts a learner's
server on the class's JupyterHub and collects their notebooks.  Console commands:
``ros2nb-grade``, ``ros2nb-learner-notebooks``, ``ros2nb-solutions``,
``ros2nb-hub-singleuser``, ``ros2nb-hub-collect`` (pyproject.toml).
"""

import sys

# Every tool here reads notebooks with nbformat, which imports jsonschema, which imports
# rfc3987_syntax if it can: that package builds a parser for IRIs at import, 2.5 CPU-s in
# each process (ros2nb-grade, its sandboxed runners, the hub's learner servers) for a format
# no notebook uses.  Marked absent, jsonschema goes without it, as it does wherever the
# package is not installed.  Programs of others the tools start (nbgrader, the lab's server)
# import this package first (``programs``).  The pip route pins jsonschema below 4.25
# (environment/requirements.txt), which does not install the package at all; the mark stays
# for the other routes (RoboStack), where jsonschema is not pinned.
sys.modules.setdefault('rfc3987_syntax', None)  # its absence is an ImportError jsonschema expects
