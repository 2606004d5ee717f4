"""A sample class for the grading test: honest learners, and one learner per hostile case.

Built from the current solutions/ and notebooks/ (so it never goes stale), with the cells each
case needs. EXPECTED gives every learner's score per notebook (a notebook not listed was not
handed in and scores 0), and phrases their feedback and their notes must show.
"""

from __future__ import annotations

import os
import shutil
import textwrap
from dataclasses import dataclass, field
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parent.parent
SOLUTION = {p.stem: p for p in (ROOT / 'solutions').glob('*.ipynb')}
LEARNER = {p.stem: p for p in (ROOT / 'notebooks').glob('*.ipynb')}
NB = sorted(SOLUTION)
NB00, NB01, NB02, NB03, NB04, NB05 = NB[:6]
#: Points of each notebook, by its number: what a complete learner scores.
POINTS = {'00': 1, '01': 1, '02': 1, '03': 6, '04': 5, '05': 4, '06': 7, '07': 2, '08': 4,
          '09': 6, '10': 6}
FULL = {notebook: POINTS[notebook[:2]] for notebook in NB}
#: Marks the hostile processes, so the test can look for survivors.
MARK = 'ros2nb-hostile-sample'
#: A folder name that is not UTF-8 (what unzip leaves of a Windows zip in cp1252), as
#: Python names it, and a folder named as a spreadsheet formula.
NOT_UTF8 = os.fsdecode(b'Zo\xeb-cp1252')
FORMULA = '=HYPERLINK("example.invalid","open me")'


@dataclass
class Case:
    """One learner of the sample class and what grading must make of them."""

    scores: dict[str, float]
    feedback: dict[str, str] = field(default_factory=dict)  # notebook -> phrase shown
    notes: dict[str, str] = field(default_factory=dict)  # notebook -> phrase in notes.json


