"""How long the judge waits for a subject: work counts, not the wall clock.

A subject that computes slowly because the machine is busy is not hanging; one that loops
for ever or waits for ever is, and its learner hears so in one line.  The slow worker below
gets about a third of a CPU, as a subject does beside two CPU-bound programs: a limit on the
wall clock alone (the judge's old one) would have called it hung.
"""

import os
import subprocess
import sys
import threading
import time

import pytest

from ros2nb.judge import observer
from ros2nb.judge.subjects import SubjectHung, SubjectProcess
from ros2nb.errors import NotDecided
from ros2nb.subject.judge_time import Acknowledgement
from ros2nb.subject_interface import Call, ExecCells, NewNode
from ros2nb.subject_replies import Called, Encoded, Output
from ros2nb.typed_json import Unreadable, decoded
from ros2nb.patience import BUSY_SHARE, LOOK_S, Patience, tree_cpu_seconds, wait_for_work
from waiting import PATIENCE_S, run_to_end, starved, wait_until

pytestmark = pytest.mark.judge

#: Seconds the subject is given in these tests.
LIMIT_S = 2.0

CELLS = '''
import time

def slow_but_honest(cpu_s):
    """Work for cpu_s CPU seconds, a third of the time (a busy machine's share)."""
    start = time.process_time()
    while time.process_time() - start < cpu_s:
        burst = time.process_time()
        while time.process_time() - burst < 0.02:
            pass
        time.sleep(0.04)
    return 'done'

def loops_for_ever():
    while True:
        pass

def waits_for_ever():
    time.sleep(3600)
'''


@pytest.fixture
def subject(tmp_path):
    process = SubjectProcess(tmp_path)
    assert process.request(ExecCells(sources=[CELLS])).cell_errors == []
    yield process
    process.close()


def call(subject: SubjectProcess, name: str, *arguments) -> tuple[Called, float]:
    began = time.monotonic()
    reply = subject.request(Call(name=name, inputs=[list(arguments)]), timeout=LIMIT_S)
    return reply, time.monotonic() - began


def test_slow_honest_work_on_a_busy_machine_is_not_a_hang(subject):
    reply, waited = call(subject, 'slow_but_honest', 0.75 * LIMIT_S)
    assert reply.outputs == [Output(result=Encoded(type='str', value='done'))]
    assert waited > LIMIT_S  # the failure prevented: a wall-clock limit would have cut it


def test_an_endless_loop_is_cut_once_it_used_the_limit_in_cpu_time(subject):
    with pytest.raises(SubjectHung, match=r'^Your code did not finish within 2 s \(an endless '
                                          r'loop, or a call that waits for ever\?\): look for a '
                                          r'loop that never ends in the part you wrote\.$'):
        call(subject, 'loops_for_ever')


def test_a_call_that_waits_for_ever_is_cut_after_the_limit_on_the_wall_clock(subject):
    began = time.monotonic()
    with pytest.raises(SubjectHung, match=r'^Your code did not finish within 2 s'):
        call(subject, 'waits_for_ever')
    assert time.monotonic() - began >= LIMIT_S


STARVED = """
import os, sys
os.sched_setaffinity(0, {int(sys.argv[1])})
os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
print('starved', flush=True)
while True:
    pass
"""


#: A node class, in a cell of its own, for the judge's clock test below.
NODE_CELL = """
from rclpy.node import Node

class Quiet(Node):
    def __init__(self):
        super().__init__('quiet')
"""


def test_a_subject_that_waits_idle_for_the_judges_clock_is_not_decided(tmp_path):
    """A subject's new runtime waits for its judge's first /clock (its time), and says so on
    the judge's pipe.  When that never comes, the learner's code has not run yet: the check
    could not decide, and says so; it once blamed the learner's code for not finishing.
    Here no judge publishes a clock at all."""
    process = SubjectProcess(tmp_path)
    try:
        assert process.request(ExecCells(sources=[NODE_CELL])).cell_errors == []
        with pytest.raises(NotDecided, match="^the grader's clock never reached the process "
                                             'that runs your code$'):
            process.request(NewNode(cls='Quiet', stand_ins=[], args=[]), timeout=LIMIT_S)
    finally:
        process.close()


