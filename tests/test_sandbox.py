"""ros2nb_instructor.grading.sandbox.bubblewrap with real processes: every protection next to the
failure it prevents.

Each probe also runs without the sandbox (or with the protection off) and must succeed
there, so a sandbox that protects nothing fails these tests.  ROS runs outside a network
namespace use ROS_DOMAIN_ID 150-160.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from ros2nb_instructor.grading.sandbox import bubblewrap
from ros2nb_instructor.grading.sandbox.bubblewrap import Limits, Sandbox
from waiting import PATIENCE_S

ROOT = Path(__file__).resolve().parent.parent
PROBLEM = bubblewrap.problem()
pytestmark = [pytest.mark.sandbox, pytest.mark.skipif(PROBLEM is not None, reason=str(PROBLEM))]
PY = sys.executable
ENV = {'PATH': '/usr/bin:/bin', 'HOME': '/tmp', 'LANG': 'C.UTF-8'}
DOMAIN = str(150 + os.getpid() % 11)
ROS_ENV = {**ENV, 'ROS_DOMAIN_ID': DOMAIN, 'ROS_AUTOMATIC_DISCOVERY_RANGE': 'LOCALHOST',
           'RCUTILS_COLORIZED_OUTPUT': '0'}

# 'pub' publishes on the topics; 'sub' prints how many messages it heard on each and the
# most publishers it discovered on each (discovery can cross where data does not).
ROS_PROBE = '''
import json, sys, time
import rclpy
from std_msgs.msg import String
mode, seconds, topics = sys.argv[1], float(sys.argv[2]), sys.argv[3:]
rclpy.init()
node = rclpy.create_node('probe')
heard, publishers = dict.fromkeys(topics, 0), dict.fromkeys(topics, 0)
if mode == 'pub':
    pubs = [node.create_publisher(String, t, 10) for t in topics]
    node.create_timer(0.05, lambda: [p.publish(String(data='x')) for p in pubs])
else:
    for t in topics:
        node.create_subscription(String, t, lambda m, t=t: heard.__setitem__(t, heard[t] + 1), 10)
end = time.monotonic() + seconds
while time.monotonic() < end:
    rclpy.spin_once(node, timeout_sec=0.05)
    for t in topics:
        publishers[t] = max(publishers[t], node.count_publishers(t))
if mode == 'sub':
    print(json.dumps({'heard': heard, 'publishers': publishers}), flush=True)
rclpy.try_shutdown()
'''


# Prints which processes carry the marker (given reversed, so that neither this probe nor
# a bwrap holding its argv carries it), whose /proc/PID/fd it can list, and what kill() did.
PID_PROBE = '''
import json, os, signal, sys
marker, target, sig = sys.argv[1][::-1], int(sys.argv[2]), int(sys.argv[3])
seen, fds = [], []
for pid in filter(str.isdigit, os.listdir('/proc')):
    try:
        if marker in open(f'/proc/{pid}/cmdline').read():
            seen.append(int(pid))
            os.listdir(f'/proc/{pid}/fd')
            fds.append(int(pid))
    except OSError:
        pass
try:
    os.kill(target, sig)
    kill = 'sent'
except OSError as error:
    kill = type(error).__name__
print(json.dumps({'seen': seen, 'fd': fds, 'kill': kill}))
'''


def plain(argv: list[str], env: dict[str, str] = ENV, **kw) -> subprocess.CompletedProcess:
    """The control: the same probe without any sandbox."""
    return subprocess.run(argv, env=env, capture_output=True, text=True, timeout=PATIENCE_S, **kw)


def boxed(box: Sandbox, argv: list[str],
          limits: Limits = Limits(wall_s=PATIENCE_S)) -> bubblewrap.Result:
    return box.run(argv, limits, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def python_code(code: str, *args: str) -> list[str]:
    return [PY, '-S', '-c', code, *args]


def test_a_trivial_sandbox_works_here():
    assert bubblewrap.problem() is None
    result = boxed(Sandbox(env=ENV), ['true'])
    assert (result.returncode, result.timed_out) == (0, False)
    assert {'wall', 'file-size'} <= set(result.limits_enforced)


def test_host_processes_are_invisible_and_cannot_be_signalled():
    marker = f'host-sleeper-{uuid.uuid4().hex}'
    sleeper = subprocess.Popen(python_code('import time; time.sleep(60)', marker))
    try:
        probe = python_code(PID_PROBE, marker[::-1], str(sleeper.pid), str(int(signal.SIGKILL)))
        inside = boxed(Sandbox(env=ENV), probe)
        assert json.loads(inside.stdout) == {'seen': [], 'fd': [], 'kill': 'ProcessLookupError'}
        assert sleeper.poll() is None
        outside = json.loads(plain(probe).stdout)
        assert outside == {'seen': [sleeper.pid], 'fd': [sleeper.pid], 'kill': 'sent'}
        assert sleeper.wait(PATIENCE_S) == -signal.SIGKILL
    finally:
        sleeper.kill()
        sleeper.wait()


NET_PROBE = '''
import json, socket, sys
udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
udp.bind(('127.0.0.1', 0))
udp.settimeout(2)
udp.sendto(b'ping', udp.getsockname())
try:
    socket.create_connection(('127.0.0.1', int(sys.argv[1])), timeout=2).close()
    host_port = 'connected'
except OSError as error:
    host_port = type(error).__name__
print(json.dumps({'interfaces': [n for _, n in socket.if_nameindex()],
                  'loopback_echo': udp.recv(4).decode(), 'host_port': host_port}))
'''


def test_network_is_loopback_only_and_host_ports_are_unreachable():
    with socket.create_server(('127.0.0.1', 0)) as server:
        probe = python_code(NET_PROBE, str(server.getsockname()[1]))
        inside = json.loads(boxed(Sandbox(env=ENV), probe).stdout)
        outside = json.loads(plain(probe).stdout)
    assert inside == {'interfaces': ['lo'], 'loopback_echo': 'ping',
                      'host_port': 'ConnectionRefusedError'}
    assert outside['host_port'] == 'connected'


def test_ros_traffic_stays_inside_the_sandbox(tmp_path):
    tmp_path.chmod(0o755)  # pytest makes it 0700: not readable for a sandbox started by root
    (tmp_path / 'ros_probe.py').write_text(ROS_PROBE)
    probe = [PY, str(tmp_path / 'ros_probe.py')]
    box = Sandbox(readable=[tmp_path], env=ROS_ENV, cwd=tmp_path)
    host_sub = subprocess.Popen([*probe, 'sub', '7', 'inside', 'outside'], env=ROS_ENV,
                                stdout=subprocess.PIPE, text=True)
    host_pub = subprocess.Popen([*probe, 'pub', '7', 'outside'], env=ROS_ENV)
    both = f'{PY} ros_probe.py pub 7 inside & {PY} ros_probe.py sub 6 inside outside; wait'
    inside = boxed(box, ['sh', '-c', both])
    outside = json.loads(host_sub.communicate(timeout=PATIENCE_S)[0])
    host_pub.wait(PATIENCE_S)
    assert outside['heard']['outside'] > 0, 'control: the host publisher must reach the host'
    # Discovery is the sharper probe: without a network namespace the host discovers the
    # sandboxed publisher, even though its data stays in the private /dev/shm.
    assert outside['publishers'] == {'inside': 0, 'outside': 1}, 'the host discovered the sandbox'
    assert outside['heard']['inside'] == 0, 'the sandboxed publisher reached the host'
    assert inside.returncode == 0, inside.stderr[-2000:]
    inside_sub = json.loads(inside.stdout.splitlines()[-1])
    assert inside_sub['heard']['inside'] > 0, 'two nodes in one sandbox must talk'
    assert inside_sub['publishers'] == {'inside': 1, 'outside': 0}
    assert inside_sub['heard']['outside'] == 0, 'the host publisher reached the sandbox'


FILE_PROBE = '''
import json, os, sys

def attempt(action, path):
    try:
        if action == 'read':
            return open(path).read() and 'ok'
        if action == 'list':
            return sorted(os.listdir(path))
        if action == 'append':
            open(path, 'a').write('x')
        elif action == 'create':
            open(path, 'x').write('x')
        elif action == 'open-for-write':
            open(path, 'r+').close()
        return 'ok'
    except OSError as error:
        return type(error).__name__

print(json.dumps({label: attempt(a, p) for label, a, p in json.loads(sys.argv[1])}))
'''


def test_files_hidden_read_only_and_scratch(tmp_path):
    course, scratch = tmp_path / 'course', tmp_path / 'scratch'
    (course / 'notebooks').mkdir(parents=True)
    (course / 'solutions').mkdir()
    (course / 'notebooks' / 'a.ipynb').write_text('{}')
    (course / 'solutions' / 'a.ipynb').write_text('secret')
    scratch.mkdir()
    (scratch / 'given.txt').write_text('from the grader')  # owned by the caller
    for path in (course, course / 'notebooks', course / 'notebooks' / 'a.ipynb'):
        path.chmod(0o777 if path.is_dir() else 0o666)  # only the read-only mount stops writes
    checks = {'course read': ('read', course / 'notebooks' / 'a.ipynb'),
              'course append': ('append', course / 'notebooks' / 'a.ipynb'),
              'course create': ('create', course / 'new.txt'),
              'hidden read': ('read', course / 'solutions' / 'a.ipynb'),
              'repository read': ('read', Path(bubblewrap.__file__)),
              'shadow read': ('read', '/etc/shadow'),
              'home list': ('list', Path.home()),
              'sysctl write': ('open-for-write', '/proc/sys/vm/swappiness'),
              'scratch append': ('append', scratch / 'given.txt'),
              'scratch create': ('create', scratch / 'made-inside.txt')}
    probe = python_code(FILE_PROBE, json.dumps([(k, a, str(p)) for k, (a, p) in checks.items()]))
    box = Sandbox(readable=[course], hidden=[course / 'solutions'], writable=[scratch], env=ENV)
    inside = json.loads(boxed(box, probe).stdout)
    # Only the folders leading to the bound Python installation show in the home folder.
    python_in_home = {p.relative_to(Path.home()).parts[0] for p in bubblewrap._python_paths()
                      if Path.home() in p.parents}
    assert inside == {
        'course read': 'ok', 'course append': 'OSError', 'course create': 'OSError',  # EROFS
        'hidden read': 'FileNotFoundError', 'repository read': 'FileNotFoundError',
        'shadow read': 'FileNotFoundError', 'home list': sorted(python_in_home),
        'sysctl write': 'PermissionError' if os.geteuid() == 0 else inside['sysctl write'],
        'scratch append': 'ok', 'scratch create': 'ok'}
    made = (scratch / 'made-inside.txt').stat().st_uid
    assert made == (bubblewrap.HOST_UID if os.geteuid() == 0 else os.getuid())
    # Control: outside, the same probe reads and writes all of it (run after the sandbox
    # so that its writes cannot hide a failure inside).
    outside = json.loads(plain(probe).stdout)
    assert all(outside[k] == 'ok' for k in list(checks)[:6]), outside
    assert len(outside['home list']) > len(python_in_home)
    if os.geteuid() == 0:
        assert outside['sysctl write'] == 'ok', 'control: root may open a global sysctl to write'


DAEMON = '''
import os, sys, time
if os.fork() == 0:
    os.setsid()
    if os.fork() == 0:
        null = os.open('/dev/null', os.O_RDWR)
        for fd in (0, 1, 2):
            os.dup2(null, fd)
        sleep = 'import time; time.sleep(120)'
        os.execv(sys.executable, [sys.executable, '-S', '-c', sleep, sys.argv[1]])
    os._exit(0)
os.wait()
time.sleep(0.5)
'''


def processes_with(marker: str) -> list[int]:
    found = []
    for pid in filter(str.isdigit, os.listdir('/proc')):
        try:
            if marker in Path(f'/proc/{pid}/cmdline').read_text():
                found.append(int(pid))
        except OSError:
            pass
    return found


def test_double_forked_daemon_dies_with_the_sandbox():
    marker = f'daemon-{uuid.uuid4().hex}'
    result = boxed(Sandbox(env=ENV), python_code(DAEMON, marker))
    assert result.returncode == 0
    assert processes_with(marker) == []
    # Control: without the sandbox the daemon lives on.
    subprocess.run(python_code(DAEMON, marker), env=ENV, timeout=60, stdin=subprocess.DEVNULL,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    survivors = processes_with(marker)
    for pid in survivors:
        os.kill(pid, signal.SIGKILL)
    assert survivors, 'control: the daemon should outlive its parent outside a sandbox'


def test_wall_time_kills_the_sandbox():
    started = time.monotonic()
    result = boxed(Sandbox(env=ENV), ['sleep', '3600'], Limits(wall_s=0.5))
    assert result.timed_out and result.returncode == -signal.SIGKILL
    assert time.monotonic() - started < PATIENCE_S  # killed, not left to sleep its hour
    control = boxed(Sandbox(env=ENV), ['sleep', '2'], Limits(wall_s=PATIENCE_S))
    assert (control.timed_out, control.returncode) == (False, 0)


#: A program that works 0.3 CPU-seconds, then ends.
WORKS = 'import time\nbegin = time.process_time()\nwhile time.process_time() - begin < 0.3: pass'


def test_wall_time_counts_no_time_the_machine_keeps_the_sandbox_from_running():
    """A sandbox held to a twentieth of a CPU (a CPU quota, ``Limits.cpu_share``) works 0.3
    CPU-seconds in 6 s or more: its wall-time limit of 1 s counts only what it worked and
    waited, not the time it stood ready for a CPU, so it ends on its own.  A wall clock
    alone cut it after 1 s: on a busy grading host, an honest notebook as a hang."""
    started = time.monotonic()
    result = boxed(Sandbox(env=ENV), python_code(WORKS), Limits(wall_s=1.0, cpu_share=0.05))
    if 'cpu(cgroup)' not in result.limits_enforced:
        pytest.skip('no CPU quota can be set here: nothing keeps the sandbox from running')
    assert (result.returncode, result.timed_out) == (0, False), result
    assert time.monotonic() - started > 1.0  # the failure prevented: past its wall time


class _BwrapWithoutDeathSignal(Sandbox):
    """bwrap as bubblewrap#633 leaves it when it is killed while setting up: its child has
    no parent-death signal yet, so it lives on after bwrap, running the program."""

    def command(self, argv, source=str):
        return [arg for arg in super().command(argv, source) if arg != '--die-with-parent']


def test_wall_time_kills_the_program_even_when_it_outlives_bwrap():
    running = _BwrapWithoutDeathSignal(env=ENV).start(
        ['sleep', '3600'], Limits(wall_s=0.5), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    try:
        if not running._cgroups:
            pytest.skip('no cgroup for the sandbox here: only bwrap is killed at its wall time')
        # Killing bwrap alone left `sleep` holding the pipes: this waited forever.
        running.process.communicate(timeout=PATIENCE_S)
    except subprocess.TimeoutExpired:
        pytest.fail(f'the program still held its pipes {PATIENCE_S} s after its wall time')
    finally:
        code = running.stop()
    assert running.timed_out and code == -signal.SIGKILL


#: Two processes that each keep a CPU busy for ever (a learner's thread that logs in a loop).
BUSY = 'import os\nos.fork()\nwhile True: pass'


def test_cpu_time_of_all_processes_together_kills_the_sandbox():
    result = boxed(Sandbox(env=ENV), python_code(BUSY), Limits(wall_s=PATIENCE_S, cpu_s=2))
    if 'cpu(cgroup)' not in result.limits_enforced:
        pytest.skip('no cgroup counts CPU time here: CPU time is limited per process only')
    assert result.out_of_cpu and not result.timed_out and result.returncode == -signal.SIGKILL
    assert result.cpu_s >= 2
    # The control: without the limit the same program burns its CPUs until the wall time.
    control = boxed(Sandbox(env=ENV), python_code(BUSY), Limits(wall_s=3))
    assert control.timed_out and not control.out_of_cpu and control.cpu_s > 0
    # CPU time, not wall time: a program that waits keeps running past the CPU limit's seconds.
    waiting = boxed(Sandbox(env=ENV), ['sleep', '2'], Limits(wall_s=PATIENCE_S, cpu_s=1))
    assert (waiting.returncode, waiting.out_of_cpu, waiting.timed_out) == (0, False, False)


def test_cpu_time_falls_back_to_a_limit_per_process(monkeypatch):
    monkeypatch.setattr(bubblewrap.cgroups_of, 'make_cgroups', lambda *limits: ([], []))
    started = time.monotonic()
    result = boxed(Sandbox(env=ENV), python_code('while True: pass'),
                   Limits(wall_s=PATIENCE_S, cpu_s=1))
    assert 'cpu(rlimit-cpu, per process)' in result.limits_enforced
    assert result.returncode != 0 and not result.timed_out and result.cpu_s is None
    assert time.monotonic() - started < PATIENCE_S


WRITE = 'import sys; open(sys.argv[1], "wb").write(bytes(2 << 20)); print("wrote")'


def test_file_size_limit(tmp_path):
    box = Sandbox(writable=[tmp_path], env=ENV)
    probe = python_code(WRITE, str(tmp_path / 'big'))
    small = boxed(box, probe, Limits(wall_s=PATIENCE_S, file_size_bytes=1 << 20))
    assert small.returncode != 0 and 'File too large' in small.stderr
    assert (tmp_path / 'big').stat().st_size <= 1 << 20
    control = boxed(box, probe, Limits(wall_s=PATIENCE_S, file_size_bytes=4 << 20))
    assert control.returncode == 0 and control.stdout.strip() == 'wrote'


FORKS = '''
import os, time
n = 0
try:
    for n in range(1, 61):
        if os.fork() == 0:
            time.sleep(30)
            os._exit(0)
except OSError as error:
    print(type(error).__name__, n)
else:
    print('forked', n)
'''


def test_pids_limit():
    box = Sandbox(env=ENV)
    limited = boxed(box, python_code(FORKS), Limits(wall_s=PATIENCE_S, pids=20))
    if 'pids(cgroup)' not in limited.limits_enforced:
        pytest.skip('no pids cgroup could be made here, so the number of tasks is not limited')
    assert limited.stdout.split()[0] == 'BlockingIOError' and int(limited.stdout.split()[1]) < 20
    control = boxed(box, python_code(FORKS), Limits(wall_s=PATIENCE_S, pids=200))
    assert control.stdout.strip() == 'forked 60'


def test_memory_limit():
    box = Sandbox(env=ENV)
    probe = python_code('data = b"x" * (400 << 20); print(len(data) >> 20)')
    limited = boxed(box, probe, Limits(wall_s=PATIENCE_S, memory_bytes=200 << 20))
    if 'memory(cgroup)' not in limited.limits_enforced:
        pytest.skip('no memory cgroup could be made here, so memory is limited per process only')
    assert limited.returncode != 0 and limited.stdout == ''
    control = boxed(box, probe, Limits(wall_s=PATIENCE_S, memory_bytes=1 << 30))
    assert (control.returncode, control.stdout.strip()) == (0, '400')


def test_start_talks_over_pipes_and_stop_removes_the_cgroup():
    read_end, write_end = os.pipe()
    echo = ('import os, sys; os.write(int(sys.argv[1]), b"fd ok"); '
            'print(input().upper(), flush=True); input()')
    running = Sandbox(env=ENV).start(python_code(echo, str(write_end)), Limits(wall_s=PATIENCE_S),
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     pass_fds=(write_end,), text=True)
    os.close(write_end)
    try:
        assert os.read(read_end, 5) == b'fd ok'
        running.process.stdin.write('hello\n')
        running.process.stdin.flush()
        assert running.process.stdout.readline() == 'HELLO\n'
        cgroups = list(running._cgroups)
        assert all(c.is_dir() for c in cgroups)
    finally:
        code = running.stop()
        os.close(read_end)
    assert code == -signal.SIGKILL and not running.timed_out
    assert not any(c.exists() for c in cgroups)


# Runs inside Sandbox(nested=True); starts subjects with the prefixes it is given.
JUDGE = '''
import json, os, subprocess, sys
prefixes, marker, folder = json.loads(sys.argv[1]), sys.argv[2], sys.argv[3]
code = {name: open(f'{folder}/{name}.py').read() for name in ('pid_probe', 'ros_probe')}
probe = [sys.executable, '-S', '-c', code['pid_probe'], marker[::-1], str(os.getpid()), '0']
subject = subprocess.run(prefixes['private'] + probe, capture_output=True, text=True)
control = subprocess.run(probe, capture_output=True, text=True)
ros = [sys.executable, '-c', code['ros_probe']]
listen = subprocess.Popen(ros + ['sub', '8', 'private', 'shared'], stdout=subprocess.PIPE,
                          text=True)
localhost = dict(os.environ, FASTDDS_BUILTIN_TRANSPORTS='DEFAULT',
                 ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
talkers = [subprocess.Popen(prefixes['private'] + ros + ['pub', '7', 'private'],
                            stderr=subprocess.PIPE, text=True),
           subprocess.Popen(prefixes['shared'] + ros + ['pub', '7', 'shared'], env=localhost,
                            stderr=subprocess.PIPE, text=True)]
print(json.dumps({'judge': os.getpid(), 'subject': subject.stdout or subject.stderr,
                  'control': control.stdout, 'heard': listen.communicate()[0],
                  'talkers': [(t.wait(), t.stderr.read()[-300:]) for t in talkers]}))
'''


def test_nested_subject_shares_network_but_not_pids(tmp_path):
    tmp_path.chmod(0o755)
    for name, text in [('judge', JUDGE), ('ros_probe', ROS_PROBE), ('pid_probe', PID_PROBE)]:
        (tmp_path / f'{name}.py').write_text(text)
    marker = f'judge-{uuid.uuid4().hex}'
    # Inside its own network namespace the judge needs no LOCALHOST range; UDPv4 because the
    # 'private' subject has its own /dev/shm (see bubblewrap.inner_prefix).
    env = {**ENV, 'ROS_DOMAIN_ID': '7', 'FASTDDS_BUILTIN_TRANSPORTS': 'UDPv4'}
    judge = Sandbox(readable=[tmp_path], env=env, nested=True)
    # What the judge receives, as JSON.
    prefixes = json.dumps({'private': bubblewrap.inner_prefix(),
                           'shared': bubblewrap.inner_prefix(share_shm=True)})
    result = boxed(judge, [PY, str(tmp_path / 'judge.py'), prefixes, marker, str(tmp_path)])
    report = json.loads(result.stdout)
    assert [code for code, _ in report['talkers']] == [0, 0], report['talkers']
    subject, control = json.loads(report['subject']), json.loads(report['control'])
    assert subject['seen'] == subject['fd'] == [], 'the subject saw the judge'
    assert report['judge'] in control['fd'], \
        'control: a plain child of the judge sees it and lists its /proc/PID/fd'
    heard = json.loads(report['heard'])['heard']
    assert heard['private'] > 0, 'UDPv4 between judge and a subject with its own /dev/shm'
    assert heard['shared'] > 0, 'default transports and LOCALHOST with a shared /dev/shm'


NOTEBOOK_CELL = """\
import os, rclpy
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import String
rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
node = rclpy.create_node('learner')
heard = []
node.create_subscription(String, 'chatter', lambda m: heard.append(m.data), 10)
pub = node.create_publisher(String, 'chatter', 10)
for _ in range(60):
    pub.publish(String(data='hi'))
    rclpy.spin_once(node, timeout_sec=0.05)