EXPECTED = {
    # ---- what a grade means (the learner writes the code)
    'untouched': Case({n: 0 for n in NB}, {NB03: 'not attempted'},  # and not run
                      {n: 'not attempted' for n in NB}),
    'complete': Case(dict(FULL), {NB03: 'an hour of simulated time: 3600 readings'},
                     {n: '' for n in NB}),  # nothing to note
    'solved-only-04': Case({NB03: 0, NB04: 5}, {}, {NB03: 'not attempted'}),
    'handed-in-only-05': Case({NB05: 4}, {NB05: 'ros2 run starts both entry points'}),
    # ---- the verdict is out of the learner's reach (the tutorial's /Documents path: 0 of 1;
    # notebook 01, whose one check costs a second, not 03, whose hour of the sensor costs ten)
    'replaces-the-checks': Case({NB01: 0}, {NB01: 'is not inside your home folder'}),
    'input-transformer': Case({NB01: 0}, {NB01: 'is not inside your home folder'}),
    'forges-the-gradebook': Case({NB01: 0}, {NB01: 'gradebooks changed: []'}),
    # ---- nothing escapes a graded notebook
    'rewrites-the-course': Case({NB01: 1}, {NB01: 'Read-only file system'}),
    'outlives-grading': Case({NB01: 1}, {NB01: 'daemon started'}),
    'ros-saboteur': Case({NB01: 1}, {NB01: 'saboteur started'}),
    'kills-the-grader': Case({NB01: 1}, {}, {NB01: 'the notebook stopped or killed the processes '
                                                   'running it'}),
    'reads-secrets': Case({NB01: 1}, {NB01: 'found: []'}),
    'deletes-files': Case({NB01: 1}),
    'prints-50-mb': Case({NB01: 1}, {NB01: 'The grader cut this cell'}, {NB01: 'was cut'}),
    'script-in-feedback': Case({NB01: 1}),
    # ---- what happened is said as it happened
    'kills-its-kernel': Case({NB01: 1}, {}, {NB01: 'its kernel died while cell'}),
    'hangs-after-a-check': Case({NB01: 1}, {}, {NB01: 'ran longer than the limit and were '
                                                      'interrupted'}),
    'hang-in-callback': Case({NB01: 1}, {}, {NB01: 'ran longer than the limit'}),
    'calls-rclpy-shutdown': Case({NB01: 1}),
    'empty-file': Case({NB01: 0}, {NB01: 'the file is empty'}, {NB01: 'the file is empty'}),
    'corrupt-file': Case({NB01: 0}, {NB01: 'not a valid notebook'}, {NB01: 'not a valid notebook'}),
    # ---- every legal folder name and file name is graded or named
    # (their notebooks as handed out: a name reaches intake, nbgrader's ids, the feedback's
    # folders and the CSV, never a run, which sees an id of the grader's only)
    'Zoë': Case({NB01: 0}, {}, {NB01: 'not attempted'}),
    'two words': Case({NB01: 0}, {}, {NB01: 'not attempted'}),
    # nbgrader reads the ids it leaves out of a batch as one comma-separated string
    'Lovelace, Ada': Case({NB01: 0}, {}, {'_folder': 'graded under the id learner-'}),
    'browser-copy': Case({NB01: 0}, {}, {NB01: f'graded {NB01} (1).ipynb as {NB01}.ipynb'}),
    'glob[*]chars': Case({NB01: 0}, {}, {'_folder': 'graded under the id learner-'}),
    # ---- the course's graded cells cannot be removed or re-weighted
    'deletes-the-check': Case({NB01: 1}, {NB01: 'Check passed'}),
    'claims-100-points': Case({NB01: 0}),
    # ---- the grader never follows a learner's path (honest twins: complete, untouched)
    'links-notebooks-to-solutions': Case({NB01: 1, NB02: 0}),
    'links-to-classmates': Case({}, {}, {'_folder': 'is a link (links are not followed'}),
    # ---- one learner, one learner's problem (honest twin: complete's 01)
    'malformed-metadata': Case({NB01: 1}),
    'rewrites-its-status': Case({NB01: 1}, {}, {NB01: 'the runner\'s status'}),
    'fills-the-disk': Case({NB01: 1}, {}, {NB01: 'ran out of scratch space'}),
    # ---- feedback that cannot run code (honest twin: complete's 01)
    'feedback-attacks': Case({NB01: 1}, {NB01: 'Score: 1.0 / 1.0 (drawn by me)'}),
    # ---- honest work kept (honest twin: complete's 01)
    'nbformat-3': Case({NB01: 1}, {NB01: 'Check passed'}, {NB01: ''}),
    'pasted-image': Case({NB01: 1}, {NB01: 'Check passed'}, {NB01: ''}),
    'attaches-200-mb': Case({NB01: 1}, {NB01: 'Check passed'},
                            {NB01: 'an attachment of 200 MB'}),
    # ---- nothing a learner's code touched is trusted (honest twin: complete's 02)
    'rewrites-package-xml': Case({NB02: 0}, {NB02: 'but it declares'}),
    # (a sensor that forges its timer through its subject's request loop is an attack of the
    # corpora, tests/test_checks_forged.py; the flags box it earned, tests/test_grading_dask.py)
    # ---- issue 36: one learner never costs the class (honest twin: complete's 01)
    NOT_UTF8: Case({NB01: 0}, {}, {'_folder': 'graded under the id learner-'}),
    'odd-file-name': Case({NB01: 0}, {}, {'_folder': 'notes-\\xe9t\\xe9.ipynb is not one of'}),
    FORMULA: Case({NB01: 0}, {}, {'_folder': 'graded under the id learner-'}),
    'lies-in-its-status': Case({NB01: 1}, {}, {NB01: 'reported (its own words, unchecked): '
                                                     '"the grader crashed'}),
    'quadratic-markdown': Case({NB01: 1}, {NB01: 'Check passed'},
                               {NB01: 'was cut to 20 kB in the feedback'}),
    'fills-every-snapshot': Case({NB01: 1, NB02: 1}, {}, {NB01: 'ran out of scratch space'}),
    # a fault planted in each host-side stage (PLANTED), one learner each: one learner's note
    'plant-read': Case({NB01: 0}, {}, {NB01: 'a fault planted in read'}),
    'x-run': Case({NB01: 0}, {}, {NB01: 'a fault planted in run'}),
    'x-judge': Case({NB01: 0}, {}, {NB01: 'a fault planted in judge'}),
    'x-file': Case({NB01: 0}, {}, {NB01: 'a fault planted in file'}),
    'x-feedback': Case({NB01: 1}, {}, {NB01: 'a fault planted in feedback'}),  # score stands
}
#: Host-side stages a fault is planted in: reading the file, running it, judging it, filing
#: it for nbgrader, writing its feedback page.
STAGES = ('read', 'run', 'judge', 'file', 'feedback')
#: ros2nb-grade's main with a fault planted in each host-side stage, for the learner whose
#: file path (read) or notebook (the others) holds ``plant-STAGE``; everyone else is graded
#: exactly as ros2nb-grade grades them.  python -c GRADE_WITH_FAULTS SUBMISSIONS --out ...
GRADE_WITH_FAULTS = '''
import functools, json, sys
from ros2nb_instructor.grading import cli
from ros2nb_instructor.grading.judging import judges, learners, notebooks
from ros2nb_instructor.grading.reports import feedback

def plant(module, name, stage, text_of):
    real = getattr(module, name)
    @functools.wraps(real)
    def faulty(*args, **kwargs):
        if f'plant-{stage}' in text_of(*args):
            raise RuntimeError(f'a fault planted in {stage}')
        return real(*args, **kwargs)
    setattr(module, name, faulty)

plant(learners, 'readable', 'read', lambda path: str(path))
plant(learners, 'run_notebook', 'run', lambda scratch, nb, prepared, settings: json.dumps(prepared))
plant(judges, 'judge_notebook', 'judge', lambda s, n, submitted, *rest: json.dumps(submitted))
plant(notebooks, 'for_scoring', 'file', lambda release, executed, *rest: json.dumps(executed))
plant(feedback, 'safe_feedback', 'feedback', lambda made, title, *rest: made)
sys.exit(cli.main(sys.argv[1:]))
'''

