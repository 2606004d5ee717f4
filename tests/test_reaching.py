"""What the judge makes of what the subjects' audit hooks saw, and of package files that no
``%%part`` cell wrote as they are (``ros2nb.judge.reaching``, ``ros2nb.judge.written``).

- A check fails with one line when a subject it used saw the learner's code do what can only
  serve cheating, whenever that was (a file's import runs before the check that loaded it);
  an event in a subject the check did not use, before it began, does not fail it (a later
  check that starts a subject afresh is graded on that subject's code).
- Only the hook's own lines count, and a kind the judge does not know is dropped.
- A notebook whose added cell writes the course's code into the learner's file has that
  file graded as its ``%%part`` cells write it; the course's solutions and every honest and
  wrong learner of the corpora have none rewritten.
"""

from __future__ import annotations

import pytest

from corpora import NOTEBOOKS, Learner, every_learner, learner_workspace
from ros2nb.errors import CheckFailed
from ros2nb.judge.reaching import Reached, Reaching, parse_seen
from ros2nb.judge.written import as_written


class Subject:
    """What Reaching reads of a subject: what its hook wrote."""

    def __init__(self) -> None:
        self.seen: list[Reached] = []

    def take_seen(self) -> list[Reached]:
        return self.seen


FRAMES = Reached('frames', 'sys._getframe', 'learner.py line 3')
PROCESS = Reached('processes', 'subprocess.Popen', 'learner.py line 4')


def test_a_check_fails_for_what_a_subject_it_used_saw_whenever():
    loaded, other = Subject(), Subject()
    running = {('file', 'a.py'): loaded, ('file', 'b.py'): other}
    reaching = Reaching(running)
    loaded.seen.append(FRAMES)  # at import, before any check
    reaching.forget()
    reaching.use(other)
    reaching.raise_any()  # the check used only the other subject: nothing against it
    reaching.forget()
    reaching.use(loaded)
    with pytest.raises(CheckFailed, match=r'^Your code reads stack frames.*sys\._getframe, '
                                          r'learner\.py line 3.*report\.$'):
        reaching.raise_any()


def test_an_event_during_a_check_fails_it_and_one_that_only_shows_never_does():
    subject = Subject()
    reaching = Reaching({('file', 'a.py'): subject})
    reaching.forget()
    subject.seen.append(PROCESS)
    reaching.raise_any()  # starting a process is shown, never failed
    subject.seen.append(FRAMES)
    with pytest.raises(CheckFailed):
        reaching.raise_any()
    assert reaching.flags() == [
        'learner.py line 4: at run time, starts another process (subprocess.Popen)',
        "learner.py line 3: at run time, reads stack frames, the course's among them "
        '(sys._getframe)']


@pytest.mark.parametrize('line, read', [
    (b'SEEN\tframes\tsys._getframe\t/ws/learner.py line 3', FRAMES._replace(
        where='/ws/learner.py line 3')),
    (b'SEEN\tunknown\tx\ty', None),
    (b'SEEN\tframes\tonly three', None),
    (b'{"t": 1}', None),
])
def test_only_the_hooks_own_lines_count(line, read):
    assert parse_seen(line) == read


#: A cell added after 04's callback: it writes the course's rule into the file's part 4.
WRITES_THE_RULE = '''\
ros2nb.write_part(SUBSCRIBER, 4, "    def temperature_callback(self, msg):\\n"
                  "        self.get_logger().info('the course\\\\'s code')\\n")
'''
#: The same, before the callback's cell, which still holds the placeholder (write_part keeps
#: the working version it finds).
PLACEHOLDER = '''
    def temperature_callback(self, msg):
        raise NotImplementedError()
'''


@pytest.mark.parametrize('learner', [
    Learner('a cell writes the part after the answer', '04',
            {'monitor-callback': PLACEHOLDER.replace('raise NotImplementedError()', 'pass')},
            added=(('monitor-callback', WRITES_THE_RULE),)),
    Learner('a cell writes the part before a placeholder', '04',
            {'monitor-constructor': [('### END SOLUTION', '### END SOLUTION')],
             'monitor-callback': PLACEHOLDER},
            added=(('monitor-constructor', WRITES_THE_RULE),)),
    Learner('a cell writes the whole file', '06', {}, added=(('fan-main', '''\
import pathlib
path = ros2nb.current_workspace() / FAN
path.write_text(path.read_text() + '\\n# changed\\n')
'''),)),
], ids=lambda learner: learner.name)
def test_a_file_another_cell_wrote_is_graded_as_the_cells_write_it(learner, tmp_path):
    with learner_workspace(learner, tmp_path) as (ws, nb):
        rewritten = as_written(nb, ws)
        (relative, text), = rewritten.items()
        assert text != (ws / relative).read_text()
    assert "the course\\'s code" not in text and '# changed' not in text, text


def test_no_honest_wrong_or_course_notebook_has_a_file_rewritten(tmp_path):
    learners = [learner for learner in every_learner().values() if not learner.added]
    learners += [Learner(f'solution {n}', n, {}) for n in sorted(NOTEBOOKS) if n >= '03']
    for index, learner in enumerate(learners):
        with learner_workspace(learner, tmp_path / str(index)) as (ws, nb):
            assert as_written(nb, ws) == {}, learner.name
