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