#: Learner code that writes two acknowledgements on its subject's pipe to the judge: one as the
#: subject writes them, then one whose count of /temperature is no number.
PLANTS_ACKNOWLEDGEMENTS = """
import os
from ros2nb.subject.judge_time import JudgeTime
os.write(JudgeTime.pipe(), b'{"t": 5, "wants": null, "published": {}, "logged": {}}\\n')
os.write(JudgeTime.pipe(), b'{"t": 7, "wants": 9, "published": {"/temperature": "all"}, '
                           b'"logged": {}}\\n')
"""


def test_an_acknowledgement_of_the_wrong_shape_is_skipped(tmp_path):
    """What a subject says on the judge's pipe is read as its type (Acknowledgement), every
    field checked: a line the learner's code wrote there with a count that is no number is
    refused, naming the field, and the judge keeps the last one it could read.  Taken as
    it came, that count would meet the judge's own counts and raise a TypeError there."""
    planted = {'t': 7, 'wants': 9, 'published': {'/temperature': 'all'}, 'logged': {}}
    with pytest.raises(Unreadable, match=r"^Acknowledgement\.published\['/temperature'\] is "
                                         r"str, not int$"):
        decoded(Acknowledgement, planted)
    process = SubjectProcess(tmp_path)
    try:
        assert process.request(ExecCells(sources=[PLANTS_ACKNOWLEDGEMENTS])).cell_errors == []
        assert process.last_ack == Acknowledgement(t=5, wants=None, published={}, logged={})
    finally:
        process.close()



def test_a_program_the_scheduler_starves_is_working_not_waiting():
    """A program that stands ready on the run queue while others hold the CPU is not waiting
    for ever. Beside CPU burners and a test run, a learner's main() stood queued for most of
    its first seconds, and was told it never started its node (docs/decisions.md).
    Here a program of the lowest scheduling class shares one CPU with a burner."""
    cpu = min(os.sched_getaffinity(0))
    burner = subprocess.Popen([sys.executable, '-c', 'import os\nos.sched_setaffinity(0, {%d})\n'
                               'while True: pass' % cpu])
    starved = subprocess.Popen([sys.executable, '-c', STARVED, str(cpu)], text=True,
                               stdout=subprocess.PIPE)
    try:
        assert starved.stdout.readline() == 'starved\n'
        patience, cpu_before = Patience(starved.pid, LIMIT_S / 4), tree_cpu_seconds(starved.pid)
        began = time.monotonic()
        while time.monotonic() - began < LIMIT_S:
            assert not patience.exhausted(), 'a program starved of CPU was taken for one that waits'
            time.sleep(0.1)
        # the failure prevented: counted by its CPU time alone, it sat waiting
        assert tree_cpu_seconds(starved.pid) - cpu_before < BUSY_SHARE * LIMIT_S
    finally:
        for process in (burner, starved):
            process.kill()
            process.wait()


#: A program under a CPU quota: it works WORK_S seconds of CPU (far longer on the wall
#: clock), says so, waits a moment, says so, and then waits for ever.
WORKS_WAITS_AND_HANGS = """
import sys, time
print('started', flush=True)
begin = time.process_time()
while time.process_time() - begin < float(sys.argv[1]):
    pass
print('worked', flush=True)
time.sleep(float(sys.argv[2]))
print('waited', flush=True)
time.sleep(3600)
"""
#: The CPU share of a starved program here: 0.05 CPU-seconds of work take at least 2.5 s.
STARVED_SHARE = 0.02


