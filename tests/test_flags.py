"""The judge's flags for the instructor: code that reaches into the course or its process.

Every attack of ``corpus_attacks.py`` that reaches in (stack frames, the garbage collector's
objects, rclpy's classes patched, a ``setup.py`` that writes the executables itself) is
flagged; no honest learner, no wrong learner and no solution is.  Some of these attacks
look the same as honest code on the wire (``same_on_the_wire``): the flag is how the
instructor learns of them.  The flag reaches ``notes.json`` through the host's note of the
notebook, and changes no point.
"""

from __future__ import annotations

import concurrent.futures
import html
import json

import nbformat
import pytest

from corpora import NOTEBOOKS, Learner, every_learner, flags_of
from corpus_attacks import ATTACKS
from ros2nb.judge.flags import reaching_in
from ros2nb.outcomes import CheckOutcome
from ros2nb_instructor.grading.reports import feedback
from ros2nb_instructor.grading.judging import learners as learners_module
from ros2nb_instructor.grading.judging.judges import Verdict
from ros2nb_instructor.grading.reports.report import write_report
from ros2nb_instructor.grading.intake.submissions import Learner as ClassLearner

LEARNERS = every_learner()
SOLUTIONS = [Learner(f'solution {number}', number, {}) for number in sorted(NOTEBOOKS)
             if number >= '03']


@pytest.mark.parametrize('learner', [*LEARNERS.values(), *SOLUTIONS],
                         ids=[*LEARNERS, *(s.name for s in SOLUTIONS)])
def test_flagged_exactly_when_the_code_reaches_in(learner: Learner, tmp_path):
    flags = flags_of(learner, tmp_path)
    assert bool(flags) == learner.flagged, flags
    assert all(' line ' in flag and '\n' not in flag for flag in flags), flags


@pytest.mark.parametrize('code, found', [
    ('import sys\nframe = sys._getframe(1)', "sys._getframe (reads the caller's stack frames)"),
    ('import inspect as i\ni.stack()', 'inspect.stack'),
    ('from gc import get_objects\nget_objects()', 'gc.get_objects'),
    ('def f(tb):\n    return tb.tb_frame.f_locals', '.f_locals'),
    ("open('/proc/1/cmdline')", '/proc'),
    ('from rclpy.publisher import Publisher\nPublisher.publish = print', 'Publisher.publish'),
    ('import rclpy\nsetattr(rclpy, "spin", print)', 'an attribute of rclpy'),
    ('from ros2nb.runtime import simulated_clock',
     "ros2nb.runtime.simulated_clock (ros2nb's internals)"),
    ('import ros2nb\nros2nb.current_runtime()', 'ros2nb.current_runtime'),
    ('import ctypes', 'ctypes'),
    ("import importlib\nimportlib.import_module('ros2nb.sub' + 'ject.stand_ins')",
     'imports importlib'),
    ("__import__('ros2nb.subject.' + 'stand_ins')", 'computed name'),
    ("x = 'ros2nb.subject.' + 'stand_ins'", "names 'stand_ins' (the course's answer"),
    ('import ros2nb\nros2nb.course.monitor_status(27.0)', 'ros2nb.course.monitor_status'),
    ('from ros2nb import course as c\nc.monitor_status(27.0)', 'ros2nb.course.monitor_status'),
    ('from ros2nb.course import monitor_status', 'ros2nb.course.monitor_status'),
    ("import sys\nsys.modules['ros2nb.rules']", 'sys.modules'),
    ('import ros2nb\nros2nb.rules.monitor_status(27.0)', "ros2nb.rules (ros2nb's internals)"),
    ('import sys\nsys.meta_path.clear()', 'sys.meta_path'),
    ("import sys\nsys.modules['ros2nb.' + 'ru' + 'les']", "names 'ros2nb.rules'"),
    ("getattr(__import__('g' + 'c'), 'get_' + 'objects')()", "names 'get_objects'"),
    ("f = lambda: 0\ngetattr(f, '__glo' + 'bals__')", "names '__globals__'"),
    ("x = ''.join(['ros2nb.ju', 'dge.stand', '_ins'])", "names 'ros2nb.judge.stand_ins'"),
    ('from rclpy.node import Node\ntype.__setattr__(Node, "spin", print)',
     'an attribute of Node'),
    ('class Mine:\n    pass\nobject.__setattr__(Mine, "x", 1)', 'an attribute of Mine'),
    ('def f():\n    pass\nf.__closure__[0].cell_contents', '.cell_contents'),
    ('object.__subclasses__()', '.__subclasses__'),
    ('def f():\n    pass\nf.__code__.co_consts', '.__code__'),
    ("exec(open('x.py').read())", 'calls exec'),
    ('import marshal', 'imports marshal'),
])
def test_each_kind_is_named(code, found):
    flags = reaching_in(code, 'cell')
    assert any(found in flag for flag in flags), flags


@pytest.mark.parametrize('code', [
    'import ros2nb\nros2nb.add(node)\nros2nb.course.TOPIC',
    'self.timer = self.create_timer(1.0, lambda: self.tick())',
    "self.get_logger().info('/processing')",
    'import random\nrandom.seed(7)',
    'node.declare_parameter("x", 1.0)',
    'this is not python',
    "import rclpy\nrclpy.qos.QoSProfile(depth=__import__('rclpy').qos.HistoryPolicy.KEEP_LAST)",
    'def monitor_status(t):\n    return "High" if t > 26.0 else "Normal"\nself.monitor_status(t)',
    "setattr(self, 'count', 1)\nobject.__setattr__(self, 'count', 2)",
    "import re\nre.compile('[0-9]+')",
    "self.get_logger().info('get objects ready: ' + 'now')",
])
def test_honest_code_is_not_flagged(code):
    assert reaching_in(code, 'cell') == []


