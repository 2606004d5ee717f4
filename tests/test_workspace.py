"""Workspace verbs with the real colcon, real setup.bash and real processes."""

import importlib
import json
import os
import re
import shutil
import subprocess
import sys

import pytest

import ros2nb
from ros2nb import course
from ros2nb.terminal.workspace import shown

ws_module = importlib.import_module('ros2nb.terminal.workspace')
run_module = importlib.import_module('ros2nb.terminal.run')

TUTORIAL_MAIN = '''
import rclpy
from rclpy.node import Node


def main():
    rclpy.init()
    node = Node('tutorial_style')
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.shutdown()


main()
'''


@pytest.fixture(scope='module')
def built(tmp_path_factory):
    """A workspace with the course's package, reference nodes, entry points, built once."""
    root = tmp_path_factory.mktemp('course')
    os.environ[ws_module.WORKSPACE_ENV] = str(root / 'ws')
    ws_module._current = None
    ws = course.catch_up(5)
    setup_py = ws / 'src' / 'sensor_simulator' / 'setup.py'
    text = setup_py.read_text()
    entry = ("'console_scripts': [\n"
             "            'temperature_publisher = "
             "sensor_simulator.temperature_publisher:main',\n"
             "            'temperature_subscriber = "
             "sensor_simulator.temperature_subscriber:main',\n"
             "        ],")
    assert "'console_scripts': [\n        ]," in text
    ros2nb.write_file(setup_py, text.replace("'console_scripts': [\n        ],", entry))
    ros2nb.colcon_build()
    yield ws


def test_create_workspace_like_mkdir_p(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(ws_module.WORKSPACE_ENV, str(tmp_path / 'ws'))
    ws = ros2nb.create_workspace()
    assert ws == tmp_path / 'ws'
    for folder in ('src', 'docs', 'scripts', 'resources/images'):
        assert (ws / folder).is_dir()
    (ws / 'src' / 'mine.txt').write_text('keep me')
    assert ros2nb.create_workspace() == ws  # twice is harmless
    assert (ws / 'src' / 'mine.txt').read_text() == 'keep me'


def test_create_workspace_refuses_outside_course(tmp_path):
    with pytest.raises(ros2nb.Ros2nbError, match='allow_outside_course=True'):
        ros2nb.create_workspace(tmp_path / 'elsewhere')
    assert not (tmp_path / 'elsewhere').exists()
    assert ros2nb.create_workspace(tmp_path / 'elsewhere', allow_outside_course=True).is_dir()


def test_create_workspace_file_in_the_way(tmp_path):
    (tmp_path / 'ws').mkdir()
    (tmp_path / 'ws' / 'src').write_text('not a folder')
    with pytest.raises(ros2nb.Ros2nbError, match='is a file, not a folder'):
        ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)


def test_write_file_never_overwrites_learner_edits(tmp_path):
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    target = ros2nb.write_file('scripts/demo.py', 'print(1)\n')
    assert ros2nb.write_file('scripts/demo.py', 'print(2)\n') == target  # ours: replaced
    target.write_text('print("my edit")\n')
    with pytest.raises(ros2nb.FileProtectedError, match='overwrite=True'):
        ros2nb.write_file('scripts/demo.py', 'print(3)\n')
    assert target.read_text() == 'print("my edit")\n'
    ros2nb.write_file('scripts/demo.py', 'print(3)\n', overwrite=True)
    assert target.read_text() == 'print(3)\n'
    assert target.with_name('demo.py.bak').read_text() == 'print("my edit")\n'


def test_write_part_joins_parts_in_order(tmp_path, capsys):
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    ros2nb.write_part('scripts/parts.py', 2, 'b = 2\n')
    path = ros2nb.write_part('scripts/parts.py', 1, 'a = 1\n')
    ros2nb.write_part('scripts/parts.py', 2, 'b = 3\n')  # re-running a part replaces it
    assert path.read_text() == 'a = 1\n\nb = 3\n'
    assert 'ws/scripts/parts.py: part 2 saved (parts 1, 2; 3 lines)' in capsys.readouterr().out


