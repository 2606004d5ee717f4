"""nbgrader's part: the course under ``grading/nbgrader``, its gradebook, scores and grades.csv.

Runs on the instructor's host.  nbgrader scores the notebooks the judging made and writes
their feedback; it executes nothing of the learners' here (its Execute step is off for the
scoring run), in a process of its own (:mod:`.scoring`).  The late penalties are the
intake's (:mod:`ros2nb_instructor.grading.intake.deadlines`), the pages the reports'.

Trusts nbgrader and the judge's outcomes as the judging decoded them; nothing a learner's
notebook holds scores a point here.
"""