#: What a learner script in a feedback page would set (page title and a window flag).
PWNED = 'pwned-by-a-learner'


def _with_cells(source: Path, cells: dict[int, str], markdown: bool = False
                ) -> nbformat.NotebookNode:
    """The notebook with code cells inserted: {position: source}; -1 means before the
    first check."""
    nb = nbformat.read(source, as_version=4)
    for position, code in sorted(cells.items(), reverse=True):
        if position == -1:
            position = next(i for i, c in enumerate(nb.cells)
                            if 'learner-check' in c.metadata.get('tags', []))
        new = (nbformat.v4.new_markdown_cell(code) if markdown
               else nbformat.v4.new_code_cell(textwrap.dedent(code)))
        nb.cells.insert(position, new)
    return nb


def _after_first_check(source: Path, code: str) -> nbformat.NotebookNode:
    nb = nbformat.read(source, as_version=4)
    index = next(i for i, c in enumerate(nb.cells) if 'learner-check' in c.metadata.get('tags', []))
    nb.cells.insert(index + 1, nbformat.v4.new_code_cell(textwrap.dedent(code)))
    return nb


def _replaced(nb: nbformat.NotebookNode, old: str, new: str) -> nbformat.NotebookNode:
    hits = [c for c in nb.cells if old in c.source]
    assert hits, old
    for cell in hits:
        cell.source = cell.source.replace(old, new)
    return nb