def test_setup_py_writes_are_flagged_only_in_setup_py():
    code = "with open('notes.txt', 'w') as f:\n    f.write('x')"
    assert reaching_in(code, 'setup.py', setup_py=True)
    assert reaching_in(code, 'helper.py') == []


def test_a_flag_reaches_the_instructors_note_and_no_point(tmp_path):
    """The host writes the judge's flags into the notebook's note; the results it scores
    are the judge's, untouched."""
    number = '02'
    release = nbformat.read(NOTEBOOKS[number], as_version=4)
    graded = {c.metadata['nbgrader']['grade_id']: CheckOutcome(True, ('Check passed: x',))
              for c in release.cells if c.metadata.get('nbgrader', {}).get('grade')}
    verdict: concurrent.futures.Future = concurrent.futures.Future()
    verdict.set_result(Verdict(graded, None, ('answer cell 02-x line 3: uses sys._getframe',)))
    notebook = NOTEBOOKS[number].stem
    done = learners_module.judged(notebook, release,
                                  learners_module.Judging((), copy_of(release), verdict))
    note = done.notes[notebook]
    assert note.startswith(learners_module.FLAGGED) and 'sys._getframe' in note
    assert done.flags[notebook] == ('answer cell 02-x line 3: uses sys._getframe',)
    scored = json.loads(done.filed[notebook])
    shown = [''.join(o.get('text', '')) for c in scored['cells'] for o in c.get('outputs', [])]
    assert sum('Check passed: x' in text for text in shown) == len(graded)


def copy_of(nb: nbformat.NotebookNode) -> nbformat.NotebookNode:
    return nbformat.reads(nbformat.writes(nb), as_version=4)


#: Notebooks built from the course's own parts (corpus_attacks.py): refused in the subject
#: (their score is their twin's, test_corpora.py), and flagged.
COPIES = [learner for learner in ATTACKS if learner.twin and (
    'stand-in' in learner.name or "course's rule" in learner.name)]


@pytest.mark.parametrize('learner', COPIES, ids=[learner.name for learner in COPIES])
def test_a_copy_of_the_course_is_flagged_on_its_feedback_page(learner: Learner, tmp_path):
    """The judge's flags of a copy reach the learner's feedback page, escaped, above
    nbgrader's page (a page without flags has no box), and the notes of report.html."""
    flags = flags_of(learner, tmp_path / 'workspace')
    assert any('stand_ins' in flag or 'monitor_status' in flag for flag in flags), flags
    notebook = NOTEBOOKS[learner.notebook].stem
    release = nbformat.read(NOTEBOOKS[learner.notebook], as_version=4)
    verdict: concurrent.futures.Future = concurrent.futures.Future()
    verdict.set_result(Verdict({}, None, tuple(flags)))
    ada = ClassLearner('ada', 'ada', {notebook: tmp_path / 'handed-in.ipynb'})
    learners_module.file_graded(tmp_path, ada, learners_module.judged(
        notebook, release, learners_module.Judging((), copy_of(release), verdict)))
    made = ('<html><head><style>p{color:#000}</style></head><body class="jp-Notebook">'
            '<p>nbgrader\'s page</p></body></html>')
    page = feedback.safe_feedback(made, notebook, ada.flags[notebook])
    assert feedback.FLAGS_HEADING in page and "nbgrader's page" in page
    box = page[page.index('id="flags"'):page.index("nbgrader's page")]
    assert all(flag in html.unescape(box) for flag in flags), box
    assert feedback.FLAGS_HEADING not in feedback.safe_feedback(made, notebook, ())
    report = write_report(tmp_path, [ada], [notebook], [['ada', notebook, '0', '6']], [])
    notes = html.unescape(report.read_text().split('id="notes"', 1)[1])
    assert all(flag in notes for flag in flags), notes


def test_a_cell_the_learner_added_is_read_and_a_course_cell_is_not(tmp_path):
    """A cell of the learner's own (no answer cell) is read too, even one that changes a
    course cell; what the course's own cells do (the graph read through the runtime) is not
    flagged where the learner changed such a cell."""
    from corpora import learner_workspace
    from ros2nb.judge.flags import notebook_flags
    learner = Learner('added cells', '06', {}, added=(
        ('fan-main', 'import gc\nstolen = gc.get_objects()\n'),
        ('room-arguments', 'runtime = ros2nb.current_runtime  # for later\n')))
    with learner_workspace(learner, tmp_path) as (ws, nb):
        source = json.loads(NOTEBOOKS['06'].read_text())
        flags = notebook_flags(nb, ws, source)
        assert notebook_flags(nb, ws) == [], 'without the source, only answer cells are read'
    assert len(flags) == 1 and "(not the course's) line 2: uses gc.get_objects" in flags[0], \
        flags


def test_a_cell_with_malformed_grading_metadata_is_read_as_the_learners(tmp_path):
    """A grade id that is a list (a learner's notebook is any JSON) makes the cell one of the
    learner's own, read like any other; before, the judge stopped on it (``unhashable type``)
    and the notebook scored nothing."""
    from ros2nb.judge.flags import notebook_flags
    source = json.loads(NOTEBOOKS['01'].read_text())
    submitted = json.loads(NOTEBOOKS['01'].read_text())
    submitted['cells'].append({'cell_type': 'code', 'source': 'import gc\ngc.get_objects()\n',
                               'metadata': {'nbgrader': {'grade': True, 'grade_id': ['a', 'list'],
                                                         'points': 'ten'}}, 'outputs': []})
    flags = notebook_flags(submitted, tmp_path, source)
    assert len(flags) == 1 and 'uses gc.get_objects' in flags[0], flags
