"""A subject or program forked from the fork server is the process a started one is.

A judge forks its unsandboxed subjects and the learner's main() from a server that has
imported ROS (``ros2nb.subject.forked``), sparing each the imports.  What the learner's code can
see of its process must not change with it: environment, working folder, ``sys.path``, its own
session, standard streams, and rclpy's field checks, which generated message modules read
from the environment once, when the server imported them (the judge's own environment, here
without ``ROS_PYTHON_CHECK_FIELDS``).
"""

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from ros2nb.judge.subjects import SUBJECT_PREFIX_ENV, SubjectProcess, subject_env
from ros2nb.subject import forked
from ros2nb.subject.fork_server import PROGRAM, ForkRequest
from ros2nb.subject_interface import ExecCells
from ros2nb.processes import kill_process_group
from waiting import run_to_end, wait_until

pytestmark = [pytest.mark.judge, pytest.mark.timeout(120)]

VIEW = '''
import json, os, sys, tempfile
from std_msgs.msg import Float32

def fds():
    found = []
    for name in os.listdir('/proc/self/fd'):
        try:
            found.append(os.readlink('/proc/self/fd/' + name).split(':')[0])
        except OSError:  # the listing's own
            pass
    return sorted(found)

try:
    Float32(data='hot')
    checks_fields = False
except AssertionError:
    checks_fields = True
print('VIEW', json.dumps({
    'leads its session': os.getsid(0) == os.getpgid(0) == os.getpid(),
    'cwd': os.getcwd(), 'sys.path': sys.path, 'argv': len(sys.argv),
    'tempdir': tempfile.gettempdir(), 'home': os.path.expanduser('~'),
    'environment': {k: v for k, v in os.environ.items() if k != 'ROS2NB_JUDGE_CLOCK'},
    'checks fields': checks_fields, 'stdin': sys.stdin.read(),
    'stdout written at once': sys.stdout.write_through, 'open files': fds(),
    'parent is the judge': os.getppid() == JUDGE}))
'''


def view(tmp_path, judge_pid: int) -> tuple[dict, SubjectProcess]:
    """What a new subject's code sees of its process."""
    (tmp_path / 'tmp').mkdir(exist_ok=True)
    extra = {'TMPDIR': str(tmp_path / 'tmp'), 'HOME': str(tmp_path / 'home'),
             'PYTHONPATH': str(tmp_path / 'lib')}
    subject = SubjectProcess(tmp_path, env=subject_env(extra))
    subject.send(ExecCells(sources=[f'JUDGE = {judge_pid}\n' + VIEW]))
    reply = None
    while reply is None:
        reply = subject.poll_reply(1.0)
    assert reply == {'ok': True, 'error': None, 'cell_errors': []}, reply
    subject.close()
    line, = (line for line in subject.output.text().splitlines() if line.startswith('VIEW '))
    return json.loads(line[len('VIEW '):]), subject


def test_a_forked_subject_sees_what_a_started_one_sees(tmp_path, monkeypatch):
    monkeypatch.delenv('ROS_PYTHON_CHECK_FIELDS', raising=False)  # the subjects' env sets it
    view(tmp_path, os.getpid())  # this process's first subject, if no test started one yet
    forked, _ = view(tmp_path, os.getpid())
    monkeypatch.setenv(SUBJECT_PREFIX_ENV, json.dumps(['env']))  # a prefix: started afresh
    started, _ = view(tmp_path, os.getpid())
    assert not forked.pop('parent is the judge') and started.pop('parent is the judge')
    assert forked == started
    assert forked['checks fields'] and forked['leads its session']
    # as python -P starts: PYTHONPATH first, the working folder nowhere on the path
    assert forked['sys.path'][0] == str(tmp_path / 'lib'), forked['sys.path']
    assert str(tmp_path) not in forked['sys.path'], forked['sys.path']