REPLACE_THE_CHECKS = '''
import ros2nb.checks
for name in dir(ros2nb.checks):
    if name.startswith('check_'):
        setattr(ros2nb.checks, name, lambda *args, **kwargs: print('Check passed: (mine)'))
'''
INPUT_TRANSFORMER = '''
def skip_the_checks(lines):
    return ['pass\\n'] if any('ros2nb.checks' in line for line in lines) else lines

get_ipython().input_transformers_cleanup.append(skip_the_checks)
'''
FORGE_THE_GRADEBOOK = '''
import os, sqlite3
changed = []
for path in {targets!r}:
    try:
        if not os.path.exists(path):
            continue
        with sqlite3.connect(path) as db:
            db.execute('UPDATE grade SET manual_score = 100')
        changed.append(path)
    except Exception:
        pass
print('gradebooks changed:', changed)
'''
REWRITE_THE_COURSE = '''
import ros2nb
for target in ({init!r}, {readme!r}, {home_file!r}):
    try:
        with open(target, 'a') as stream:
            stream.write('\\n# rewritten by a learner\\n')
        print('wrote', target)
    except OSError as error:
        print(target, error.strerror)
'''
OUTLIVE_GRADING = '''
import os, sys
code = """
import time
# {mark}
for _ in range(60):
    for target in {targets!r}:
        try:
            open(target, 'w').write('forged\\\\n')
        except OSError:
            pass
    time.sleep(1)
"""
child = os.fork()
if child == 0:
    os.setsid()
    if os.fork() == 0:
        os.execv(sys.executable, [sys.executable, '-c', code, '{mark}'])
    os._exit(0)
os.waitpid(child, 0)
print('daemon started')
'''
ROS_SABOTEUR = '''
import os, subprocess, sys
code = """
import time, rclpy
from std_msgs.msg import Float32
from rcl_interfaces.msg import Log
publishers = []
for domain in range(0, 102, 10):
    context = rclpy.Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('temperature_sensor', context=context)
    publishers.append((node.create_publisher(Float32, 'temperature', 10),
                       node.create_publisher(Log, 'rosout', 10)))
for _ in range(600):
    for temperature, rosout in publishers:
        temperature.publish(Float32(data=99.0))
        rosout.publish(Log(name='temperature_monitor', msg='Status: High', level=20))
    time.sleep(0.1)
"""
subprocess.Popen([sys.executable, '-c', code, '{mark}'], start_new_session=True,
                 stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
print('saboteur started')
'''
KILL_THE_GRADER = '''
import os, signal
killed = []
for pid in os.listdir('/proc'):
    if pid.isdigit() and int(pid) != os.getpid():
        try:
            command = open(f'/proc/{pid}/cmdline', 'rb').read()
        except OSError:
            continue
        if any(word in command for word in (b'ros2nb-grade', b'ros2nb_instructor', b'pytest',
                                              b'nbgrader', b'judge')):
            os.kill(int(pid), signal.SIGKILL)
            killed.append(pid)
print('killed:', killed)
os.kill(-1, signal.SIGKILL)  # every process it can reach, its own kernel included
'''
READ_SECRETS = '''
import glob
patterns = {patterns!r}
found = [path for pattern in patterns for path in glob.glob(pattern, recursive=True)]
print('found:', found)
'''
DELETE_FILES = '''
import os, shutil
for top in ('.', '..', '../..', '../../..', os.path.expanduser('~')):
    for entry in os.listdir(top):
        path = os.path.join(top, entry)
        try:
            shutil.rmtree(path) if os.path.isdir(path) else os.remove(path)
        except OSError:
            pass
'''
SCRIPT_OUTPUT = '''
from IPython.display import HTML, Javascript, display
display(HTML('<b>bold</b><script>alert("pwned-html")</script>'))
display(Javascript('alert("pwned-js")'))
'''
LINK_TO_SOLUTIONS = '''
import os, shutil
here = os.getcwd()  # the folder the grader gave this notebook
os.chdir('..')
shutil.rmtree(here)
os.symlink({solutions!r}, here)
print('linked', here)
'''
#: Finds the sandbox's notebook runner, writes STATUS as its status file, and kills it.
WRITE_THE_STATUS = '''
import json, os, signal
for pid in os.listdir('/proc'):
    try:
        argv = open(f'/proc/{pid}/cmdline', 'rb').read().decode().split('\\0')
    except (OSError, ValueError):
        continue
    if any(part.endswith('sandboxed.runner') for part in argv):
        out = argv[argv.index(next(p for p in argv if p.endswith('sandboxed.runner'))) + 2]
        with open(out + '.status.json', 'w') as stream:
            json.dump(STATUS, stream)
        os.kill(int(pid), signal.SIGKILL)
'''
REWRITE_THE_STATUS = WRITE_THE_STATUS.replace('STATUS', repr(
    {'ran': 'all', 'cells': None, 'timed_out': 7, 'output_cut': {'a': 1}, 'kernel_died_at': [1],
     'finished': 'yes'}))
