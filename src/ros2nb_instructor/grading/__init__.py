"""Grading a class: every notebook run in a sandbox, judged in another, scored by nbgrader.

Runs on the instructor's host (as root, when root starts it).  In the order a notebook
goes through: ``submissions`` (who handed in what) -> ``scratch`` (the learner's folders)
-> ``runs`` (the notebook in its ``sandbox``, through ``sandboxed.runner``) -> ``judging``
(ros2nb's judge in a sandbox) -> ``notebooks`` (the notebook nbgrader scores) ->
``gradebook`` (nbgrader: scores, feedback, grades.csv).  ``learners`` puts one learner
through it, ``cli`` the class (``ros2nb-grade``).
"""