@pytest.mark.parametrize('how', ['forked', 'started'])
def test_a_module_in_the_working_folder_stands_in_for_nothing(tmp_path, monkeypatch, how):
    """A json.py (or any module named as the standard library's: colorsys, which no subject
    imports before its learner's code) in a subject's working folder is never imported in its
    place: before, subjects started as ``python -m`` in the
    learner's workspace, and a json.py the learner wrote there loaded before the audit hook
    and everything the subject bound."""
    (tmp_path / 'json.py').write_text('raise SystemExit("the working folder\'s json.py ran")\n')
    (tmp_path / 'colorsys.py').write_text('raise SystemExit("the working folder\'s colorsys")\n')
    SubjectProcess(tmp_path).close()  # this process's first subject, if no test started one yet
    monkeypatch.setenv(SUBJECT_PREFIX_ENV, json.dumps(['env']) if how == 'started' else '')
    subject = SubjectProcess(tmp_path)
    reply = subject.request(ExecCells(sources=['import colorsys, json\nprint(json.__file__)']))
    subject.close()
    assert reply.ok and not reply.cell_errors, (reply, subject.output.text())
    assert str(tmp_path) not in subject.output.text(), subject.output.text()


def test_a_forked_subject_is_stopped_and_reaped_as_a_started_one(tmp_path):
    SubjectProcess(tmp_path).close()  # this process's first subject is started afresh
    subject = SubjectProcess(tmp_path)
    assert subject.proc.poll() is None
    with pytest.raises(subprocess.TimeoutExpired):
        subject.proc.wait(0.1)
    assert kill_process_group(subject.proc) == -signal.SIGTERM
    assert subject.proc.poll() == -signal.SIGTERM
    subject.close()


SCRIPT_JUDGE = '''
import sys
from pathlib import Path
print('the judge script ran')
if __name__ == '__main__':
    from ros2nb.judge.subjects import SubjectProcess
    from ros2nb.subject_interface import ExecCells
    for _ in range(2):  # the first started afresh, the second forked from a server
        subject = SubjectProcess(Path(sys.argv[1]))
        subject.request(ExecCells(sources=['import os\\nprint("parent", os.getppid())']))
        subject.close()
        print('subject said:', subject.output.text().replace('\\n', ' | '))
'''


