"""What the grader takes in, read strictly before anything is graded.

Runs on the instructor's host (and, for due dates and hand-in times, in the classroom
server's hand-in service).  Two kinds of input, trusted differently:

- what learners handed in (their folders, a platform's zip, hand-in times): trusted for
  nothing; a name that is not legal, a link, a file too large or a time that does not parse
  is refused or noted for that learner alone;
- the instructor's files for a term (``course.toml``, ``extensions.toml``, the roster) and
  the grader's own record of an earlier grading (``learners.json``): trusted as the
  instructor's word, but every field checked; a mistake is refused with one line each
  (:class:`.mistakes.Mistakes`), never guessed at.

It imports no other part of the grading.
"""
