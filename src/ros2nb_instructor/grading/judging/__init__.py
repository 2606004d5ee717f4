"""One learner graded: each notebook run in its sandbox, judged in another, readied for nbgrader.

Runs on the instructor's host (or a Dask worker, :mod:`ros2nb_instructor.grading.cluster`),
as root while grading.  A notebook runs in a sandbox through the runner
(:mod:`ros2nb_instructor.grading.sandboxed.runner`); ros2nb's judge decides every graded cell
in a sandbox of its own; the notebook nbgrader scores is built from the judge's outcomes.
What grading makes of a learner is one frozen value, :class:`.learners.Graded`.

Trusts the judge's lines and the runner's status file only as data, each field checked as it
is read (one that does not fit is a note for that notebook); never the learner's kernel,
whose outputs count for nothing.  One learner's failure is one learner's note.
"""
