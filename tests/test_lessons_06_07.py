"""The checks of notebooks 06 (the five promises) and 07 (a live plot) against real mistakes.

As tests/test_checks.py: this process is the judge, the learner's files run in real subject
processes, verdicts come from the judge's own ROS node.  The course's reference files pass
first, so every failure below is its mistake's.
"""

import re
from pathlib import Path

import pytest

from ros2nb import checks, course
from ros2nb.errors import CheckFailed
from judging import FIND_SUBJECT, run_check

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]
#: The judge session's workspace is caught up to notebook 07 (tests/conftest.py: session).
CAUGHT_UP_TO = 7

FAN, PROMISES, PLOT = course.FAN_FILE, course.PROMISES_FILE, course.LIVE_PLOT_FILE


@pytest.fixture(scope='module')
def session(session):
    """tests/conftest.py's judge session, caught up to notebook 07, with the 06 files."""
    for relative in (FAN, PROMISES, PLOT):
        restore(session, relative)
    return session


def restore(session, relative: str) -> None:
    (session.workspace / relative).write_text(course.reference_source(Path(relative).name))
    session.drop(('file', relative))


def mutated(session, relative: str, old: str, new: str) -> None:
    text = course.reference_source(Path(relative).name)
    assert old in text, old
    (session.workspace / relative).write_text(text.replace(old, new))
    session.drop(('file', relative))


def passes_with(session, capsys, relative: str, old: str, new: str, check) -> None:
    """``check`` passes on the course's file with ``old`` written as ``new``."""
    mutated(session, relative, old, new)
    try:
        run_check(session, check)
    finally:
        restore(session, relative)
    assert 'Check passed:' in capsys.readouterr().out


def fails_forged(session, relative: str, old: str, new: str, forge: str, check,
                 pattern: str) -> None:
    """``check`` fails with ``pattern`` on the course's file with ``old`` written as ``new``
    and the forging code ``forge`` at its end."""
    mutated(session, relative, old, new)
    path = session.workspace / relative
    path.write_text(path.read_text() + forge)
    try:
        with pytest.raises(CheckFailed, match=pattern):
            run_check(session, check)
    finally:
        restore(session, relative)


def test_reference_files_pass(session, capsys):
    for check in (checks.check_fan_controller, checks.check_fan_main,
                  checks.check_counting_monitor, checks.check_responsive_worker,
                  checks.check_room_arguments, checks.check_plot_callback):
        run_check(session, check)
    out = capsys.readouterr().out
    assert out.count('Check passed:') == 6, out
    assert 'the heartbeat kept coming while slow_work waited for the slow job, on a ' \
           'MultiThreadedExecutor' in out


