"""The only code of the instructor's side that runs inside a learner's sandbox: the notebook runner.

It runs as the sandbox's user beside the learner's kernel, so it is the learner's to
tamper with: the grader reads back only the two files it asked for, and trusts no more.
"""
