"""Authoring the course: the learner notebooks from the solutions, and the solutions' outputs.

Runs on the instructor's (or a developer's) machine.  ``solutions/`` is the single source;
``learner_notebooks`` (``ros2nb-learner-notebooks``) makes ``notebooks/`` from it with
nbgrader, ``solutions`` (``ros2nb-solutions``) re-runs it so its stored outputs are fresh.
"""