print('heard', bool(heard), 'uid', os.getuid())
"""


def test_grader_recipe_executes_a_notebook_writing_only_scratch(tmp_path):
    """The grader's use: the course readable, a scratch folder for the kernel's files."""
    nbformat = pytest.importorskip('nbformat')
    tmp_path.chmod(0o755)
    course, scratch = tmp_path / 'course', tmp_path / 'scratch'
    course.mkdir()
    scratch.mkdir()
    nbformat.write(nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(NOTEBOOK_CELL)]),
                   course / 'learner.ipynb')
    venv_bin = Path(sys.executable).parent
    env = {**ROS_ENV, 'PATH': f'{venv_bin}:/usr/bin:/bin', 'HOME': str(scratch),
           'JUPYTER_RUNTIME_DIR': str(scratch / 'runtime'), 'IPYTHONDIR': str(scratch / 'ipython'),
           'MPLCONFIGDIR': str(scratch / 'mpl'), 'ROS_HOME': str(scratch / 'ros')}
    box = Sandbox(readable=[course], writable=[scratch], env=env, cwd=scratch)
    executed = scratch / 'learner.ipynb'
    result = boxed(box, [str(venv_bin / 'jupyter'), 'execute', '--output', str(executed),
                         str(course / 'learner.ipynb')], Limits(wall_s=PATIENCE_S))
    assert result.returncode == 0, result.stderr[-2000:]
    outputs = nbformat.read(executed, as_version=4).cells[0].outputs
    assert [o.get('text') for o in outputs] == ['heard True uid 1000\n']
