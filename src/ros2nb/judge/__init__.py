"""The judge: decides whether the learner's code does what a check asks, from outside it.

Introduced in ``03-write-the-publisher.ipynb`` (every check of a node runs here).

The judge is a process of its own, started for a check cell by the kernel, and once per
notebook by the grader.  It never imports or executes the learner's code itself: that
runs in subject processes (:mod:`ros2nb.subject`), which the judge watches over ROS with a
node of its own (the graph, ``/temperature``, ``/rosout``) and asks for raw facts only.
The verdict is computed here, so nothing a notebook does to its own kernel (replacing the
checks, hooks, exceptions) changes it.  While grading, every subject also runs in a
sandbox of its own (the grader passes the sandbox command in ``ROS2NB_SUBJECT_PREFIX``)
and cannot see, signal or trace the judge.

Modules: ``observer`` (its own ROS node),
``clock`` (its simulated time), ``subjects`` (the processes that run the learner's code),
``session`` (what the checks get as their judge), ``graded_cells`` (a whole notebook's
graded cells), ``flags`` (code that reaches in, for the instructor), ``__main__`` (the
command line).  The checks depend only on the judge's small interface
(:mod:`ros2nb.judge_interface`, which the session implements), never on this package; only
``__main__`` and ``graded_cells`` reach into the checks, to run a check's body by name
(:func:`ros2nb.checks.run_check`), and ``flags`` reads the learner's text through them.  The
kernel starts the judge by name.

Command line (``python -m ros2nb.judge``):

- ``check NAME``: run the body of the check ``ros2nb.checks.NAME`` with the judge's session;
  print one JSON line.
- ``grade SOURCE.ipynb SUBMISSION.ipynb``: run every graded cell of the course's source
  notebook (hidden tests included) against the learner's submission and workspace; print
  one JSON object, ``{"results": {grade_id: result}, "flags": [...]}`` (the flags, for the
  instructor only, from :mod:`ros2nb.judge.flags`).

Both take the learner's workspace from ``ROS2NB_WORKSPACE``.
"""