def test_missing_parts_of_a_record_the_learner_wrote_by_hand(tmp_path):
    """The judge reads the workspace's parts record, which the learner's code may write.
    A part numbered 10**9 made it list a billion numbers (the judge ran out of time); a
    record of another shape ended it with a traceback. Now: ten numbers, or none."""
    from ros2nb.terminal.files import PARTS_RECORD, missing_parts

    record = tmp_path / PARTS_RECORD
    record.write_text(json.dumps({'f.py': {'1': 'a', '3': 'c', str(10 ** 9): 'z'}}))
    assert missing_parts(tmp_path, 'f.py') == [2, 4, 5, 6, 7, 8, 9, 10, 11, 12]
    for odd in ([1, 2], {'f.py': [None]}, {'f.py': {'one': 'a'}}, {'f.py': 'x'}):
        record.write_text(json.dumps(odd))
        assert missing_parts(tmp_path, 'f.py') == []


PART_IN_A_NEW_KERNEL = """
import os, sys
import ros2nb
ros2nb.create_workspace(sys.argv[1], allow_outside_course=True)
ros2nb.write_part('scripts/parts.py', 2, 'part2 = "again"\\n')
"""


def test_parts_survive_a_kernel_restart(tmp_path, capsys):
    """Three parts, a restart (a new process), then part 2 alone again: all three stay."""
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    for number in (1, 2, 3):
        path = ros2nb.write_part('scripts/parts.py', number, f'part{number} = {number}\n')
    done = subprocess.run([sys.executable, '-c', PART_IN_A_NEW_KERNEL, str(tmp_path / 'ws')],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert path.read_text() == 'part1 = 1\n\npart2 = "again"\n\npart3 = 3\n'
    assert 'part 2 saved (parts 1, 2, 3; 5 lines)' in done.stdout


def test_write_part_never_overwrites_an_edited_file(tmp_path):
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    path = ros2nb.write_part('scripts/parts.py', 1, 'a = 1\n')
    path.write_text('a = 1\nmine = True\n')  # edited in JupyterLab's editor
    with pytest.raises(ros2nb.FileProtectedError, match='add --overwrite to the %%part line'):
        ros2nb.write_part('scripts/parts.py', 2, 'b = 2\n')
    assert path.read_text() == 'a = 1\nmine = True\n'
    ros2nb.write_part('scripts/parts.py', 2, 'b = 2\n', overwrite=True)
    assert path.with_name('parts.py.bak').read_text() == 'a = 1\nmine = True\n'


def test_part_markers_of_the_course_are_left_out(tmp_path):
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    path = ros2nb.write_part('scripts/m.py', 1, 'x = 1\n### BEGIN SOLUTION\ny = 2\n'
                                               '### END SOLUTION\n')
    assert path.read_text() == 'x = 1\ny = 2\n'


@pytest.mark.ros
def test_colcon_build_installs_entry_points(built):
    lib = built / 'install' / 'sensor_simulator' / 'lib' / 'sensor_simulator'
    assert sorted(p.name for p in lib.iterdir()) == ['temperature_publisher',
                                                     'temperature_subscriber']


@pytest.mark.ros
def test_colcon_build_failure_names_cause(built, capsys):
    with pytest.raises(ros2nb.ColconBuildError, match='found no package'):
        ros2nb.colcon_build('--packages-select', 'no_such_package')
    setup_py = built / 'src' / 'sensor_simulator' / 'setup.py'
    good = setup_py.read_text()
    try:
        setup_py.write_text(good + '\nsetup(\n')  # a learner's unfinished edit
        with pytest.raises(ros2nb.ColconBuildError, match='SyntaxError'):
            ros2nb.colcon_build('--packages-select', 'sensor_simulator')
    finally:
        setup_py.write_text(good)


@pytest.mark.ros
def test_source_workspace_adds_prefix(built, capsys):
    env = ros2nb.source_workspace(show=True)
    assert str(built / 'install' / 'sensor_simulator') in env['AMENT_PREFIX_PATH'].split(':')
    assert 'AMENT_PREFIX_PATH: added ws/install/sensor_simulator' in capsys.readouterr().out


@pytest.mark.ros
def test_ros2_run_errors_match_cli(built):
    with pytest.raises(ros2nb.Ros2nbError, match=r"^Package 'no_such_pkg' not found$"):
        ros2nb.ros2_run(('no_such_pkg', 'x'))
    with pytest.raises(ros2nb.Ros2nbError, match='^No executable found$'):
        ros2nb.ros2_run(('sensor_simulator', 'no_such_exe'))


@pytest.mark.ros
def test_ros2_run_two_processes_and_ctrl_c(built, capsys):
    codes = ros2nb.ros2_run(('sensor_simulator', 'temperature_publisher'),
                            ('sensor_simulator', 'temperature_subscriber'), seconds=4)
    out = capsys.readouterr().out
    assert codes == [0, 0]
    assert '[temperature_publisher-1] [INFO] [temperature_sensor]: Publishing:' in out
    assert '[temperature_subscriber-2] [INFO] [temperature_monitor]: Temperature:' in out
    assert '^C' in out and 'Traceback' not in out


#: A node with notebook 08's threshold, a double, given on its command line as ros2 run does.
THRESHOLD_NODE = """
import sys
import rclpy
from rclpy.node import Node
rclpy.init(args=sys.argv)
node = Node('temperature_monitor')
node.declare_parameter('high_above_c', 26.0)
"""


@pytest.mark.ros
def test_a_parameter_of_the_wrong_type_gets_its_fix_after_the_traceback(capsys):
    """08: `-p high_above_c:=25` makes an integer of a double parameter; the node's traceback
    through rclpy ended the cell with `exited with code 1` and nothing after it."""
    codes = ros2nb.run_and_interrupt([sys.executable, '-c', THRESHOLD_NODE, '--ros-args', '-p',
                                      'high_above_c:=25'], labels=['temperature_subscriber'])
    out = capsys.readouterr().out.strip().splitlines()
    assert codes == [1] and out[-2] == 'temperature_subscriber exited with code 1', out
    assert out[-1] == ("temperature_subscriber: the parameter 'high_above_c' holds a double (its "
                       "default decides), and '25' is an integer: give it 25.0, e.g. -p "
                       'high_above_c:=25.0.'), out


@pytest.mark.ros
def test_a_room_without_its_slash_is_named_by_the_graph_at_once(built, ros):
    """06: a room's nodes started with `-r __ns:=kitchen` end at once; the graph's wait says
    why (rcl's own line is 'Expected lexeme type 19, got 18'), not a minute later."""
    started = [ros2nb.ros2_start('sensor_simulator', executable, '--ros-args', '-r',
                                 '__ns:=kitchen')
               for executable in ('temperature_publisher', 'temperature_subscriber')]
    try:
        with pytest.raises(ros2nb.Ros2nbError) as caught:
            ros2nb.graph_edges(expect=['/kitchen/temperature_sensor'])
    finally:
        for node in started:
            node.stop()
    said = str(caught.value)
    assert said.startswith('The graph shows no node /kitchen/temperature_sensor with a topic: '
                           'temperature_publisher exited with code '), said
    assert ("ROS could not read the remap rule '-r __ns:=kitchen': a namespace starts with a "
            'slash: __ns:=/kitchen.') in said and 'lexeme' not in said, said


@pytest.mark.ros
def test_missing_setup_cfg_gives_no_executable(built, tmp_path):
    scratch = tmp_path / 'nocfg'
    shutil.copytree(built / 'src' / 'sensor_simulator', scratch / 'src' / 'sensor_simulator')
    (scratch / 'src' / 'sensor_simulator' / 'setup.cfg').unlink()
    ros2nb.colcon_build(workspace_path=scratch)
    with pytest.raises(ros2nb.Ros2nbError, match='^No executable found$'):
        ros2nb.ros2_run(('sensor_simulator', 'temperature_publisher'), workspace_path=scratch)


@pytest.mark.ros
def test_import_file_reloads(built):
    path = 'scripts/reloaded.py'
    ros2nb.write_file(path, 'VALUE = 1\n')
    assert ros2nb.import_file(path).VALUE == 1
    ros2nb.write_file(path, 'VALUE = 2\n')
    assert ros2nb.import_file(path).VALUE == 2  # re-running the cell picks up the edit
    with pytest.raises(ros2nb.Ros2nbError, match='does not exist'):
        ros2nb.import_file('src/nothing.py')


@pytest.mark.ros
def test_processes_inherit_the_kernels_domain(built, capsys):
    from ros2nb import domains
    domain = domains.domain_id()
    ros2nb.run_and_interrupt([sys.executable, '-c',
                              'import os; print(os.environ["ROS_DOMAIN_ID"])'],
                             seconds=5)
    assert capsys.readouterr().out.splitlines()[0] == str(domain)


SLOW_START = """
import time
time.sleep(2)  # a program still starting (imports, discovery) on a busy machine
print('ready', flush=True)
try:
    while True:
        time.sleep(0.05)
except KeyboardInterrupt:
    print('stopped cleanly', flush=True)
"""


@pytest.mark.ros
def test_ctrl_c_waits_until_every_process_has_started(capsys):
    """Ctrl+C's countdown starts once a process has printed its first line: before, 1 s
    after launch it landed in the start-up and the program died with a traceback."""
    codes = ros2nb.run_and_interrupt([sys.executable, '-c', SLOW_START], seconds=1)
    out = capsys.readouterr().out
    assert codes == [0], out
    assert out.index('ready') < out.index('^C') < out.index('stopped cleanly')


#: A program whose clean-up after Ctrl+C takes 0.8 s of CPU on a CPU it shares with a burner:
#: longer than that on the wall clock, as on a busy machine.  The burner is its own
#: grandchild: in its session, so that Linux's autogroup scheduling shares the CPU between the
#: two (a burner of another session shares it with that session instead, and a busy machine
#: gave the program most of the CPU), but outside its tree, whose CPU time Patience counts.
#: It ignores the Ctrl+C and ends when the program has ended.
SLOW_EXIT = """
import os, signal, sys, time
os.sched_setaffinity(0, {int(sys.argv[1])})
program = os.getpid()
if os.fork() == 0:
    if os.fork() == 0:
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, 1)
        os.dup2(null, 2)
        while True:
            try:
                os.kill(program, 0)
            except OSError:
                os._exit(0)
    os._exit(0)
os.wait()
try:  # Ctrl+C may come as soon as 'ready' is out
    print('ready', flush=True)
    while True:
        time.sleep(0.05)
except KeyboardInterrupt:
    began, cpu = time.monotonic(), time.process_time()
    while time.process_time() - cpu < 0.8:
        pass
    print(f'stopped cleanly after {time.monotonic() - began:.2f} s', flush=True)
"""


@pytest.mark.ros
def test_a_slow_exit_after_ctrl_c_is_waited_for_while_it_works(capsys, monkeypatch):
    """After Ctrl+C a program that works on its way out is waited for (patience.Patience),
    not pressed again: with a fixed grace on the wall clock (here 1 s), the second Ctrl+C
    landed in its clean-up, and it printed a traceback and another exit code."""
    monkeypatch.setattr(run_module, 'STOP_GRACE_S', 1.0)
    cpu = min(os.sched_getaffinity(0))
    codes = ros2nb.run_and_interrupt([sys.executable, '-c', SLOW_EXIT, str(cpu)], seconds=0)
    out = capsys.readouterr().out
    assert codes == [0] and 'Traceback' not in out, out
    took = float(re.search(r'stopped cleanly after ([\d.]+) s', out).group(1))
    assert took > 1.0  # the failure prevented: the grace on the wall clock ran out first


@pytest.mark.ros
def test_ros2_run_defers_to_a_real_ros2_on_path(built, tmp_path, monkeypatch, capsys):
    """With a `ros2` on PATH, `ros2 run` itself is started (a recording stand-in shows it)."""
    stub = tmp_path / 'ros2'
    stub.write_text('#!/bin/sh\necho "real ros2 called with: $@"\n')
    stub.chmod(0o755)
    monkeypatch.setenv('PATH', f'{tmp_path}{os.pathsep}{os.environ["PATH"]}')
    assert ros2nb.ros2_run(('sensor_simulator', 'temperature_publisher'), seconds=1) == [0]
    assert 'real ros2 called with: run sensor_simulator temperature_publisher' in \
        capsys.readouterr().out


def test_catch_up_says_what_it_created(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(ws_module.WORKSPACE_ENV, str(tmp_path / 'ws'))
    monkeypatch.setattr(ws_module, '_current', None)
    course.catch_up(3)
    last = capsys.readouterr().out.splitlines()[-1]  # after pkg create's own output
    assert last == 'Caught up: created ws, ws/src/sensor_simulator'  # 03 writes the publisher
    course.catch_up(3)
    assert capsys.readouterr().out.startswith('Nothing to catch up')


def test_catch_up_never_writes_course_nodes_while_grading(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv(ws_module.WORKSPACE_ENV, str(tmp_path / 'ws'))
    monkeypatch.setattr(ws_module, '_current', None)
    monkeypatch.setenv(course.GRADING_ENV, '1')
    ws = course.catch_up(5)
    assert not (ws / course.PUBLISHER_FILE).exists() and not (ws / course.SUBSCRIBER_FILE).exists()
    assert capsys.readouterr().out.splitlines()[-1] == (
        'Not created: temperature_publisher.py, temperature_subscriber.py (only your own nodes '
        'count here); the cells that use them will fail until you write them.')


def test_notebook_05s_unwritten_answers_never_replace_the_working_package_files(tmp_path, capsys):
    """05's answer cells run unedited keep 02's setup.py and setup.cfg; --overwrite
    replaces them."""
    import nbformat
    ros2nb.create_workspace(tmp_path / 'ws', allow_outside_course=True)
    ros2nb.pkg_create(course.PACKAGE, destination=tmp_path / 'ws' / 'src',
                      dependencies=list(course.DEPENDENCIES))
    files = {'{SETUP_PY}': course.SETUP_PY_FILE, '{SETUP_CFG}': course.SETUP_CFG_FILE}
    notebook = nbformat.read(os.path.join(os.path.dirname(__file__), '..', 'notebooks',
                                          '05-entry-points-and-run.ipynb'), as_version=4)
    answers = [c.source for c in notebook.cells if c.source.startswith('%%part ')]
    assert len(answers) == 2
    working = {name: (tmp_path / 'ws' / name).read_text() for name in files.values()}
    capsys.readouterr()
    for answer in answers:
        first, _, body = answer.partition('\n')
        _, name, number = first.split()
        ros2nb.write_part(files[name], int(number), body)
        assert (tmp_path / 'ws' / files[name]).read_text() == working[files[name]]
    said = capsys.readouterr().out.splitlines()
    assert said == [f'{shown(tmp_path / "ws" / name)} was not changed: this cell still holds '
                    'the placeholder "raise NotImplementedError()", which would replace the '
                    'working version; write your answer in its place and run the cell again '
                    '(to replace it on purpose, add --overwrite to the %%part line).'
                    for name in files.values()]
    # the failure it prevents: the same write on purpose puts the placeholder in
    first, _, body = answers[1].partition('\n')
    ros2nb.write_part(files['{SETUP_CFG}'], 1, body, overwrite=True)
    assert 'raise NotImplementedError()' in (tmp_path / 'ws' / course.SETUP_CFG_FILE).read_text()