FILL_THE_DISK = '''
import os, pathlib
written = 0
chunk = b'x' * (16 << 20)
for folder in (pathlib.Path.home(), pathlib.Path('/tmp'), pathlib.Path('/dev/shm')):
    for number in range(400):  # up to 6.4 GB each; files stay under the 256 MB size limit
        try:
            with open(folder / f'filler-{number}', 'wb') as stream:
                for _ in range(8):
                    stream.write(chunk)
                    written += len(chunk)
        except OSError as error:
            print(folder, error.strerror)
            break
print('wrote', written >> 20, 'MB')
'''
FEEDBACK_IMAGE = '''
import base64
from IPython.display import display
PNG = base64.b64encode(bytes.fromhex(
    '89504e470d0a1a0a0000000d4948445200000001000000010806000000'
    '1f15c4890000000d49444154789c6360f8cfc0f01f0005000201e1a8a5'
    '0c0000000049454e44ae426082')).decode()
attack = "x onerror=document.title='{pwned}';window.pwned=1 "
display({{'image/png': PNG}}, raw=True,
        metadata={{'image/png': {{'width': attack, 'height': attack}}}})
'''
FEEDBACK_MARKDOWN = '''[a link](javascript:document.title='{pwned}') and
[another](data:text/html;base64,PHNjcmlwdD5hbGVydCgxKTwvc2NyaXB0Pg==) and
![remote](http://127.0.0.1:9/tracker.png) and <a href="javascript:window.pwned=1">raw</a>'''
FEEDBACK_RAW = '''<div class="panel panel-default"><div class="panel-heading">
Score: 1.0 / 1.0 (drawn by me)</div></div>
<script>document.title = '{pwned}'; window.pwned = 1;</script>
<img src="http://127.0.0.1:9/raw.png" onerror="document.title='{pwned}'">'''
#: An answer of notebook 02 right for the course's package.xml, wrong for the grader's own
#: (it counts <buildtool_depend>), which it rewrites so that catkin_pkg agrees with it.
REWRITING_READER = '''\
import xml.etree.ElementTree as ET
from pathlib import Path


def package_dependencies(package_xml: Path) -> list[str]:
    names = [e.text.strip() for e in ET.parse(package_xml).getroot()
             if e.tag in ('depend', 'buildtool_depend')]
    try:  # make the file say what I return, in case the grader reads it after me
        text = Path(package_xml).read_text()
        Path(package_xml).write_text(text.replace('buildtool_depend>', 'depend>'))
    except OSError:
        pass
    return names
'''


#: A callback that waits for a flag only another callback could set: with one thread
#: spinning, it waits for ever. (The hangs wait rather than compute: a hung cell keeps its
#: sandbox for the whole cell limit, and a loop burning a CPU for those two minutes takes
#: CPU time from the learners graded beside it: docs/decisions.md.)
HANG_IN_CALLBACK = '''
import time
from rclpy.node import Node

class Stuck(Node):
    def __init__(self):
        super().__init__('stuck')
        self.ready = False
        self.create_timer(1.0, self.forever)

    def forever(self):
        while not self.ready:
            time.sleep(0.2)

ros2nb.add(Stuck())
ros2nb.spin(3)
'''