MISTAKES = [
    ('fan: >=', FAN, 'msg.data > HIGH_ABOVE_C', 'msg.data >= HIGH_ABOVE_C',
     checks.check_fan_controller, r'For 26.0 °C the fan controller published True; it should be '
                                  r'False: the fan is on only when the reading is High'),
    ('fan: no publish', FAN, '        self.publisher_.publish(command)\n', '',
     checks.check_fan_controller, r'published nothing on /fan_command: publish one Bool'),
    ('fan: topic typo', FAN, "FAN_TOPIC = 'fan_command'", "FAN_TOPIC = 'fan_comand'",
     checks.check_fan_controller, r'no publisher on /fan_command \(it has: /fan_comand'),
    # time.sleep in a callback is refused in the check's process: named at its first call.
    ('fan: a callback that sleeps', FAN, '        self.publisher_.publish(command)\n',
     "        __import__('time').sleep(1.0)\n        self.publisher_.publish(command)\n",
     checks.check_fan_controller, r'temperature_callback raised for 22.0 °C: time\.sleep\(1\.0\) '
                                  r'in a callback holds its node up'),
    # Another wait is timed; busy programs of its own keep its threads waiting for a CPU:
    # still its own slowness.
    ('fan: a callback that waits beside busy programs of its own', FAN,
     '        self.publisher_.publish(command)\n',
     "        if not hasattr(self, 'busy'):\n"
     "            import subprocess, sys\n"
     "            self.busy = [subprocess.Popen([sys.executable, '-c', 'while True: pass'])\n"
     "                         for _ in range(4)]\n"
     "        __import__('threading').Event().wait(1.0)\n"
     "        self.publisher_.publish(command)\n",
     checks.check_fan_controller, r'took 0\.5 s or more to answer each of 10 readings: '
                                  r'temperature_callback waits \(a loop, or a wait\?\)'),
    ('fan: node name', FAN, "super().__init__('fan_controller')", "super().__init__('fan')",
     checks.check_fan_controller, r'The node is called fan; name it fan_controller'),
    ('counting: name ignored', PROMISES, 'super().__init__(name)',
     "super().__init__('counting_monitor')", checks.check_counting_monitor,
     r"CountingMonitor\('monitor_7'\) made a node called counting_monitor: pass the name"),
    ('counting: never counts', PROMISES, 'self.received += 1', 'pass',
     checks.check_counting_monitor,
     r'logged "received 0"; the count is 1: start self.received at 0 in __init__'),
    ('counting: no attribute', PROMISES, '        self.received = 0\n', '',
     checks.check_counting_monitor,
     r'has no attribute received yet: it is read before any method sets it'),
    ('worker: single-threaded', PROMISES, 'executor = MultiThreadedExecutor(num_threads=2)',
     'from rclpy.executors import SingleThreadedExecutor\n    executor = SingleThreadedExecutor()',
     checks.check_responsive_worker, r'No heartbeat came while slow_work waited for the slow '
                                     r'job: a SingleThreadedExecutor runs one callback at a '
                                     r'time'),
    ('worker: one group', PROMISES, '''slow_group=MutuallyExclusiveCallbackGroup(),
                  heartbeat_group=MutuallyExclusiveCallbackGroup())''', ')',
     checks.check_responsive_worker, r'both timers are in one MutuallyExclusiveCallbackGroup'),
    ('worker: returns the node only', PROMISES, 'return node, executor', 'return node',
     checks.check_responsive_worker, r'returned <.*Worker object.*; return two things'),
    ('rooms: no --ros-args', PROMISES, "['--ros-args', '-r', f'__ns:=/{room}']",
     "['-r', f'__ns:=/{room}']", checks.check_room_arguments,
     r"only the arguments after '--ros-args'"),
    ('rooms: topic only', PROMISES, "f'__ns:=/{room}'", "f'temperature:=/{room}/temperature'",
     checks.check_room_arguments, r"room_arguments\('kitchen'\) the node runs as "
                                  r'/temperature_sensor; put it in the namespace /kitchen'),
    ('rooms: room ignored', PROMISES, "f'__ns:=/{room}'", "'__ns:=/kitchen'",
     checks.check_room_arguments, r"room_arguments\('attic'\) the node runs as "
                                  r'/kitchen/temperature_sensor'),
    ('rooms: a namespace without its slash', PROMISES, "f'__ns:=/{room}'", "f'__ns:={room}'",
     checks.check_room_arguments, r"rclpy refused the arguments room_arguments\('kitchen'\) "
                                  r"returned, \['--ros-args', '-r', '__ns:=kitchen'\]: ROS could "
                                  r"not read the remap rule '-r __ns:=kitchen': a namespace starts "
                                  r'with a slash: __ns:=/kitchen\.$'),
    ('rooms: the namespace as a parameter', PROMISES, "['--ros-args', '-r', f'__ns:=/{room}']",
     "['--ros-args', '-p', f'__ns:=/{room}']", checks.check_room_arguments,
     r"ROS could not read the parameter override rule '-p __ns:=/kitchen': __ns is not a "
     r'parameter but a remap: -r __ns:=/kitchen\.$'),
    ('fan: a Bool given its value in order', FAN,
     '        command = Bool()\n        command.data = msg.data > HIGH_ABOVE_C\n',
     '        command = Bool(msg.data > HIGH_ABOVE_C)\n', checks.check_fan_controller,
     r'a Bool message takes its fields by name, not in order: write '
     r'Bool\(data=msg\.data > HIGH_ABOVE_C\) \(its fields: data\)\. \(fan_controller\.py line '
     r'\d+: command = Bool\(msg\.data > HIGH_ABOVE_C\)\)$'),
    ('counting: the count without self', PROMISES, '        self.received += 1\n',
     '        received += 1\n', checks.check_counting_monitor,
     r"received here is a new local name of this method, not the node's count \(the node keeps "
     r'it as self\.received\): write self\.received .*\(promises\.py line \d+: received \+= 1\)$'),
    ('rooms: placeholder', PROMISES, "    return ['--ros-args', '-r', f'__ns:=/{room}']",
     '    raise NotImplementedError()', checks.check_room_arguments,
     r"room_arguments\('kitchen'\) still raises NotImplementedError"),
    ('plot: wall-clock time', PLOT, 'self.get_clock().now().nanoseconds / 1e9',
     "__import__('time').time()",
     checks.check_plot_callback, r"was plotted at [\d.e+]+ s: use the node's clock in seconds"),
    ('plot: plt.pause in the callback', PLOT, '        self.redraw()\n',
     '        self.redraw()\n        import matplotlib.pyplot as plt\n        plt.pause(0.5)\n',
     checks.check_plot_callback, r'temperature_callback raised for [\d.]+ °C: plt\.pause\(\) in '
                                 r'a callback waits its interval on every message.*\(live_plot\.py '
                                 r'line \d+: plt\.pause\(0\.5\)\)$'),
    ('plot: plt.show in the callback', PLOT, '        self.redraw()\n',
     '        self.redraw()\n        import matplotlib.pyplot as plt\n        plt.show()\n',
     checks.check_plot_callback, r'plt\.show\(\) in a callback draws the whole figure again on '
                                 r'every message'),
    ('plot: no redraw', PLOT, '        self.redraw()\n', '',
     checks.check_plot_callback, r'nothing was plotted: append the time and the reading, then '
                                 r'call self.redraw\(\) once per message'),
    ('plot: the message, not its data', PLOT, 'self.temps_c.append(msg.data)',
     'self.temps_c.append(msg)', checks.check_plot_callback,
     r'temperature_callback raised for [\d.]+ °C: a Float32 message is not its value: use its '
     r'field \(data\), e\.g\. msg\.data\.'),
]


