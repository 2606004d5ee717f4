"""Grades as files for others' software: a learning platform's import, and every CSV written.

Runs on the instructor's host (``make export``, or ``make grade ... EXPORT=canvas``).  The
marks come from nbgrader's gradebook and the grader's own ``learners.json``, never from a
learner's notebook; nothing is graded again.

Trusts the gradebook and the instructor's roster (read by
:mod:`ros2nb_instructor.grading.intake`); every cell it writes is made inert for a spreadsheet
(:mod:`.spreadsheets`), since a learner's folder name reaches it.
"""
