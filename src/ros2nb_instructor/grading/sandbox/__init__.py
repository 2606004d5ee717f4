"""Running untrusted code (a learner's notebook, a judge and its subjects) in a sandbox.

Runs on the instructor's host, as root while grading: bubblewrap namespaces, cgroups and
rlimits for each sandbox, its wall and CPU time watched until it ends, and the learner's
folders it may write (size-capped tmpfs, a workspace snapshot per notebook).

Trusts nothing a sandbox wrote, said or linked, except what the host asked for, read after
the sandbox ended, by file descriptor from folders of its own and never through a link
(:mod:`.paths_of_learners`).  It knows nothing of notebooks or judges: what runs inside is
its callers' (:mod:`ros2nb_instructor.grading.judging`).
"""