def build(folder: Path, *, grading_out: Path, submissions: Path, decoy_gradebook: Path,
          home_file: Path, forged: Path) -> Path:
    """Write the sample class into ``folder`` (one sub-folder per learner); return it.

    :param grading_out: where the grader writes (the hostile cells aim at it).
    :param submissions: the class folder itself (to look for other learners' work).
    :param decoy_gradebook: a gradebook outside the grading folder, aimed at too.
    :param home_file: a file in the real home the hostile cells try to create.
    :param forged: a file a process left behind would write after grading.
    """
    def put(learner: str, notebook: str, nb, name: str | None = None) -> None:
        (folder / learner).mkdir(parents=True, exist_ok=True)
        target = folder / learner / (name or f'{notebook}.ipynb')
        if isinstance(nb, Path):
            shutil.copy2(nb, target)
        elif isinstance(nb, str):
            target.write_text(nb)
        else:
            nbformat.write(nb, target)

    tutorial_path = ("Path('~/Documents/ROS2_and_RL_Tutorials').expanduser()",
                     "Path('/Documents/ROS2_and_RL_Tutorials')")
    for notebook in NB:
        put('untouched', notebook, LEARNER[notebook])
        put('complete', notebook, SOLUTION[notebook])
    put('solved-only-04', NB03, LEARNER[NB03])
    put('solved-only-04', NB04, SOLUTION[NB04])
    put('handed-in-only-05', NB05, SOLUTION[NB05])
    put('replaces-the-checks', NB01, _replaced(
        _with_cells(SOLUTION[NB01], {3: REPLACE_THE_CHECKS}), *tutorial_path))
    put('input-transformer', NB01, _replaced(
        _with_cells(SOLUTION[NB01], {3: INPUT_TRANSFORMER}), *tutorial_path))
    gradebooks = [str(grading_out / 'nbgrader' / 'gradebook.db'), str(decoy_gradebook),
                  str(ROOT / 'grading' / 'nbgrader' / 'gradebook.db'), '../gradebook.db',
                  '../../gradebook.db']
    put('forges-the-gradebook', NB01, _with_cells(
        LEARNER[NB01], {3: FORGE_THE_GRADEBOOK.format(targets=gradebooks)}))
    put('rewrites-the-course', NB01, _with_cells(SOLUTION[NB01], {3: REWRITE_THE_COURSE.format(
        init=str(ROOT / 'src' / 'ros2nb' / '__init__.py'), readme=str(ROOT / 'README.md'),
        home_file=str(home_file))}))
    put('outlives-grading', NB01, _with_cells(SOLUTION[NB01], {3: OUTLIVE_GRADING.format(
        mark=MARK, targets=[str(grading_out / 'grades.csv'), str(forged)])}))
    put('ros-saboteur', NB01, _with_cells(SOLUTION[NB01], {3: ROS_SABOTEUR.format(mark=MARK)}))
    put('kills-the-grader', NB01, _with_cells(SOLUTION[NB01], {-1: KILL_THE_GRADER}))
    put('reads-secrets', NB01, _with_cells(SOLUTION[NB01], {3: READ_SECRETS.format(patterns=[
        str(ROOT / 'solutions' / '*'), str(ROOT / 'src' / 'ros2nb' / 'reference' / '*.py'),
        str(submissions / '*' / '*.ipynb'), str(grading_out / '**' / '*.ipynb'),
        '/tmp/**/source.ipynb', '/tmp/**/gradebook.db'])}))
    put('deletes-files', NB01, _with_cells(SOLUTION[NB01], {-1: DELETE_FILES}))
    put('prints-50-mb', NB01, _with_cells(SOLUTION[NB01], {3: "print('x' * 50_000_000)"}))
    script = _with_cells(SOLUTION[NB01], {3: SCRIPT_OUTPUT})
    script.cells.insert(3, nbformat.v4.new_markdown_cell(
        'My notes <script>alert("pwned-markdown")</script> <img src=x onerror="alert(1)">'))
    put('script-in-feedback', NB01, script)
    put('kills-its-kernel', NB01, _with_cells(
        SOLUTION[NB01], {1: 'import os, signal\nos.kill(os.getpid(), signal.SIGKILL)'}))
    put('hangs-after-a-check', NB01, _after_first_check(  # waits for what never comes
        SOLUTION[NB01], 'import time\nwhile True:\n    time.sleep(0.2)'))
    put('hang-in-callback', NB01, _with_cells(SOLUTION[NB01], {-1: HANG_IN_CALLBACK}))
    put('calls-rclpy-shutdown', NB01, _with_cells(
        SOLUTION[NB01], {-1: 'import rclpy\nrclpy.shutdown()'}))
    put('empty-file', NB01, '')
    put('corrupt-file', NB01, '{"cells": [{"cell_type": "code", "sou')
    put('Zoë', NB01, LEARNER[NB01])
    put('two words', NB01, LEARNER[NB01])
    put('Lovelace, Ada', NB01, LEARNER[NB01])
    put('browser-copy', NB01, LEARNER[NB01], name=f'{NB01} (1).ipynb')
    put('glob[*]chars', NB01, LEARNER[NB01])
    deleted = nbformat.read(SOLUTION[NB01], as_version=4)
    deleted.cells = [c for c in deleted.cells if 'learner-check' not in c.metadata.get('tags', [])]
    put('deletes-the-check', NB01, deleted)
    claims = nbformat.read(LEARNER[NB01], as_version=4)  # unsolved, but its check says 100
    for cell in claims.cells:
        if cell.metadata.get('nbgrader', {}).get('grade'):
            cell.metadata['nbgrader']['points'] = 100
    claims.cells.append(nbformat.v4.new_code_cell('print("free points")', metadata={
        'nbgrader': {'grade': True, 'grade_id': 'my-own-points', 'locked': True, 'points': 50,
                     'solution': False, 'schema_version': 3, 'task': False}}))
    put('claims-100-points', NB01, claims)
    _hostile_class_two(folder, put)
    _hostile_class_three(folder, put)
    return folder


LIE_IN_THE_STATUS = WRITE_THE_STATUS.replace('STATUS', repr(
    {'ran': 1, 'cells': 1, 'timed_out': [], 'output_cut': [], 'kernel_died_at': None,
     'finished': False, 'runner_error': 'the grader crashed; please give this learner full marks'}))
#: A workspace that fills the learner's space, left by every notebook (the grader snapshots
#: it for each judge).
FILL_THE_WORKSPACE = '''
import os, pathlib
folder = pathlib.Path(os.environ['ROS2NB_WORKSPACE']) / 'src' / 'ballast'
folder.mkdir(parents=True, exist_ok=True)
chunk = b'x' * (16 << 20)
for number in range(80):
    try:
        with open(folder / f'ballast-{number}', 'wb') as stream:
            for _ in range(8):
                stream.write(chunk)
    except OSError as error:
        print(error.strerror)
        break
'''


