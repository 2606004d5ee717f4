"""A class graded on a Dask cluster: a learner a task (``make grade SCHEDULER=tcp://host:8786``).

Runs in two places: :mod:`.client` on the instructor's host (it hands out the learners and
files what comes back), :mod:`.worker` on each Dask worker, where the course is installed,
as root while grading, like the grader on one machine.

The host trusts a worker it checked before any learner ran there (the same course version,
a sandbox that works: the instructor's machines); what a worker sends back is one frozen
value per learner (:class:`.worker.FromWorker`), and a learner whose task fails is one
learner's note.  A worker trusts nothing of a learner's,
exactly as :mod:`ros2nb_instructor.grading.judging` does.
"""
