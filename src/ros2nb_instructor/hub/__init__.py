"""The classroom server: one learner's server on the course's JupyterHub, and collecting their work.

Runs on the classroom server.  ``singleuser`` (``ros2nb-hub-singleuser``) runs as the
learner; ``collect`` (``ros2nb-hub-collect``) as root or an instructor.
"""