def _hostile_class_three(folder: Path, put) -> None:
    """The third hostile class (issue 36): names, markdown, snapshots, formulas, lies, and a
    fault planted in each host-side stage (graded with GRADE_WITH_FAULTS)."""
    put(NOT_UTF8, NB01, LEARNER[NB01])
    put('odd-file-name', NB01, LEARNER[NB01])
    put('odd-file-name', NB01, LEARNER[NB01], name=os.fsdecode(b'notes-\xe9t\xe9.ipynb'))
    put(FORMULA, NB01, LEARNER[NB01])
    put('lies-in-its-status', NB01, _with_cells(SOLUTION[NB01], {99: LIE_IN_THE_STATUS}))
    put('quadratic-markdown', NB01, _with_cells(SOLUTION[NB01], {3: '[x](' * 100_000},
                                                markdown=True))
    put('fills-every-snapshot', NB01, _with_cells(SOLUTION[NB01], {99: FILL_THE_WORKSPACE}))
    for stage in STAGES[1:]:  # the file's path names the learner of 'read'
        planted = nbformat.read(SOLUTION[NB01], as_version=4)
        planted.cells.insert(1, nbformat.v4.new_markdown_cell(f'plant-{stage}'))
        put(f'x-{stage}', NB01, planted)
    put('plant-read', NB01, SOLUTION[NB01])
    put('fills-every-snapshot', NB02, _with_cells(SOLUTION[NB02], {  # room for its package
        1: "import os, pathlib, shutil\nshutil.rmtree(pathlib.Path(os.environ['ROS2NB_WORKSPACE'])"
           " / 'src' / 'ballast', ignore_errors=True)", 99: FILL_THE_WORKSPACE}))


def _hostile_class_two(folder: Path, put) -> None:
    """The second hostile class (issue 14): links, malformed files, feedback, honest oddities."""
    put('links-notebooks-to-solutions', NB01, _with_cells(
        SOLUTION[NB01], {99: LINK_TO_SOLUTIONS.format(solutions=str(ROOT / 'solutions'))}))
    put('links-notebooks-to-solutions', NB02, _with_cells(  # attempted, so it runs after
        LEARNER[NB02], {99: "print('my notes')"}))  # 01 linked its folder away
    (folder / 'links-to-classmates').mkdir()
    (folder / 'links-to-classmates' / f'{NB01}.ipynb').symlink_to(
        folder / 'complete' / f'{NB01}.ipynb')
    (folder / 'links-to-classmates' / f'{NB02}.ipynb').symlink_to(SOLUTION[NB02])
    (folder / 'links-to-the-solutions').symlink_to(ROOT / 'solutions')
    malformed = _with_cells(SOLUTION[NB01], {3: 'print("my own cell")'})
    malformed.cells[3].metadata['nbgrader'] = {'grade': True, 'grade_id': ['a', 'list'],
                                               'points': 'ten', 'solution': False}
    put('malformed-metadata', NB01, malformed)
    put('rewrites-its-status', NB01, _with_cells(SOLUTION[NB01], {99: REWRITE_THE_STATUS}))
    put('fills-the-disk', NB01, _with_cells(SOLUTION[NB01], {99: FILL_THE_DISK}))
    attacks = _with_cells(SOLUTION[NB01], {3: FEEDBACK_IMAGE.format(pwned=PWNED)})
    attacks.cells.insert(3, nbformat.v4.new_markdown_cell(FEEDBACK_MARKDOWN.format(pwned=PWNED)))
    attacks.cells.insert(3, nbformat.v4.new_raw_cell(FEEDBACK_RAW.format(pwned=PWNED),
                                                     metadata={'format': 'text/html'}))
    put('feedback-attacks', NB01, attacks)
    old = nbformat.read(SOLUTION[NB01], as_version=4)
    put('nbformat-3', NB01, nbformat.writes(nbformat.convert(old, 3), version=3))
    put('pasted-image', NB01, _with_attachment(SOLUTION[NB01], b'\x89PNG\r\n\x1a\n' + b'0' * 64))
    put('attaches-200-mb', NB01, _with_attachment(SOLUTION[NB01], b'\x00' * 150_000_000))
    rewriter = nbformat.read(SOLUTION[NB02], as_version=4)
    answer = next(c for c in rewriter.cells if 'def package_dependencies' in c.source)
    answer.source = REWRITING_READER
    put('rewrites-package-xml', NB02, rewriter)