@pytest.mark.parametrize('label, file, old, new, check, pattern', MISTAKES,
                         ids=[m[0] for m in MISTAKES])
def test_a_mistake_gets_one_line(session, label, file, old, new, check, pattern):
    mutated(session, file, old, new)
    try:
        with pytest.raises(CheckFailed) as caught:
            run_check(session, check)
    finally:
        restore(session, file)
    message = str(caught.value)
    assert re.search(pattern, message), message
    assert '\n' not in message


#: A program with a node named like the learner's that owns no endpoint of the learner's:
#: what the grader's graph can still list for a moment after a subject's process ended.
DECOY = '''
import sys
import rclpy
from rclpy.node import Node
rclpy.init()
node = Node(sys.argv[1])
print('up', flush=True)
sys.stdin.read()
'''


def test_a_node_of_the_same_name_in_another_program_hides_nothing(session):
    """The graph's per-node query answers for one of two same-named nodes (whichever it
    lists first); the check reads the endpoints themselves, so the learner's shows."""
    import subprocess
    import sys
    from waiting import wait_for
    decoy = subprocess.Popen([sys.executable, '-c', DECOY, course.PLOT_NODE],
                             env=session.subject_env(), stdin=subprocess.PIPE,
                             stdout=subprocess.PIPE, text=True)
    try:
        assert decoy.stdout.readline().strip() == 'up'
        observer = session.observer
        wait_for(lambda: observer.has_node(course.PLOT_NODE), 'the decoy node in the graph')
        # the learner's node is alive in its subject after it
        run_check(session, checks.check_plot_callback)
        by_process = observer._endpoints_by_process(course.PLOT_NODE, '/')
        assert len(by_process) == 2, by_process
        per_node = {('subscription', topic, kind) for topic, kinds in
                    observer.node.get_subscriber_names_and_types_by_node(course.PLOT_NODE, '/')
                    for kind in kinds}
        # One process's subscriptions, never both: with the decoy listed first, the learner's
        # /temperature subscription was invisible to the query the check used before.
        assert per_node in [{e for e in found if e[0] == 'subscription'}
                            for found in by_process.values()]
    finally:
        decoy.stdin.close()
        decoy.wait(30)
        session.drop(('file', PLOT))