def test_a_judge_run_from_a_script_file_never_runs_it_in_its_subjects(tmp_path):
    """The fork server never runs its parent's main module (multiprocessing's ran it again
    in each child): a judge whose main module is a script file (a benchmark,
    tests/corpora.py) forks its subjects too, and none of its code runs in them."""
    script = tmp_path / 'judge_script.py'
    script.write_text(SCRIPT_JUDGE)
    judge = subprocess.Popen([sys.executable, str(script), str(tmp_path)], text=True,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    out = ''

    def ended() -> bool:
        nonlocal out
        try:
            out = judge.communicate(timeout=0.25)[0]
        except subprocess.TimeoutExpired:
            return False
        return True

    assert wait_until(ended), 'the judge script never ended'
    said = [line for line in out.splitlines() if line.startswith('subject said:')]
    assert len(said) == 2 and judge.returncode == 0, out
    assert all('the judge script ran' not in line for line in said), out
    assert f'parent {judge.pid}' in said[0] and f'parent {judge.pid}' not in said[1], out


SERVING_JUDGE = '''
import json, os, sys
from pathlib import Path
from ros2nb.subject.forked import serve_from_here
serve_from_here()  # as python -m ros2nb.judge does, first thing
sys.path.insert(0, sys.argv[2])
from test_forked_subjects import SUBJECT_PREFIX_ENV, view
forked, subject = view(Path(sys.argv[1]), os.getpid())
os.environ[SUBJECT_PREFIX_ENV] = json.dumps(['env'])  # a prefix: started afresh
started, _ = view(Path(sys.argv[1]), os.getpid())
print('SEEN', json.dumps([forked, started, subject.proc.wait(5)]))
'''


def test_a_judge_forks_even_its_first_subject_from_itself(tmp_path, monkeypatch):
    """A judge process forks its fork server from itself as it starts: its first subject is
    forked too, sees what a started one sees, and its exit code comes back."""
    monkeypatch.delenv('ROS_PYTHON_CHECK_FIELDS', raising=False)
    script = tmp_path / 'serving_judge.py'
    script.write_text(SERVING_JUDGE)
    judge = run_to_end([sys.executable, str(script), str(tmp_path), str(Path(__file__).parent)],
                       'a judge that serves its own subjects')
    lines = [line for line in judge.stdout.splitlines() if line.startswith('SEEN ')]
    assert len(lines) == 1, judge.stdout + judge.stderr
    forked, started, code = json.loads(lines[0][len('SEEN '):])
    assert not forked.pop('parent is the judge') and started.pop('parent is the judge')
    assert code == 0 and forked == started


#: main() of a learner's program that ends in each way a program can end.
ENDINGS = {
    'returns': 'def main():\n    print("done")\n',
    'returns 3': 'def main():\n    return 3\n',
    'sys.exit with text': 'import sys\n\ndef main():\n    sys.exit("stopped: no sensor")\n',
    'raises': 'def main():\n    raise ValueError("no such topic")\n',
    'Ctrl+C not caught': 'def main():\n    raise KeyboardInterrupt\n',
    'a thread and an exit handler': (
        'import atexit, threading, time\n\n'
        'def main():\n'
        '    atexit.register(print, "exit handler ran")\n'
        '    threading.Thread(target=lambda: (time.sleep(0.3), print("thread ended"))).start()\n'),
}


@pytest.mark.parametrize('ending', ENDINGS)
def test_a_forked_program_ends_as_a_started_one(tmp_path, monkeypatch, ending):
    """A learner's main() forked from the fork server (ros2nb.subject.program) ends as the
    same program started afresh: its exit code (a signal's too), its traceback's last line
    and what its threads and exit handlers print."""
    from ros2nb.judge.session import Session
    program = tmp_path / 'program.py'
    program.write_text(ENDINGS[ending])
    session = Session(tmp_path)
    seen = []
    try:
        for prefix in ('', json.dumps(['env'])):  # forked, then started afresh
            monkeypatch.setenv(SUBJECT_PREFIX_ENV, prefix)
            proc, output = session.start_program(program)
            code = proc.wait(30)
            lines = [line for line in output.text().splitlines()
                     if not line.startswith('  ')]  # a traceback's frames differ in their start
            seen.append((code, lines[:1] + lines[-2:]))
    finally:
        session.close()
    assert seen[0] == seen[1]
    assert ending != 'Ctrl+C not caught' or seen[0][0] == -signal.SIGINT


def test_a_subject_in_a_missing_folder_fails_as_a_started_one(tmp_path, monkeypatch):
    """Popen raises FileNotFoundError in the judge for a working folder that is not there; a
    fork does the same (the check then says the grader could not finish it), never a subject
    that just ended."""
    SubjectProcess(tmp_path).close()  # this process's first subject, if no test started one yet
    for prefix in ('', json.dumps(['env'])):  # forked, then started afresh
        monkeypatch.setenv(SUBJECT_PREFIX_ENV, prefix)
        with pytest.raises(FileNotFoundError):
            SubjectProcess(tmp_path / 'gone')


def test_a_fork_request_of_the_wrong_shape_is_refused_in_its_child(tmp_path):
    """The fork server's child reads its request as its type (ForkRequest), every field
    checked: a program's arguments sent as one string, not a list, are refused in the child's
    own output, naming the field, and it exits with 1.  Taken as it came, the string would
    have become ten arguments of one letter each (``list('program.py')``)."""
    planted = ForkRequest(module=PROGRAM, cwd=str(tmp_path), env=subject_env(),
                          site_path=forked._site_path(), args='program.py')
    read_output, write_output = os.pipe()
    try:
        pid, status = forked._started_server().fork((write_output,), planted)
    finally:
        os.close(write_output)
    child = forked.ForkedProcess(pid, os.fdopen(read_output), status, ['python'])
    assert child.wait(30) == 1
    said = child.stdout.read().splitlines()
    assert said[-1] == 'ros2nb.typed_json.Unreadable: ForkRequest.args is str, not list', said
