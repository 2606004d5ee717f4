"""Grading a class: every notebook run in a sandbox, judged in another, scored by nbgrader.

Runs on the instructor's host (as root, when root starts it).  One subpackage per role, in
the order a notebook goes through them, each importing only the ones before it:

- ``intake``: what the grader takes in (who handed in what, and when; a platform's zip; the
  term's files: due dates, the late policy, extensions, the roster);
- ``sandbox``: running what a learner wrote in a bubblewrap sandbox, and reading back what a
  sandbox wrote without following a link;
- ``sandboxed``: the one module that runs inside a learner's sandbox (the notebook runner);
- ``judging``: one learner's notebooks, each run in its sandbox and judged in another, made
  ready for nbgrader;
- ``reports`` (feedback pages, ``report.html``) and ``export`` (CSV for a spreadsheet or a
  learning platform): what the grader writes for people;
- ``scores``: nbgrader's course, its gradebook and scores, and ``grades.csv``;
- ``cluster``: a class on a Dask cluster, on the instructor's side and on each worker.

``cli`` (``ros2nb-grade``) grades the class through them.
"""