#: The counting monitor's callback does nothing; at import, the file finds the subject's
#: request loop and has it report received = 0 for a new node and the number of readings
#: the subject delivered since.
FORGED_COUNT = FIND_SUBJECT + '''

def _forge(_attribute=_HANDLERS.get('attribute'), _asked=[]):
    def attribute(name):
        reply = _attribute(name=name)
        if name == 'received' and 'value' in reply:
            _asked.append(_SUBJECT.received)
            reply['value']['value'] = _SUBJECT.received - _asked[0]
        return reply

    _HANDLERS['attribute'] = attribute


if _SUBJECT is not None:
    _forge()
'''


def test_a_count_reported_by_a_forged_subject(session, monkeypatch):
    """The subject's reply said received == 5 although the callback counts nothing: against
    the check before it, that passed (checked by hand); now the judge reads the count the
    monitor logs."""
    fails_forged(session, PROMISES, 'self.received += 1', 'pass', FORGED_COUNT,
                 checks.check_counting_monitor,
                 r'logged "received 0"; the count is 1: start self.received at 0 in __init__')


def test_a_count_through_a_lambda_passes(session, capsys):
    """The honest twin of the forged count, written another way: the subscription's callback
    is a lambda that calls the counting method; the file shows it counts, so it passes."""
    passes_with(session, capsys, PROMISES, 'Float32, TOPIC, self.count, QUEUE_DEPTH',
                'Float32, TOPIC, lambda msg: self.count(msg), QUEUE_DEPTH',
                checks.check_counting_monitor)


#: The plot feeder's callback does nothing; at import, the file finds the subject's request
#: loop and has it report the lists and the counter a right callback would have made, from
#: the times the subject itself reported and the check's own readings.
FORGED_PLOT = FIND_SUBJECT + '''

def _forge(_attribute=_HANDLERS.get('attribute'), _wait=_HANDLERS.get('wait_received'),
           _times=[]):
    PLOT_READINGS_C = (21.5, 26.25, 19.75, 23.0)  # an older judge's readings

    def wait_received(**request):
        reply = _wait(**request)
        _times.append(reply['t'])
        return reply

    def attribute(name):
        reply = _attribute(name=name)
        floats = {'temps_c': PLOT_READINGS_C[:len(_times)], 'times_s': _times}.get(name)
        if floats is not None:
            reply['value'] = {'type': 'list',
                              'value': [{'type': 'float', 'value': v} for v in floats]}
        elif name == 'redraws':
            reply['value'] = {'type': 'int', 'value': len(_times)}
        return reply

    _HANDLERS['wait_received'] = wait_received
    _HANDLERS['attribute'] = attribute


if _SUBJECT is not None:
    _forge()
'''


def test_a_plot_reported_by_a_forged_subject(session, monkeypatch):
    """The subject's replies gave the lists and the redraw count of a right callback although
    the callback does nothing: against the check before it, that passed (checked by hand).
    The subject's first command loads the file before any request loop exists, so the frame
    walk finds none, and the judge decides from the /rosout lines redraw() logs."""
    right = '''        self.times_s.append(self.get_clock().now().nanoseconds / 1e9)
        self.temps_c.append(msg.data)
        self.redraw()
'''
    fails_forged(session, PLOT, right, '        pass\n', FORGED_PLOT, checks.check_plot_callback,
                 r'nothing was plotted')


def test_a_plot_fed_through_a_helper_method_passes(session, capsys):
    """The honest twin of the forged plot, written another way: the callback hands the
    reading to a method of the class, which appends both and redraws."""
    passes_with(session, capsys, PLOT, '''    def temperature_callback(self, msg):''', '''\
    def temperature_callback(self, msg):
        self.keep(msg.data)

    def keep(self, reading):
        self.times_s.extend([self.get_clock().now().nanoseconds / 1e9])
        self.temps_c += [reading]
        self.redraw()

    def unused(self, msg):''', checks.check_plot_callback)


