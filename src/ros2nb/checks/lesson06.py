"""Checks of notebook 06, the five promises: a third node, its main(), a counting monitor,
a worker that stays responsive, and the arguments that make two rooms of one package.

Part of :mod:`ros2nb.checks`.  Every part is in a file of the learner's package
(``fan_controller.py``, ``promises.py``); the judge runs it in a subject and decides from
what its own node sees (the ROS graph, ``/fan_command``) and from the file read as text; the
counts the subject reports only name a mistake.
"""

from __future__ import annotations

import ast

from std_msgs.msg import Bool, Float32

from .. import course
from ..errors import CheckFailed
from .base import ARRIVAL_TIMEOUT_S, Judge, judged, learner_error
from .mains import run_main
from .nodes import new_node, reach
from .source import ClassSource, called_name, made_by, module_function, read_module
from .verdicts import endpoint_verdict, node_name_verdict

#: Readings the fan check sends (°C): both sides of the High threshold.
FAN_READINGS_C = (22.0, 26.0, 26.01, 27.5, 25.99, 19.0)
#: Readings the counting monitor check sends.
COUNTED_READINGS = 5
#: Wall-clock seconds the worker is spun, and the share of its heartbeats that must run.
WORKER_SPIN_S = 2.0
HEARTBEAT_SHARE = 0.6


def _send(judge: Judge, subject, value: float, received: int, callback: str) -> dict:
    """Publish one reading to the learner's node; return the subject's counts after it."""
    judge.probe_publisher.publish(Float32(data=value))
    reply = subject.request('wait_received', count=received + 1, seconds=ARRIVAL_TIMEOUT_S)
    if reply['failure']:
        raise learner_error(reply['failure']['callback'], reply['failure'],
                            context=f' for {value} °C')
    if not reply['ok']:
        raise CheckFailed(f'The reading {value} °C never reached {callback}: is it the '
                          'subscription\'s callback?')
    return reply


# ------------------------------------------------------------------ modularity
def _fan_controller(judge: Judge) -> str:
    judge.drop(('file', course.PROMISES_FILE))  # the fan is the only subscription here
    subject, info = new_node(judge, course.FAN_FILE, course.FAN_CLASS)
    node_name_verdict(info, course.FAN_NODE)
    found = judge.observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    endpoint_verdict(info['name'], found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE)
    endpoint_verdict(info['name'], found, 'publisher', '/' + course.FAN_TOPIC,
                     course.FAN_MESSAGE_TYPE)
    commands = judge.observer.watch_messages('/' + course.FAN_TOPIC, Bool)
    if not subject.request('wait_matched', topic='/' + course.FAN_TOPIC,
                           seconds=ARRIVAL_TIMEOUT_S)['ok']:
        raise CheckFailed(f'The fan controller\'s publisher never reached the grader\'s '
                          f'subscription on /{course.FAN_TOPIC}: is the machine very busy? '
                          'Run this check again.')
    reach(judge, subject, info['name'])
    received = info['received']
    for value in FAN_READINGS_C:
        before = len(commands)
        received = _send(judge, subject, value, received, 'temperature_callback')['received']
        judge.observer.wait_until(lambda: len(commands) > before, ARRIVAL_TIMEOUT_S)
        said = commands[before:]
        want = course.monitor_status(value) == 'High'
        if not said:
            raise CheckFailed(f'For a reading of {value} °C the fan controller published nothing '
                              f'on /{course.FAN_TOPIC}: publish one Bool for every reading.')
        if len(said) > 1:
            raise CheckFailed(f'For a reading of {value} °C the fan controller published '
                              f'{len(said)} commands; publish exactly one per reading.')
        if bool(said[0]) != want:
            raise CheckFailed(f'For {value} °C the fan controller published {bool(said[0])}; it '
                              f'should be {want}: the fan is on only when the reading is High, '
                              f'strictly above HIGH_ABOVE_C = {course.HIGH_ABOVE_C} °C.')
    return (f'{info["name"]} hears /{course.TOPIC} and publishes one command on '
            f'/{course.FAN_TOPIC} per reading, True only when High ({len(FAN_READINGS_C)} '
            'readings).')


def check_fan_controller() -> None:
    """Check part 2 of ``fan_controller.py``: the third node, added without touching the others.

    The judge creates your ``FanController``, reads its subscription and publisher from the
    ROS graph, publishes readings on both sides of 26 °C from its own publisher and reads
    every command on ``/fan_command``.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the reading and the command your node published.
    """
    judged('check_fan_controller', _fan_controller)