def test_a_wait_lasts_while_its_program_works_and_counts_only_its_idle_time():
    """The one wait for what processes do (``wait_for_work``): a line that a starved program
    is slow to print is waited for well past the limit on the wall clock, a short wait
    after its work is not its limit's end, and a program that waits for ever is given up
    after the limit of idle time.  The program gets a fiftieth of a CPU (a cgroup quota):
    slow for certain, however idle or busy the machine."""
    limit = 1.5
    with starved(STARVED_SHARE) as admit:
        program = subprocess.Popen([sys.executable, '-c', WORKS_WAITS_AND_HANGS, '0.05',
                                    str(limit / 2)], text=True, stdout=subprocess.PIPE)
        admit(program.pid)
        lines: list[str] = []
        threading.Thread(target=lambda: lines.extend(program.stdout), daemon=True).start()
        try:
            assert wait_until(lambda: 'started\n' in lines)
            began = time.monotonic()
            assert wait_for_work(lambda: 'worked\n' in lines, [program.pid], limit)
            worked = time.monotonic() - began
            assert worked > limit  # the failure prevented: a wall-clock wait gave up before it
            assert wait_for_work(lambda: 'waited\n' in lines, [program.pid], limit)
            began = time.monotonic()
            assert not wait_for_work(lambda: 'never\n' in lines, [program.pid], limit)
            assert time.monotonic() - began >= limit
        finally:
            program.kill()
            program.wait()


#: A program that says it is ready, then waits for a line on its input and says it got it.
WAITS_FOR_A_LINE = "print('ready', flush=True)\ninput()\nprint('got it', flush=True)\n"


#: CPU seconds the starved watcher works before it answers.
ANSWER_WORK_S = 0.1