#: The worker spins on a SingleThreadedExecutor with both timers in the node's default group;
#: at import, the file finds the subject's request loop and has it report what a right
#: answer would have (a MultiThreadedExecutor, a group per timer, a full heartbeat).
FORGED_WORKER = FIND_SUBJECT + '''

def _forge(_timer_runs=_HANDLERS.get('timer_runs')):
    def timer_runs(**request):
        _timer_runs(**request)
        return {'ok': True, 'executor': 'MultiThreadedExecutor',
                'runs': {'slow_work': 4, 'heartbeat': 20},
                'groups': [['slow_work', 'MutuallyExclusiveCallbackGroup', 1],
                           ['heartbeat', 'MutuallyExclusiveCallbackGroup', 2]]}

    _HANDLERS['timer_runs'] = timer_runs


if _SUBJECT is not None:
    _forge()
'''
RESPONSIVE = '''    node = Worker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup(),
                  heartbeat_group=MutuallyExclusiveCallbackGroup())
    executor = MultiThreadedExecutor(num_threads=2)
    return node, executor
'''


def test_a_worker_reported_by_a_forged_subject(session, monkeypatch):
    """The subject's reply gave a right answer's executor, groups and counts although the
    function returns a single-threaded executor: against the check before it, that passed
    (checked by hand); now the judge hears no heartbeat while slow_work is busy."""
    fails_forged(session, PROMISES, RESPONSIVE, '''\
    from rclpy.executors import SingleThreadedExecutor
    return Worker('responsive_worker'), SingleThreadedExecutor()
''', FORGED_WORKER, checks.check_responsive_worker,
                 r'a SingleThreadedExecutor runs one callback at a time')


@pytest.mark.parametrize('label, answer', [
    ('one reentrant group, an executor from a helper', '''\
    from rclpy.callback_groups import ReentrantCallbackGroup
    both = ReentrantCallbackGroup()
    return Worker('responsive_worker', both, both), _executor()


def _executor():
    return MultiThreadedExecutor(num_threads=2)
'''),
    ('a group for the slow timer only', '''    executor = MultiThreadedExecutor()
    node = Worker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup())
    return (node, executor)
'''),
])
def test_a_worker_written_another_way_passes(session, capsys, label, answer):
    """Honest twins of the forged worker, written as the text reader must still follow."""
    passes_with(session, capsys, PROMISES, RESPONSIVE, answer, checks.check_responsive_worker)


def test_a_worker_built_in_a_list_passes(session, capsys):
    """Before, the judge read responsive_worker() as text and failed this honest answer
    ("cannot tell what it returns"); now the worker's lines on /rosout decide."""
    passes_with(session, capsys, PROMISES, RESPONSIVE, '''\
    made = [Worker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup(),
                   heartbeat_group=MutuallyExclusiveCallbackGroup()),
            MultiThreadedExecutor(num_threads=2)]
    return tuple(made)
''', checks.check_responsive_worker)


def test_a_reply_of_no_known_shape_fails_that_check_alone(session, monkeypatch):
    """A check that meets a reply it cannot read (the subject runs learner code, which may
    write anything on its pipe) raises an error of its own, here the typed reply's
    (Unreadable); before, that ended the judge and every check of the notebook went with it.
    Now it fails that check with one line, and the notebook's other checks are graded."""
    from ros2nb.judge_interface import captured
    from ros2nb.judge.subjects import SubjectProcess
    from ros2nb.subject_interface import NewNode
    from ros2nb.typed_json import Unreadable

    reply_to = SubjectProcess.reply_to

    def nonsense(command, data):
        return reply_to(command, {'ok': True, 'name': 7} if isinstance(command, NewNode)
                        else data)

    monkeypatch.setattr(SubjectProcess, 'reply_to', staticmethod(nonsense))
    session.drop(('file', PLOT))
    with pytest.raises(Unreadable, match=r'^NodeMade.name is int, not str$'):
        run_check(session, checks.check_plot_callback)
    outcome = captured(lambda: run_check(session, checks.check_plot_callback))
    assert outcome.passed is False and outcome.message and '\n' not in outcome.message
    assert outcome.message.startswith('The grader could not finish this check (Unreadable: '
                                         'NodeMade.name is int, not str)'), outcome


