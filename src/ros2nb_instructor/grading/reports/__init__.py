"""What the grader writes for people to read: each learner's feedback pages, the class's report.

Runs on the instructor's host, after the judge decided and nbgrader scored.  Every page is
made from a jinja2 template in ``templates/`` with autoescape on, sanitised and served
under a Content-Security-Policy that forbids scripts and remote loads.

Trusts no text a learner wrote: their code, names and outputs reach a page only as escaped
text; the numbers on it are the grader's (the judge's outcomes, nbgrader's scores).
"""