@pytest.mark.parametrize('answered', [True, False], ids=['answered', 'never answered'])
def test_a_program_that_waits_for_its_starved_watcher_is_not_idle(answered):
    """What a subject waits for may be its judge's own work (its clock, its answers, its
    discovery messages): time the machine keeps the judge's threads from running is not the
    subject's idle time.  Here the watcher's own thread that must answer gets a fiftieth of
    a CPU and works 0.1 CPU-seconds first; the program sits idle meanwhile, five times its
    limit on the wall clock (what the watcher's looks miss: the first look's length, and what
    the answering thread stood ready after the last look before it ended).  Counted as its
    idle time, the wait gave up before the answer came (a subject made beside a busy judge
    was told its code did not finish).  A program nobody answers is still given up after
    its limit of idle time."""
    limit = 1.0
    program = subprocess.Popen([sys.executable, '-c', WAITS_FOR_A_LINE], text=True,
                               stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    lines: list[str] = []
    threading.Thread(target=lambda: lines.extend(program.stdout), daemon=True).start()

    def answer() -> None:
        admit(threading.get_native_id())
        begin = time.thread_time()  # this thread's own work: the worker's others work too
        while time.thread_time() - begin < ANSWER_WORK_S:
            pass
        program.stdin.write('go\n')
        program.stdin.flush()

    try:
        assert wait_until(lambda: 'ready\n' in lines)
        with starved(STARVED_SHARE) as admit:
            answering = threading.Thread(target=answer if answered else lambda: None,
                                         daemon=True)
            began = time.monotonic()
            answering.start()
            got = wait_for_work(lambda: 'got it\n' in lines, [program.pid], limit)
            waited = time.monotonic() - began
            answering.join()
        if answered:
            assert got and waited > limit, waited  # the failure prevented: given up at limit
        else:
            assert not got and waited >= limit
    finally:
        program.kill()
        program.wait()


WATCHER = """
import subprocess, sys, threading, time, zlib
from ros2nb.patience import Patience

def compress_for_ever(data=bytes(range(256)) * 4096):
    while True:
        zlib.compress(data, 9)  # in C, without the GIL: this thread runs or stands ready

threading.Thread(target=compress_for_ever, daemon=True).start()
limit, cut = float(sys.argv[1]), float(sys.argv[2])
sleeper = subprocess.Popen([sys.executable, '-c', 'import time\\nprint("asleep", flush=True)\\n'
                            'time.sleep(3600)'], stdout=subprocess.PIPE, text=True)
sleeper.stdout.readline()  # its start is work (a busy machine queues it): watch it asleep
began = time.monotonic()
patience = Patience(sleeper.pid, limit, started=began)  # one start for both: no rounding
while not (gave_up := patience.exhausted()) and time.monotonic() - began < cut * limit:
    time.sleep(0.1)
print('gave up' if gave_up else 'still waiting', time.monotonic() - began)
sleeper.kill()
"""
#: Where the watcher stops waiting for Patience itself (times the limit): the failure
#: prevented stood ready in every look, so it never gave up.  Generous: what the machine
#: keeps the watcher's thread from running is not the program's idle time, so a busy
#: machine lengthens the wait (by how much depends on the machine's load).
CUT = 30


def test_a_watcher_late_to_a_look_counts_two_looks_of_waiting():
    """Callers start counting a moment after they asked (``started``), a look's length as
    they mean it, and look every LOOK_S.  A watcher the machine kept from a look for seconds
    (a thread of its own holding the GIL while its cgroup's quota held it back: the first
    call in a fresh process imports psutil, dozens of GIL hand-overs) counted those seconds
    as the program's idle time, and gave up on it at that look."""
    limit = 1.5
    sleeper = subprocess.Popen([sys.executable, '-c', 'import time\nprint("asleep", flush=True)'
                                '\ntime.sleep(3600)'], stdout=subprocess.PIPE, text=True)
    try:
        assert sleeper.stdout.readline() == 'asleep\n'
        patience = Patience(sleeper.pid, limit, started=time.monotonic() - 2 * limit)
        time.sleep(LOOK_S)
        assert not patience.exhausted()  # the failure prevented: 3 s counted as waiting
        time.sleep(2 * limit)
        assert not patience.exhausted()  # and here: 3 s late to a look
        assert wait_until(patience.exhausted)  # an idle program is still given up
    finally:
        sleeper.kill()
        sleeper.wait()


#: The share of every interval the watcher's busiest thread stands on the run queue in
#: :func:`test_a_watcher_held_back_in_every_look_still_counts_the_rest_as_waiting`.
HELD_SHARE = 0.8


def test_a_watcher_held_back_in_every_look_still_counts_the_rest_as_waiting(monkeypatch):
    """On a loaded machine a judge's threads stand on the run queue most of every interval
    and its looks come late.  What the machine held it back was taken from an idle interval
    only after the interval was cut to two looks, and the rest was owed to the next one, so
    the debt grew by every late look and every busy one: a main() that never starts ROS, and
    06's worker whose two timers share a group, sat idle beside such a judge, their idle time
    never growing, until pytest's limit (docs/decisions.md).  Here the watcher's threads
    report what such a judge's did (their run-queue seconds growing by HELD_SHARE of the wall
    clock) and it looks a second late each time: the rest of each interval is the program's
    waiting, and it is given up."""
    limit = 1.0
    began = time.monotonic()
    monkeypatch.setattr(Patience, '_watcher_threads',
                        lambda self: {1: HELD_SHARE * (time.monotonic() - began)})
    sleeper = subprocess.Popen([sys.executable, '-c', 'import time\nprint("asleep", flush=True)'
                                '\ntime.sleep(3600)'], stdout=subprocess.PIPE, text=True)
    try:
        assert sleeper.stdout.readline() == 'asleep\n'
        patience = Patience(sleeper.pid, limit)
        looks = 0
        # each late look counts about (1 - HELD_SHARE) s; the failure prevented never gave up
        while not patience.exhausted() and looks < 4 * limit / (1 - HELD_SHARE):
            time.sleep(1.0)
            looks += 1
        assert patience.ran_out_idle, (looks, patience.idle_s)
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_busy_watcher_does_not_make_a_waiting_program_look_busy():
    """Only the watched tree's threads count. A judge that grades in the test process has
    executor and Fast DDS threads at work beside its watch; counted too, they stood ready in
    every look, and a main() that never starts ROS was given ten times its limit beside CPU
    burners (docs/decisions.md). Here the watcher's own thread computes without
    the GIL while the program it watches sleeps for an hour."""
    done = run_to_end([sys.executable, '-c', WATCHER, str(LIMIT_S), str(CUT)], 'the watcher')
    verdict, _, waited = done.stdout.strip().rpartition(' ')
    # Patience gave up on its own, at its limit or soon after (never a fixed number of
    # seconds: how soon depends on how busy the machine is); the failure waited on.
    assert verdict == 'gave up' and float(waited) >= LIMIT_S, (done.stdout, done.stderr[-500:])


@pytest.mark.timeout(2 * PATIENCE_S)
def test_the_judges_observer_closes_at_once_however_long_its_wait():
    """The judge's spin thread waits for work without end (SPIN_WAIT_S is None); close() wakes
    it. With rclpy's spin_once the wait ended only at its timeout: every judge would have
    waited it out on close (here for ever), and an idle judge polled 20 times a second."""
    assert observer.SPIN_WAIT_S is None
    watching = observer.Observer()
    closed = threading.Event()
    threading.Thread(target=lambda: (watching.close(), closed.set()), daemon=True).start()
    assert wait_until(closed.is_set), "close() waited for the spin thread's wait to time out"


def test_the_judges_node_waits_only_for_what_it_hears():
    """The judge's executor waits once or twice per step of its clock, thousands of times
    per check, and each wait walks every entity of its node. rclpy's default QoS event
    handlers (two per publisher and per subscription, /parameter_events included) made eight
    of them here, only to warn of a QoS mismatch, in every wait of a simulated hour
    (docs/decisions.md)."""
    from std_msgs.msg import Float32
    from ros2nb.judge.clock import JudgeClock
    watching = observer.Observer()
    try:
        watching.watch('/temperature', Float32)
        JudgeClock(watching)
        assert list(watching.node.waitables) == []
        assert len(list(watching.node.subscriptions)) == 2  # /rosout and /temperature
    finally:
        watching.close()


ENDS_WITH_AN_EXIT_HANDLER = """
import atexit, sys
from ros2nb.processes import end_this_process
atexit.register(lambda: print('exit handler ran'))
print('x' * 100_000, end='')  # most of it waits in stdout's buffer: stdout is a pipe
end_this_process(3)
"""


def test_a_process_ended_early_still_runs_its_exit_handlers_and_says_everything():
    """The judge and its subjects skip the interpreter's teardown (end_this_process); what a
    normal exit does first still happens: with os._exit alone the exit handler would not
    run and most of the buffered output would be lost."""
    env = {k: v for k, v in os.environ.items() if k != 'PYTHONUNBUFFERED'}
    done = run_to_end([sys.executable, '-c', ENDS_WITH_AN_EXIT_HANDLER], 'a program ended early',
                      env=env)
    assert done.returncode == 3, done.stderr
    assert done.stdout == 'x' * 100_000 + 'exit handler ran\n'


def test_a_subject_ends_by_itself_and_its_exit_handlers_run(tmp_path):
    """A subject asked to quit ends by itself, exit status 0, having run what the learner's
    code registered to run at exit, as before it skipped the interpreter's teardown."""
    marker = tmp_path / 'exit-handler-ran'
    process = SubjectProcess(tmp_path)
    cells = f"import atexit, pathlib\natexit.register(pathlib.Path({str(marker)!r}).touch)"
    assert process.request(ExecCells(sources=[cells])).cell_errors == []
    process.close()
    assert process.proc.returncode == 0, process.output.text()
    assert marker.exists()


#: Fast DDS's default lease of a participant (s): one that vanished without a word stays in
#: every other participant's graph, its endpoints matched, until it runs out.
DDS_LEASE_S = 20.0

MAKES_A_NODE = '''
import pathlib, time
from rclpy.node import Node

class Leaver(Node):
    def __init__(self):
        super().__init__('leaver')

def busy(marker):
    """Code of the learner's still running when the judge ends it."""
    pathlib.Path(marker).touch()
    while True:
        time.sleep(0.01)
'''


@pytest.mark.parametrize('when', ['between commands', 'in a call'])
def test_a_subject_the_judge_ends_leaves_its_graph_at_once(session, tmp_path, when):
    """A subject the judge ends (``kill_process_group``: a flood, a hang) takes its nodes
    down on SIGTERM, also when the learner's code was running and its command caught
    everything: its participant says it leaves, and the judge's graph drops its endpoints at
    once.  Ended by SIGTERM's default action, it stayed there until its lease ran out (20 s),
    its /clock subscription matched, and the judge's /clock reached the next subjects late:
    ``test_floods.py``'s topic flood failed so beside four burners, the next subject waiting
    over 30 s for the judge's time."""
    from ros2nb.processes import kill_process_group
    from ros2nb.subject_interface import NewNode

    def load(subject: SubjectProcess) -> None:
        assert subject.request(ExecCells(sources=[MAKES_A_NODE])).cell_errors == []

    subject = session.subject(('leaver',), load)
    subject.request(NewNode(cls='Leaver'))
    # The node's endpoints as DDS discovery reports them (its parameter services), which the
    # judge's matches follow: the graph's list of node names can keep a node that left for
    # good (a node list the subject sent, taken after it left: docs/decisions.md).
    service = '/leaver/get_parameters'
    servers = session.observer.node.count_services
    assert wait_until(lambda: servers(service) == 1), servers(service)
    if when == 'in a call':
        marker = tmp_path / 'busy'
        subject.send(Call(name='busy', inputs=[[str(marker)]]))
        assert wait_until(marker.exists)
    assert kill_process_group(subject.proc) == -15  # ended by the signal, as asked
    # Idle time of the judge's own wait: half the lease, which a vanished participant outlives.
    assert session.observer.wait_until(lambda: servers(service) == 0, DDS_LEASE_S / 2), \
        'the ended subject is still in the judge\'s graph'


#: Another process on the judge's domain whose node has the name the learner's node will
#: have, logging without pause: a subject made by an earlier attempt of the same check.
SAME_NAME_ELSEWHERE = '''
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node('echoer')
while True:
    node.get_logger().info('a line of the other process')
    rclpy.spin_once(node, timeout_sec=0.002)
'''

MAKES_A_NODE_THAT_LOGS_ONCE = '''
from rcl_interfaces.msg import Log
from rclpy.node import Node
from rclpy.wait_for_message import wait_for_message

class Echoer(Node):
    def __init__(self):
        super().__init__('echoer')
        self.get_logger().info('up')
        # The race made certain: a new line of the other process's reaches this process
        # (its runtime's /rosout subscription as well) while the node is made.
        while wait_for_message(Log, self, '/rosout')[1].name != 'echoer':
            pass
'''


def test_a_node_counts_only_the_lines_its_own_process_logged(session):
    """What a subject says its node logged counts the lines its own process sent, never
    those of another process's node of the same name, which its /rosout subscription hears
    too.  Counted as heard, an earlier subject's start-up line that reached the next one
    while it made its node became a line the judge waited for, and never had, for a whole
    minute of idle patience (docs/decisions.md)."""
    from ros2nb.domains import DOMAIN_ENV
    from ros2nb.processes import kill_process_group
    from ros2nb.subject_interface import GetCounts, NewNode
    other = subprocess.Popen([sys.executable, '-c', SAME_NAME_ELSEWHERE],
                             env={**os.environ, DOMAIN_ENV: str(session.observer.domain_id)},
                             start_new_session=True)
    try:
        assert session.observer.wait_until(lambda: session.observer.lines_of('echoer'),
                                           PATIENCE_S), 'the other process logged nothing'

        def load(subject: SubjectProcess) -> None:
            assert subject.request(ExecCells(sources=[MAKES_A_NODE_THAT_LOGS_ONCE])
                                   ).cell_errors == []

        subject = session.subject(('echoer',), load)
        made = subject.request(NewNode(cls='Echoer'))
        assert made.ok and made.started_lines == 1, made
        assert subject.request(GetCounts()).logged == 1
    finally:
        kill_process_group(other)
