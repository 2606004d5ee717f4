"""What the judge makes of what the subjects' audit hooks saw, and of package files that no
``%%part`` cell wrote as they are (``ros2nb.judge.reaching``, ``ros2nb.judge.written``).

- What a subject's hook saw is a note for the instructor, never a verdict: no check fails or
  passes on it (the hook runs where the learner's code can read, replace or mute it).
- Every event is counted: past a kind's places shown, its total is noted; a subject that
  ended as asked without the hook's last line had its channel cut, which is a note too.
- Only the hook's own lines count, and a kind the judge does not know is dropped.
- A notebook whose added cell writes the course's code into the learner's file has that
  file graded as its ``%%part`` cells write it; the course's solutions and every honest and
  wrong learner of the corpora have none rewritten.
"""

from __future__ import annotations

import pytest

from corpora import NOTEBOOKS, Learner, every_learner, learner_workspace
from ros2nb.judge.reaching import (CHANNEL_LOST, Counted, Reached, Reaching, parse_count,
                                   parse_seen)
from ros2nb.judge.written import as_written


class Subject:
    """What Reaching reads of a subject: what its hook wrote."""

    def __init__(self) -> None:
        self.seen: list[Reached] = []
        self.seen_counts: dict[str, int] = {}
        self.channel_lost = False

    def take_seen(self) -> list[Reached]:
        return self.seen


FRAMES = Reached('frames', 'sys._getframe', 'learner.py line 3')
PROCESS = Reached('processes', 'subprocess.Popen', 'learner.py line 4')


def test_what_a_hook_saw_is_noted_never_a_verdict():
    """Reaching has nothing that fails a check: it only words notes, each once, in order."""
    subject = Subject()
    reaching = Reaching({('file', 'a.py'): subject})
    assert not hasattr(reaching, 'raise_any')
    subject.seen += [PROCESS, FRAMES, FRAMES]
    assert reaching.flags() == [
        'learner.py line 4: at run time, starts another process (subprocess.Popen)',
        "learner.py line 3: at run time, reads stack frames, the course's among them "
        '(sys._getframe)']


def test_a_flood_of_one_kind_is_counted_and_a_cut_channel_noted():
    """A subject whose code added 64 audit hooks and read frames 1000 times: both kinds
    noted with their totals; and a subject that ended as asked without the hook's last line
    (its pipe closed or redirected) gets the note that says so."""
    flooding, cut = Subject(), Subject()
    flooding.seen = [FRAMES, Reached('hooks', 'sys.addaudithook', 'learner.py line 9')]
    flooding.seen_counts = {'frames': 1000, 'hooks': 64}
    cut.channel_lost = True
    reaching = Reaching({('file', 'a.py'): flooding})
    reaching.keep(cut)
    notes = reaching.flags()
    assert "at run time, reads stack frames, the course's among them: 1000 times in all " \
        '(1 places shown)' in notes, notes
    assert 'at run time, adds an audit hook of its own: 64 times in all (1 places shown)' \
        in notes, notes
    assert notes[-1] == CHANNEL_LOST, notes


@pytest.mark.parametrize('line, read', [
    (b'SEEN\tframes\tsys._getframe\t/ws/learner.py line 3', FRAMES._replace(
        where='/ws/learner.py line 3')),
    (b'SEEN\tunknown\tx\ty', None),
    (b'SEEN\tframes\tonly three', None),
    (b'{"t": 1}', None),
])
def test_only_the_hooks_own_lines_count(line, read):
    assert parse_seen(line) == read


@pytest.mark.parametrize('line, read', [
    (b'SEEN\tcount\thooks\t128', Counted('hooks', {'hooks': 128})),
    (b'SEEN\tend\tframes=3,hooks=64,unknown=2\t', Counted('end', {'frames': 3, 'hooks': 64})),
    (b'SEEN\tcount\tunknown\t4', None),
    (b'SEEN\tframes\tsys._getframe\tx', None),
])
def test_counts_and_the_last_line_are_read(line, read):
    assert parse_count(line) == read


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