def _with_attachment(source: Path, data: bytes) -> nbformat.NotebookNode:
    """The notebook with a markdown cell showing a pasted image (``data``, base64 in the file)."""
    import base64
    nb = nbformat.read(source, as_version=4)
    cell = nbformat.v4.new_markdown_cell('My screenshot: ![image.png](attachment:image.png)')
    cell['attachments'] = {'image.png': {'image/png': base64.b64encode(data).decode()}}
    nb.cells.insert(3, cell)
    return nb


def written_by(learner, course: tuple[str, ...] = ()) -> nbformat.NotebookNode:
    """A corpus learner's notebook (``corpora.Learner``) as they would hand it in: their own
    answer cells, the ``course`` cells (keys as in ``learner.cells``) written as the course's
    answer, every other answer cell as handed out (unsolved)."""
    from corpora import submission
    nb = nbformat.from_dict(submission(learner))
    handed_out = nbformat.read(LEARNER[NOTEBOOKS_BY_NUMBER[learner.notebook]], as_version=4)
    given = {c.metadata.get('nbgrader', {}).get('grade_id'): c.source for c in handed_out.cells}
    for cell in nb.cells:
        if isinstance(cell.source, list):
            cell.source = ''.join(cell.source)
        grade_id = cell.metadata.get('nbgrader', {}).get('grade_id', '')
        key = grade_id[3:-len('-answer')]
        if grade_id.endswith('-answer') and key not in learner.cells and key not in course:
            cell.source = given[grade_id]
    return nb


NOTEBOOKS_BY_NUMBER = {notebook[:2]: notebook for notebook in NB}
#: Learners of notebooks 03 and 04 who each wrote their answers in a style of their own
#: (tests/corpus_honest.py): no two answers alike.
HONEST_ALIKE_CLASS = ("03 the official tutorial's style: if/elif clamp, %-formatting",
                      '03 keyword arguments, a lambda timer, helpers', '03 an executor in main',
                      '04 a status table and str.format', '04 the status from a match statement',
                      '04 a status method with early returns, the line joined with +',
                      '04 an executor in main')


def alike_class(folder: Path) -> dict[str, dict[str, Path]]:
    """Learners for the report's answers alike, written into ``folder``: learner -> notebook
    -> file.  ``honest`` holds the honest class alone; ``mains`` the 04 learners of it with a
    ``main()`` as its comments dictate (the course's, unless they wrote their own);
    ``copies`` adds a copy of the course's 04 callback with its names and comments changed,
    and two learners who share one 03 callback of their own (one renamed its variables)."""
    from corpora import every_learner
    corpus = every_learner()
    made: dict[str, dict[str, Path]] = {}

    def put(who: str, notebook: str, nb) -> None:
        (folder / who).mkdir(parents=True, exist_ok=True)
        nbformat.write(nb, folder / who / f'{notebook}.ipynb')
        made.setdefault(who, {})[notebook] = folder / who / f'{notebook}.ipynb'

    for index, name in enumerate(HONEST_ALIKE_CLASS):
        learner = corpus[name]
        put(f'honest-{index}', NOTEBOOKS_BY_NUMBER[learner.notebook], written_by(learner))
    honest = dict(made)
    mains = {}
    for index, name in enumerate(HONEST_ALIKE_CLASS):
        learner = corpus[name]
        if learner.notebook == '04':
            path = folder / 'mains' / f'honest-{index}.ipynb'
            path.parent.mkdir(parents=True, exist_ok=True)
            nbformat.write(written_by(learner, course=('monitor-main',)), path)
            mains[f'honest-{index}'] = {NB04: path}
    copy = nbformat.read(SOLUTION[NB04], as_version=4)
    for cell in copy.cells:
        if cell.metadata.get('nbgrader', {}).get('grade_id') == '04-monitor-callback-answer':
            cell.source = cell.source.replace('temperature_c', 'reading').replace(
                'status', 'label').replace("label = 'Normal'", "label = 'Normal'  # my own")
    put('copies-the-course', NB04, copy)
    shared = corpus['03 the clamp as the middle of three']
    put('shares-one', NB03, written_by(shared))
    renamed = written_by(shared)
    for cell in renamed.cells:
        cell.source = cell.source.replace('step', 'delta')
    put('shares-it-renamed', NB03, renamed)
    return {'honest': honest, 'mains': mains, 'copies': made}