#: The Worker's slow callback logs the heartbeat's line itself, three times, before it waits
#: for its answer on a SingleThreadedExecutor: the lines say "heartbeat", yet none ran while
#: the slow job was held.
LOGGED_HEARTBEAT = ("        self.slow_client.call(Trigger.Request())"
                    "   # waits for the slow job's answer\n", """\
        for _ in range(3):
            self.get_logger().info('heartbeat')
        self.slow_client.call(Trigger.Request())
""")
SINGLE_THREADED = '''    from rclpy.executors import SingleThreadedExecutor
    return Worker('responsive_worker'), SingleThreadedExecutor()
'''


def worker_file(session, *changes: tuple[str, str], end: str = '') -> None:
    """The course's promises.py with ``changes`` made and ``end`` added."""
    text = course.reference_source(Path(PROMISES).name)
    for old, new in changes:
        assert old in text, old
        text = text.replace(old, new)
    (session.workspace / PROMISES).write_text(text + end)
    session.drop(('file', PROMISES))


def test_a_heartbeat_the_slow_callback_logs_itself(session, monkeypatch):
    """The judge holds the slow job open and hears three "heartbeat" lines: all sent before
    the slow job was asked for, at once; a heartbeat that keeps running sends them after it,
    apart in time.  Counting any heartbeat line, the same worker passes."""
    worker_file(session, LOGGED_HEARTBEAT, (RESPONSIVE, SINGLE_THREADED))
    try:
        with pytest.raises(CheckFailed, match=r'No heartbeat came while slow_work waited for '
                                              r'the slow job: a SingleThreadedExecutor runs one'):
            run_check(session, checks.check_responsive_worker)
        from ros2nb.checks import lesson06_worker
        monkeypatch.setattr(lesson06_worker._Heartbeats, 'kept_beating',
                            lambda self, since_ns: len(self.sent_ns) >= 1)
        session.drop(('file', PROMISES))
        run_check(session, checks.check_responsive_worker)
    finally:
        restore(session, PROMISES)


#: A Worker of the learner's whose slow work is a coroutine that awaits the call.
COROUTINE = '''    from rclpy.executors import SingleThreadedExecutor

    class Waiting(Worker):
        async def slow_work(self):
            self.get_logger().info('slow work: start')
            await self.slow_client.call_async(Trigger.Request())
            self.get_logger().info('slow work: done')

    return Waiting('responsive_worker', {groups}), SingleThreadedExecutor()
'''


def test_a_coroutine_slow_work_on_one_thread_passes(session, capsys):
    """Slow work written as a coroutine hands the executor back while it awaits the call: on
    a SingleThreadedExecutor, the heartbeat keeps coming while the judge holds the slow job.
    A valid style, stated in notebook 06."""
    passes_with(session, capsys, PROMISES, RESPONSIVE, COROUTINE.format(
        groups='MutuallyExclusiveCallbackGroup(), MutuallyExclusiveCallbackGroup()'),
        checks.check_responsive_worker)


def test_a_coroutine_slow_work_in_the_shared_group_gets_its_line(session):
    """A coroutine holds its callback group while it waits: with both timers in the node's
    default group, no heartbeat comes, and the line names the group."""
    worker_file(session, (RESPONSIVE, COROUTINE.format(groups='')))
    try:
        with pytest.raises(CheckFailed, match=r'No heartbeat came while slow_work waited for '
                                              r'the slow job: both timers are in one '
                                              r'MutuallyExclusiveCallbackGroup'):
            run_check(session, checks.check_responsive_worker)
    finally:
        restore(session, PROMISES)


RIGHT_PLOT = '''        self.times_s.append(self.get_clock().now().nanoseconds / 1e9)
        self.temps_c.append(msg.data)
        self.redraw()
'''
#: The plot's callback logs redraw()'s line for each reading, with the node's time and the
#: reading, and neither keeps them nor calls redraw(): the lines say "plotted", nothing was.
LOGGED_POINT = '''        self.logged = getattr(self, 'logged', 0) + 1
        self.get_logger().info(f'Plotted {msg.data:.2f} °C at '
                               f'{self.get_clock().now().nanoseconds / 1e9:.3f} s, '
                               f'point {self.logged}')
'''