def check_fan_main() -> None:
    """Check part 3 of ``fan_controller.py``: ``main()`` runs it as a process of its own.

    As :func:`check_sensor_main`: the file is started as a program, gets Ctrl+C once its
    node spins, and must exit with code 0 after cleaning up in ``finally``.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    judged('check_fan_main', run_main, relative=course.FAN_FILE, node_name=course.FAN_NODE,
           part=3)


# ------------------------------------------------------------------ scalability
def _counting_monitor(judge: Judge) -> str:
    judge.drop(('file', course.FAN_FILE))  # the counting monitor is the only subscription here
    name = 'monitor_7'
    subject, info = new_node(judge, course.PROMISES_FILE, course.COUNTING_CLASS, args=(name,))
    if info['name'] != name:
        raise CheckFailed(f"{course.COUNTING_CLASS}('{name}') made a node called {info['name']}: "
                          'pass the name it is given on to super().__init__(name).')
    found = judge.observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    endpoint_verdict(name, found, 'subscription', '/' + course.TOPIC, course.MESSAGE_TYPE)
    start = subject.request('attribute', name='received')
    if start.get('missing'):
        raise CheckFailed(f'{course.COUNTING_CLASS} has no attribute received: set '
                          'self.received = 0 in __init__.')
    if start['value']['value'] != 0:
        raise CheckFailed(f'A new {course.COUNTING_CLASS} starts with received = '
                          f"{start['value']['value']}; start counting at 0.")
    reach(judge, subject, name)
    received = info['received']
    for index in range(COUNTED_READINGS):
        received = _send(judge, subject, 21.0 + index, received, 'its callback')['received']
    count = subject.request('attribute', name='received')['value']['value']
    if count != COUNTED_READINGS:
        raise CheckFailed(f'After {COUNTED_READINGS} readings self.received is {count!r}: add '
                          'one in the callback for every message.')
    _counting_source_verdict(judge)
    return (f"{course.COUNTING_CLASS}('{name}') is called {name} and counted "
            f'{COUNTED_READINGS} of {COUNTED_READINGS} readings.')


def _counting_source_verdict(judge: Judge) -> None:
    """The subscription's callback adds to ``self.received``, as the file (read as text) says.

    The count is the subject's word, and a subject runs the learner's code, which may
    rewrite what it reports: the count only names a mistake, the source decides.
    """
    source = ClassSource.read(judge.workspace, course.PROMISES_FILE, course.COUNTING_CLASS)
    callbacks = source.callbacks('create_subscription', 2) if source else []
    if source is None or not any(source.reaches_assignment(c, 'received') for c in callbacks):
        called = ', '.join(sorted(set(callbacks))) or 'nothing'
        raise CheckFailed(f"The subscription calls {called}, which never adds to "
                          'self.received: give it a method of the class that does, '
                          'self.received += 1 (the method itself, without parentheses).')


def check_counting_monitor() -> None:
    """Check part 2 of ``promises.py``: a monitor that only counts, named as it is told.

    Creates ``CountingMonitor('monitor_7')``, checks its name and subscription in the ROS
    graph, publishes 5 readings and reads ``received``, and reads in your file that the
    subscription's callback adds to ``self.received``.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the name or count found and the one expected.
    """
    judged('check_counting_monitor', _counting_monitor)


# ------------------------------------------------------------------ concurrency
def _worker_verdict(reply: dict) -> str:
    """Say why the heartbeat was held up (from the executor and groups), or that it was not."""
    runs, groups = reply['runs'], {name: (kind, number) for name, kind, number in reply['groups']}
    if not {'slow_work', 'heartbeat'} <= set(runs):
        raise CheckFailed(f'{course.WORKER_FUNCTION}() returned a node with the timers '
                          f'{sorted(runs) or "none"}; return the Worker of part 3, with its '
                          'slow_work and heartbeat timers.')
    expected = round(WORKER_SPIN_S / course.HEARTBEAT_PERIOD_S)
    # Same code, same words: how often the heartbeat ran depends on the machine, so the lines
    # that follow from the executor and its groups do not quote the count.
    beats = (f'heartbeat cannot keep its {1 / course.HEARTBEAT_PERIOD_S:g} Hz while slow_work '
             'runs')
    if reply['executor'] == 'SingleThreadedExecutor':
        raise CheckFailed(f'{beats}: a SingleThreadedExecutor runs one callback at a time, so '
                          'slow_work holds up heartbeat; return a MultiThreadedExecutor.')
    shared = groups['slow_work'] == groups['heartbeat']
    if shared and groups['heartbeat'][0] == 'MutuallyExclusiveCallbackGroup':
        raise CheckFailed(f'{beats}: both timers are in one MutuallyExclusiveCallbackGroup (the '
                          "node's default), which runs one of its callbacks at a time; give "
                          'each timer a group of its own.')
    if runs['slow_work'] == 0:
        raise CheckFailed(f'slow_work never ran in {WORKER_SPIN_S:g} s: keep both timers of the '
                          'Worker running.')
    if runs['heartbeat'] < HEARTBEAT_SHARE * expected:
        raise CheckFailed(f'heartbeat ran {runs["heartbeat"]} times in {WORKER_SPIN_S:g} s '
                          f'({expected} expected) although the executor and groups allow it: '
                          'give the MultiThreadedExecutor at least num_threads=2.')
    return (f'with slow_work busy {course.SLOW_WORK_S:g} s of every {course.SLOW_PERIOD_S:g} s, '
            f'heartbeat kept at least {HEARTBEAT_SHARE:.0%} of its {expected} runs in '
            f'{WORKER_SPIN_S:g} s on a {reply["executor"]}.')


def _responsive_worker(judge: Judge) -> str:
    subject = judge.file_subject(course.PROMISES_FILE)
    reply = subject.request('timer_runs', name=course.WORKER_FUNCTION, seconds=WORKER_SPIN_S,
                            timeout=WORKER_SPIN_S + 30)
    if reply.get('undefined'):
        raise CheckFailed(f'promises.py defines no function {course.WORKER_FUNCTION}: write '
                          'part 4 (and run its cell).')
    if 'error' in reply:
        raise learner_error(f'{course.WORKER_FUNCTION}()', reply['error'])
    if 'returned' in reply:
        raise CheckFailed(f'{course.WORKER_FUNCTION}() returned {reply["returned"]["value"]}; '
                          'return two things, the Worker node and the executor to spin it: '
                          'return node, executor.')
    verdict = _worker_verdict(reply)
    _worker_source_verdict(judge)
    return verdict


#: The keyword and the position of each timer's group in ``Worker(name, slow_group,
#: heartbeat_group)``.
_WORKER_GROUPS = (('slow_group', 1), ('heartbeat_group', 2))


def _worker_source_verdict(judge: Judge) -> None:
    """``responsive_worker()`` returns a Worker whose timers may overlap and a multi-threaded
    executor, as the file (read as text) says.

    The executor, the groups and the counts are the subject's word, and a subject runs the
    learner's code, which may rewrite what it reports: they only name a mistake (the lines
    of :func:`_worker_verdict`), the source decides.
    """
    module = read_module(judge.workspace, course.PROMISES_FILE)
    function = module_function(module, course.WORKER_FUNCTION) if module else None
    unread = (f'The grader reads {course.WORKER_FUNCTION}() in your file as text and cannot '
              'tell {what}: build the Worker and the MultiThreadedExecutor in the function '
              'itself (node = Worker(...); executor = MultiThreadedExecutor(...)) and end with '
              'return node, executor.')
    returns = [r.value for r in ast.walk(function) if isinstance(r, ast.Return)] \
        if function else []
    returned = made_by(module, function, returns[-1]) if returns and returns[-1] else None
    if not isinstance(returned, ast.Tuple) or len(returned.elts) != 2:
        raise CheckFailed(unread.format(what='what it returns'))
    node, executor = (made_by(module, function, e) for e in returned.elts)
    kind = called_name(executor)
    if kind == 'SingleThreadedExecutor':
        raise CheckFailed('a SingleThreadedExecutor runs one callback at a time, so slow_work '
                          'holds up heartbeat; return a MultiThreadedExecutor.')
    if kind != 'MultiThreadedExecutor':
        raise CheckFailed(unread.format(what='which executor it returns'))
    given = {k.arg: k.value for k in executor.keywords}
    threads = given.get('num_threads', executor.args[0] if executor.args else None)
    if isinstance(threads, ast.Constant) and isinstance(threads.value, int) \
            and threads.value < 2:
        raise CheckFailed(f'A MultiThreadedExecutor with num_threads={threads.value} runs one '
                          'callback at a time: give it at least num_threads=2.')
    if called_name(node) != course.WORKER_CLASS:
        raise CheckFailed(unread.format(what=f'that the node it returns is a '
                                             f'{course.WORKER_CLASS}'))
    groups = []
    for keyword, position in _WORKER_GROUPS:
        given = {k.arg: k.value for k in node.keywords}
        group = given.get(keyword, node.args[position] if len(node.args) > position else None)
        if group is None or (isinstance(group, ast.Constant) and group.value is None):
            groups.append(None)  # the node's default group, one for both timers
            continue
        made = made_by(module, function, group)
        if called_name(made) not in ('MutuallyExclusiveCallbackGroup', 'ReentrantCallbackGroup'):
            raise CheckFailed(unread.format(what=f'which callback group {keyword} is'))
        groups.append(made)
    slow, heartbeat = groups
    if slow is heartbeat and called_name(slow) != 'ReentrantCallbackGroup':
        raise CheckFailed('both timers are in one MutuallyExclusiveCallbackGroup (the node\'s '
                          'default, or one you made for both), which runs one of its callbacks '
                          'at a time; give each timer a group of its own.')


def check_responsive_worker() -> None:
    """Check part 4 of ``promises.py``: a slow callback no longer holds up the heartbeat.

    Calls your ``responsive_worker()`` for its node and executor and spins them for 2 s of
    wall-clock time, counting each timer's runs.  The heartbeat (10 Hz) must keep most of
    its rate while ``slow_work`` is busy; when it does not, the line says why, from the
    executor's type and the timers' callback groups.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: with the heartbeat's count and its cause.
    """
    judged('check_responsive_worker', _responsive_worker)


# ------------------------------------------------------------------ reusability
def _room_arguments_of(subject, room: str) -> list[str]:
    reply = subject.request('call', name=course.ROOMS_FUNCTION, inputs=[[room]])
    if reply.get('undefined'):
        raise CheckFailed(f'promises.py defines no function {course.ROOMS_FUNCTION}: write part 5 '
                          '(and run its cell).')
    output = reply['outputs'][0]
    if 'error' in output:
        raise learner_error(f"{course.ROOMS_FUNCTION}('{room}')", output['error'])
    result = output['result']
    if result['type'] not in ('list', 'tuple') or \
            any(item['type'] != 'str' for item in result['value']):
        raise CheckFailed(f"{course.ROOMS_FUNCTION}('{room}') returned {result['value']!r}; "
                          "return a list of strings, e.g. ['--ros-args', '-r', ...].")
    arguments = [item['value'] for item in result['value']]
    if '--ros-args' not in arguments:
        raise CheckFailed(f"{course.ROOMS_FUNCTION}('{room}') returned {arguments}: a node reads "
                          "only the arguments after '--ros-args'; start the list with it.")
    return arguments


def _rooms(judge: Judge) -> str:
    subject = judge.file_subject(course.PROMISES_FILE)
    seen: dict[str, str] = {}
    for room in course.ROOMS:
        arguments = _room_arguments_of(subject, room)
        reply = subject.request('room_nodes', arguments=arguments)
        if not reply['ok']:
            error = reply['error']
            raise CheckFailed(f"rclpy refused the arguments {arguments}: {error['type']}: "
                              f"{error['message'].splitlines()[0][:160]}")
        for name, namespace, endpoints in reply['nodes']:
            full = namespace.rstrip('/') + '/' + name
            found = judge.observer.endpoints(name, namespace, endpoints)
            if namespace != f'/{room}':
                raise CheckFailed(f"With {course.ROOMS_FUNCTION}('{room}') the node runs as "
                                  f'{full}; put it in the namespace /{room} (remap __ns) so '
                                  'that each room has its own nodes and topics.')
            kind = 'publisher' if name == course.SENSOR_NODE else 'subscription'
            endpoint_verdict(full, found, kind, f'/{room}/{course.TOPIC}', course.MESSAGE_TYPE)
            if full in seen:
                raise CheckFailed(f'Both rooms run a node {full}: use the room you are given.')
            seen[full] = room
    return (f'the same two nodes run as {", ".join(sorted(seen))}, each room on its own '
            f'/ROOM/{course.TOPIC}, as the ROS graph shows.')


def check_room_arguments() -> None:
    """Check part 5 of ``promises.py``: the arguments that make one package serve two rooms.

    Calls ``room_arguments('kitchen')`` and ``room_arguments('attic')``, starts a sensor and
    a monitor node with each list (as ``ros2 run ... --ros-args ...`` would) and reads the
    ROS graph: each room's nodes in their own namespace, talking on their own topic.

    Introduced in ``06-five-promises.ipynb``.

    :raises CheckFailed: naming the node or topic the graph shows and the one expected.
    """
    judged('check_room_arguments', _rooms)