def test_a_point_the_callback_logs_itself(session):
    """Before, the judge read redraw()'s lines on /rosout and this callback passed (its
    honest twin, a callback that does nothing, failed); now the course's redraw() tells the
    judge what it drew, and it never drew."""
    fails_forged(session, PLOT, RIGHT_PLOT, LOGGED_POINT, '', checks.check_plot_callback,
                 r'For the reading [\d.]+ °C nothing was plotted')


#: The callback keeps nothing and tells the judge's witness topic a drawing itself: the node's
#: times as each reading arrived, and the readings an older judge always sent.
WITNESS_TABLE = '''        from std_msgs.msg import String
        if not hasattr(self, 'forger'):
            self.forger = self.create_publisher(String, '/ros2nb/witness', 10)
            self.points = []
        self.points.append(self.get_clock().now().nanoseconds / 1e9)
        times = ','.join(repr(t) for t in self.points)
        temps = ','.join(repr(t) for t in [21.5, 26.25, 19.75, 23.0][:len(self.points)])
        self.forger.publish(String(data=f'drawn {times};{temps}'))
'''
#: The same, with the reading each message carries: what the callback had to keep, told its
#: own way.
WITNESS_KEPT = WITNESS_TABLE.replace(
    "        self.points.append(self.get_clock().now().nanoseconds / 1e9)\n",
    "        self.points.append((self.get_clock().now().nanoseconds / 1e9, msg.data))\n").replace(
    "repr(t) for t in self.points", "repr(t) for t, _v in self.points").replace(
    "repr(t) for t in [21.5, 26.25, 19.75, 23.0][:len(self.points)]",
    "repr(v) for _t, v in self.points")


def test_a_drawing_counts_for_what_it_holds_not_for_who_told_it(session, capsys):
    """The drawings are plain data, compared with the readings the judge sent (drawn for each
    run) and the times it sent them: one told by the callback itself with a table of
    readings fails on the first reading that is not the table's; one that holds what the
    callback kept passes, whoever told it: the task was done, its own way."""
    from ros2nb.checks.lesson07 import readings_c
    sent = readings_c(session)
    first = next(i for i, v in enumerate(sent) if v != (21.5, 26.25, 19.75, 23.0)[i])
    fails_forged(session, PLOT, RIGHT_PLOT, WITNESS_TABLE, '', checks.check_plot_callback,
                 rf'For the reading {sent[first]} °C the plot shows '
                 rf'{(21.5, 26.25, 19.75, 23.0)[first]} °C')
    passes_with(session, capsys, PLOT, RIGHT_PLOT, WITNESS_KEPT, checks.check_plot_callback)


#: The worker's file also serves the slow job from a node of its own, spun in a thread of its
#: own: it answers at once, so that a worker whose two timers share one group (on two
#: threads, the answer taken in a group of its own) runs its heartbeat between two slow works.
OWN_SERVER = '''
def _answer_for_the_worker():
    import threading
    from rclpy.executors import SingleThreadedExecutor

    def done(request, response):
        response.success = True
        return response

    helper = Node('slow_job_helper')
    helper.create_service(Trigger, SLOW_SERVICE, done)
    executor = SingleThreadedExecutor()
    executor.add_node(helper)
    threading.Thread(target=executor.spin, daemon=True).start()
'''


ONE_GROUP = '''    node = Worker('responsive_worker')
    executor = MultiThreadedExecutor(num_threads=2)
    return node, executor
'''


def test_a_slow_job_a_node_of_its_own_answers_counts_for_nothing(session, monkeypatch):
    """The graph shows two servers of the slow job: the check fails with one line.  Not
    counting the servers, the worker whose timers share one group passes: its own server
    answered at once, and its heartbeat ran while the judge still held its copy of the call
    (its twin without the server fails with the line about the group, MISTAKES)."""
    worker_file(session, (RESPONSIVE, '    _answer_for_the_worker()\n' + ONE_GROUP),
                end=OWN_SERVER)
    try:
        with pytest.raises(CheckFailed, match=r'^Something in your code answers the slow job'):
            run_check(session, checks.check_responsive_worker)
        from ros2nb.checks import lesson06_worker
        monkeypatch.setattr(lesson06_worker._SlowJob, 'servers', lambda self: 1)
        session.drop(('file', PROMISES))
        run_check(session, checks.check_responsive_worker)
    finally:
        restore(session, PROMISES)
