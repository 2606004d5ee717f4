"""The checks behind every part you write: each says in one line what is still wrong.

A check passes with one ``Check passed: ...`` line, or raises :class:`CheckFailed` whose
one line names your value, the expected one and what to change; when your own code
raised, you see its traceback (your lines only) instead.  Checks test behaviour (what a
node publishes and logs, what a function returns, how a process exits on Ctrl+C); they
never print the answer's code.

Checks of your files (notebooks 03-05) run in a judge process of their own
(:mod:`ros2nb.judge`), on a ROS domain of their own, so the nodes running in your kernel
neither disturb them nor are disturbed.  The grader runs the very same functions, in the
same way, on your submitted work; the points come from there, never from your kernel.
Checks of a function or class you defined in a cell (notebooks 00-02) call it right here
in the kernel; the grader runs those from the source of your answer cell.
"""

from __future__ import annotations

import ast
import configparser
import difflib
import math
import re
import shutil
import subprocess
import sys
from hashlib import sha256
from pathlib import Path
from typing import Any, Callable, Optional

from . import course
from .errors import CheckFailed, Ros2nbError
from .graph import node_endpoints
from .judge import (ARRIVAL_TIMEOUT_S, AnswerRef, Session, in_judge, learner_error,
                    run_in_judge, session, subject_env)
from .processes import interrupt, kill_process_group

__all__ = [
    'CheckFailed', 'check_dependencies', 'check_endpoint', 'check_entry_points',
    'check_expanded_path', 'check_monitor_callback', 'check_monitor_constructor',
    'check_monitor_main', 'check_monitor_readings', 'check_package_runs',
    'check_publisher_samples', 'check_sensor_callback', 'check_sensor_constructor',
    'check_sensor_hour', 'check_sensor_main', 'check_setup_cfg', 'package_dependencies',
]

#: Tolerance for values that went through a 32-bit float (°C).
FLOAT32_TOLERANCE_C = 1e-4
#: Simulated seconds the callback check runs the sensor, then each clamp probe.
CALLBACK_RUN_S, CLAMP_RUN_S = 20, 40
#: Seeds of ``random`` for the sensor checks (a clamp-less walk crosses both limits).
SENSOR_SEED, CEILING_SEED, FLOOR_SEED = 7, 2, 1
#: Where the clamp probes start the walk (°C): just inside the limits.
CLAMP_PROBES_C = (course.MAX_TEMPERATURE_C - 0.05, course.MIN_TEMPERATURE_C + 0.05)
#: Readings the monitor callback check sends: both boundaries and their neighbours (°C).
BOUNDARY_READINGS_C = (19.99, 20.0, 23.0, 26.0, 26.01, 18.5, 27.5)
#: Seconds a node process gets to exit after Ctrl+C (which comes once its node spins).
EXIT_AFTER_CTRL_C_S = 10.0


def passed(message: str) -> None:
    """Print the line a passing check shows."""
    print(f'Check passed: {message}')


def _judged(name: str, body: Callable[..., str], **arguments: Any) -> None:
    """Run ``body(session, **arguments)`` in the judge, starting one if this is the kernel."""
    if in_judge():
        passed(body(session(), **arguments))
    else:  # the judge calls the same public check, which knows its own arguments
        run_in_judge(name, {})


def _call(function: Callable[..., Any], *args: Any) -> Any:
    """Call the learner's function in the kernel; NotImplementedError becomes one line."""
    try:
        return function(*args)
    except NotImplementedError:
        raise CheckFailed(f'{function.__name__}() still raises NotImplementedError: replace '
                          '"raise NotImplementedError()" with your code and run its cell '
                          'again.') from None


def _require_ros() -> None:
    """Raise CheckFailed when ROS is not running in this kernel (e.g. after rclpy.shutdown())."""
    import rclpy
    if not rclpy.ok():
        raise CheckFailed('ROS 2 is not running in this kernel (was rclpy.shutdown() called?): '
                          'run ros2nb.shutdown(); ros2nb.start() and this cell again.')


# ----------------------------------------------------------- answer cells
def _answer_results(ref: AnswerRef, inputs: list[list[Any]]) -> list[dict]:
    """Call the learner's function ``ref`` (from their answer cell) in a subject."""
    subject = session().answer_subject(ref)
    reply = subject.request('call', name=ref.name, inputs=inputs)
    if reply.get('undefined'):
        raise CheckFailed(f'{ref.name} is not defined in your answer cell: define it there '
                          '(and run the cell) without renaming it.')
    return reply['outputs']


def _decoded(output: dict, label: str) -> Any:
    if 'error' in output:
        raise learner_error(label, output['error'])
    result = output['result']
    if result['type'] == 'Path':
        return Path(result['value'])
    if result['type'] in ('list', 'tuple'):
        return [item['value'] for item in result['value']]
    if result['type'] in ('str', 'float', 'int', 'bool', 'NoneType'):
        return result['value']
    return _Opaque(result['type'], result['value'])


class _Opaque:
    """A value of a type the judge does not rebuild; only its type and repr travel."""

    def __init__(self, type_name: str, text: str) -> None:
        self.type_name, self.text = type_name, text

    def __repr__(self) -> str:
        return self.text


def _type_name(value: Any) -> str:
    return value.type_name if isinstance(value, _Opaque) else type(value).__name__


# ------------------------------------------------------------- endpoints
def _endpoint_verdict(node: str, found: list[tuple[str, str, str]], kind: str, topic: str,
                      type_name: str) -> None:
    """Raise CheckFailed unless ``found`` holds a ``kind`` on ``topic`` of ``type_name``."""
    mine = {t: ty for k, t, ty in found if k == kind}
    if mine.get(topic) == type_name:
        return
    if topic in mine:
        raise CheckFailed(f'The {kind} of {node} on {topic} uses {mine[topic]}, but the topic '
                          f'carries {type_name}: import and pass that type.')
    if mine:
        have = ', '.join(f'{t} [{ty}]' for t, ty in sorted(mine.items()))
        close = difflib.get_close_matches(topic, list(mine), n=1)
        hint = (f': did you mean {topic}? Check the topic name' if close
                else ': check the topic name')
        raise CheckFailed(f'{node} has no {kind} on {topic} (it has: {have}){hint}.')
    raise CheckFailed(f'{node} has no {kind} yet: create one for {type_name} on {topic} in '
                      '__init__ and keep it in an attribute of the node.')


def check_endpoint(node_class: Any, kind: str, topic: str, type_name: str) -> None:
    """Check that a node class makes a publisher or subscription on ``topic`` with ``type_name``.

    In the kernel the node is created, inspected and destroyed again (ROS must be up);
    the grader creates it in a process of its own and reads the ROS graph.

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node_class: the class, e.g. ``LoudListener`` (no parentheses).
    :param kind: ``'publisher'`` or ``'subscription'``.
    :param topic: e.g. ``'/chatter'``.
    :param type_name: e.g. ``'std_msgs/msg/String'``.
    :raises CheckFailed: naming what the node has instead.
    """
    if isinstance(node_class, AnswerRef):
        name, found = _answer_node_endpoints(node_class)
    else:
        name, found = _kernel_node_endpoints(node_class)
    _endpoint_verdict(name, found, kind, topic, type_name)
    passed(f'{name} has a {kind} on {topic} [{type_name}].')


def _kernel_node_endpoints(node_class: Any) -> tuple[str, list]:
    _require_ros()
    from rclpy.node import Node
    node = _call(node_class)
    if not isinstance(node, Node):
        raise CheckFailed(f'Expected a node, got {type(node).__name__}: pass your Node '
                          'subclass itself, e.g. LoudListener (no parentheses).')
    try:
        return node.get_name(), node_endpoints(node)
    finally:
        node.destroy_node()


def _answer_node_endpoints(ref: AnswerRef) -> tuple[str, list]:
    judge = session()
    subject = judge.answer_subject(ref)
    reply = subject.request('new_node', cls=ref.name, placeholders=[], attributes=[], seed=None)
    if reply.get('no_class'):
        raise CheckFailed(f'{ref.name} is not defined in your answer cell as a Node subclass.')
    if reply.get('refused'):
        raise CheckFailed(reply['refused'])
    if not reply['ok']:
        raise learner_error(f'{ref.name}()', reply['error'])
    found = judge.observer.endpoints(reply['name'], reply['namespace'], reply['endpoints'])
    return reply['name'], found


# ------------------------------------------------------------- 01 and 02
def check_expanded_path(make_path: Any, *, ends_with: str) -> None:
    """Check the path a function returns is absolute, inside home and ends with ``ends_with``.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param make_path: the learner's function (called with no arguments).
    :param ends_with: how the path must end, e.g. ``'Documents/ROS2_and_RL_Tutorials'``.
    :raises CheckFailed: e.g. for the tutorial's ``/Documents/...`` (no ``~``).
    """
    if isinstance(make_path, AnswerRef):
        path = _decoded(_answer_results(make_path, [[]])[0], f'{make_path.name}()')
    else:
        path = _call(make_path)
    if not isinstance(path, Path):
        raise CheckFailed(f'{make_path.__name__}() returned {_type_name(path)} {path!r}; return '
                          'a pathlib.Path.')
    if '~' in str(path):
        raise CheckFailed(f'{path} still contains "~": Python does not expand it, call '
                          '.expanduser().')
    if Path.home() not in path.parents:
        raise CheckFailed(f'{path} is not inside your home folder {Path.home()}: a path that '
                          'starts with "/" starts at the root of the disk.')
    if not str(path).endswith(ends_with):
        raise CheckFailed(f'{path} should end with {ends_with}.')
    passed(f'{path} is inside your home folder.')


def package_dependencies(package_xml: Path) -> list[str]:
    """Return the ``<depend>`` entries of a package.xml, in order, as catkin_pkg reads them.

    A ``<depend>`` is needed to build, to export and to run, so it is a name that shows up
    in all three of catkin_pkg's lists.

    Introduced in ``02-create-a-package.ipynb``.

    :raises Ros2nbError: when the file is not a valid package.xml.
    """
    from catkin_pkg.package import InvalidPackage, parse_package
    try:
        package = parse_package(str(package_xml))
    except (InvalidPackage, OSError) as error:
        raise Ros2nbError(f'{package_xml} is not a valid package.xml: {error}') from None
    exported = {d.name for d in package.build_export_depends}
    run = {d.name for d in package.exec_depends}
    return [d.name for d in package.build_depends if d.name in exported and d.name in run]


#: package.xml files the grader feeds a learner's reader, beyond the course's own.
_EXTRA_PACKAGE_XML = '''<?xml version="1.0"?>
<package format="3">
  <name>graded_reader</name>
  <version>1.2.3</version>
  <description>A package.xml of the grader's own.</description>
  <maintainer email="grader@example.com">grader</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_python</buildtool_depend>
  <depend>geometry_msgs</depend>
  <test_depend>python3-pytest</test_depend>
  <depend>  rclpy  </depend>
  <depend>sensor_msgs</depend>
  <export><build_type>ament_python</build_type></export>
</package>
'''


def check_dependencies(reader: Any, package_xml: Optional[Path] = None) -> None:
    """Check a learner's package.xml reader against catkin_pkg, ROS's own reader.

    Introduced in ``02-create-a-package.ipynb``.

    :param reader: the learner's function, ``reader(path) -> list[str]``.
    :param package_xml: the file to read; default the course package's in the workspace.
        The grader also feeds a package.xml of its own.
    :raises CheckFailed: when the result differs from the file's ``<depend>`` tags.
    """
    from .workspace import current_workspace
    files = [Path(package_xml) if package_xml else current_workspace() / course.PACKAGE_XML_FILE]
    if not files[0].is_file():
        raise CheckFailed(f'{files[0]} does not exist: run the pkg_create cell above first.')
    if isinstance(reader, AnswerRef):
        extra = session().scratch / 'graded_reader' / 'package.xml'
        extra.parent.mkdir(parents=True, exist_ok=True)
        extra.write_text(_EXTRA_PACKAGE_XML)
        files.append(extra)
        outputs = _answer_results(reader, [[{'path': str(f)}] for f in files])
        results = [_decoded(o, f'{reader.name}(package_xml)') for o in outputs]
    else:
        results = [_call(reader, f) for f in files]
    for file, got in zip(files, results):
        want = package_dependencies(file)
        if not isinstance(got, list):
            raise CheckFailed(f'{reader.__name__}() returned {_type_name(got)}; return a list of '
                              'names.')
        if got != want:
            raise CheckFailed(f'For {file.parent.name}/package.xml you returned {got}, but it '
                              f'declares {want}: read the text of each <depend> element, in '
                              'order, without spaces around it (test_depend is not a depend).')
    passed(f'package.xml depends on {", ".join(package_dependencies(files[0]))}.')


# ------------------------------------------------------------- nodes in files
def _new_node(judge: Session, relative: str, cls: str, *, placeholders: tuple[str, ...] = (),
              attributes: tuple[str, ...] = (), seed: Optional[int] = None) -> tuple[Any, dict]:
    """Create the learner's node from their file in a subject; raise for what went wrong."""
    subject = judge.file_subject(relative)
    reply = subject.request('new_node', cls=cls, placeholders=list(placeholders),
                            attributes=list(attributes), seed=seed)
    file = Path(relative).name
    if reply.get('no_class'):
        others = reply['classes']
        hint = (f' (it defines {", ".join(others)}: names must match exactly; the tutorial '
                'misspelt TemperaturSensor in places)' if others else '')
        raise CheckFailed(f'{file} defines no class {cls}{hint}.')
    if reply.get('refused'):
        raise CheckFailed(reply['refused'])
    if not reply['ok']:
        raise learner_error(f'{cls}()', reply['error'])
    return subject, reply


def _node_name_verdict(info: dict, want: str) -> None:
    if info['name'] != want:
        raise CheckFailed(f"The node is called {info['name']}; name it {want} in its "
                          'super().__init__(...) call.')


def _started_log_verdict(judge: Session, info: dict, mark: int, cls: str) -> None:
    if info['started_lines'] == 0 or not _caught_up(judge, info, mark, info['started_lines']):
        raise CheckFailed(f'{cls} logged nothing when it started: log a line such as '
                          f"'{cls[:11]} {cls[11:]} Node Started' with the node's logger.")


def _sensor_verdict(info: dict, found: list) -> None:
    """Publisher, timer and start value of a freshly created sensor."""
    _node_name_verdict(info, course.SENSOR_NODE)
    _endpoint_verdict(info['name'], found, 'publisher', '/' + course.TOPIC, course.MESSAGE_TYPE)
    timers = info['timers']
    if not timers:
        raise CheckFailed(f'{course.SENSOR_CLASS} has no timer: create one in __init__ that calls '
                          f'self.publish_temperature every PUBLISH_PERIOD_S = '
                          f'{course.PUBLISH_PERIOD_S} s.')
    if len(timers) > 1:
        raise CheckFailed(f'{course.SENSOR_CLASS} has {len(timers)} timers; one timer calling '
                          'publish_temperature is all it needs.')
    period_ns, callback = timers[0]
    if callback != 'publish_temperature':
        raise CheckFailed(f'The timer calls {callback}; it must call self.publish_temperature '
                          '(the method itself, without parentheses).')
    if not math.isclose(period_ns / 1e9, course.PUBLISH_PERIOD_S):
        raise CheckFailed(f'The timer fires every {period_ns / 1e9:g} s; the sensor publishes '
                          f'every {course.PUBLISH_PERIOD_S} s (PUBLISH_PERIOD_S).')
    start = info['attributes'].get('temperature')
    if start is None:
        raise CheckFailed(f'{course.SENSOR_CLASS} has no attribute temperature: start the walk '
                          'in __init__ with self.temperature = START_TEMPERATURE_C.')
    if start['type'] not in ('float', 'int') or not math.isclose(start['value'],
                                                                 course.START_TEMPERATURE_C):
        raise CheckFailed(f'self.temperature starts at {start["value"]!r}; the walk starts at '
                          f'START_TEMPERATURE_C = {course.START_TEMPERATURE_C} °C.')


def _sensor_constructor(judge: Session) -> str:
    mark = len(judge.observer.logs)
    _subject, info = _new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                               placeholders=('publish_temperature',), attributes=('temperature',))
    found = judge.observer.endpoints(info['name'], info['namespace'], info['endpoints'])
    _sensor_verdict(info, found)
    _started_log_verdict(judge, info, mark, course.SENSOR_CLASS)
    return (f'{info["name"]} publishes {course.MESSAGE_TYPE} on /{course.TOPIC} every '
            f'{course.PUBLISH_PERIOD_S} s, starting at {course.START_TEMPERATURE_C} °C.')


def check_sensor_constructor() -> None:
    """Check part 3 of ``temperature_publisher.py``: the sensor's ``__init__``.

    Creates your ``TemperatureSensor`` (a stand-in replaces ``publish_temperature`` if part
    4 is not written yet) and checks its name, its publisher (topic and type, as the ROS
    graph shows them), its timer (period and callback), the start value of
    ``self.temperature`` and its start-up log line.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    _judged('check_sensor_constructor', _sensor_constructor)


def _caught_up(judge: Session, info: dict, mark: int, lines: int) -> list[str]:
    """Wait until the judge has ``lines`` log lines of the node after ``mark``; return them."""
    observer = judge.observer
    observer.wait_until(lambda: len(observer.lines_of(info['name'], mark)) >= lines,
                        ARRIVAL_TIMEOUT_S)
    return observer.lines_of(info['name'], mark)


def _run_sensor(judge: Session, subject: Any, info: dict, seconds: int, *,
                step_s: float = 1.0, seed: Optional[int] = None) -> tuple[list[float], int, int]:
    """Run the sensor ``seconds`` simulated seconds; return readings, log lines, firings.

    The readings and log lines are what arrived at the judge's own subscriptions, over
    ROS; the subject's counts only tell the judge how long to wait for them.
    """
    observer = judge.observer
    topic = '/' + course.TOPIC
    observer.watch_readings(topic)
    if not subject.request('wait_matched', topic=topic, seconds=ARRIVAL_TIMEOUT_S)['ok']:
        raise CheckFailed(f'The publisher on {topic} never reached the grader\'s subscription: '
                          f'check its topic name and its type ({course.MESSAGE_TYPE}).')
    base = subject.request('counts')
    first, log_mark = len(observer.readings), len(observer.logs)
    reply = base
    for number in range(math.ceil(seconds / step_s)):
        reply = subject.request('advance', seconds=step_s, seed=seed if number == 0 else None)
        if reply['failure']:
            failure = reply['failure']
            raise learner_error(failure['callback'], failure)
        want = reply['published'].get(topic, 0) - base['published'].get(topic, 0)
        if not observer.wait_until(lambda: len(observer.readings) - first >= want,
                                   ARRIVAL_TIMEOUT_S):
            raise CheckFailed(f'The node published {want} readings, but only '
                              f'{len(observer.readings) - first} arrived: is something else '
                              'wrong with the publisher (its queue depth)?')
    lines = _caught_up(judge, info, log_mark, reply['logged'] - base['logged'])
    return observer.readings[first:], len(lines), reply['fired'] - base['fired']


def _samples_verdict(samples: list[float], *, seconds: float,
                     start_c: float = course.START_TEMPERATURE_C) -> None:
    """Raise CheckFailed for the first rule a run of readings breaks."""
    low, high = course.MIN_TEMPERATURE_C, course.MAX_TEMPERATURE_C
    if abs(len(samples) - seconds / course.PUBLISH_PERIOD_S) > 1:
        raise CheckFailed(f'{len(samples)} readings in {seconds:g} s; expected one every '
                          f'{course.PUBLISH_PERIOD_S} s: check the timer period.')
    if samples and abs(samples[0] - start_c) > course.MAX_STEP_C + FLOAT32_TOLERANCE_C:
        raise CheckFailed(f'The first reading is {samples[0]:.2f} °C, but self.temperature was '
                          f'{start_c} °C: each reading is the previous self.temperature plus one '
                          f'step of at most ±{course.MAX_STEP_C} °C.')
    for i, (a, b) in enumerate(zip(samples, samples[1:]), start=2):
        if abs(b - a) > course.MAX_STEP_C + FLOAT32_TOLERANCE_C:
            raise CheckFailed(f'Reading {i} jumps {b - a:+.2f} °C ({a:.2f} to {b:.2f}); one step '
                              f'is at most ±{course.MAX_STEP_C} °C (MAX_STEP_C).')
    if len(samples) > 2 and max(samples) - min(samples) < FLOAT32_TOLERANCE_C:
        raise CheckFailed(f'Every reading is {samples[0]:.2f} °C: add a random step between '
                          f'-MAX_STEP_C and +MAX_STEP_C to self.temperature each time.')
    for value in samples:
        if value > high + FLOAT32_TOLERANCE_C:
            raise CheckFailed(f'A reading of {value:.2f} °C is above MAX_TEMPERATURE_C = {high} °C: '
                              f'clamp every new reading into [{low}, {high}].')
        if value < low - FLOAT32_TOLERANCE_C:
            tutorial = (' (the tutorial\'s floor of 10.2 °C lets it fall too far)'
                        if value >= 10.2 - FLOAT32_TOLERANCE_C else '')
            raise CheckFailed(f'A reading of {value:.2f} °C is below MIN_TEMPERATURE_C = {low} '
                              f'°C{tutorial}: clamp every new reading into [{low}, {high}].')


def check_publisher_samples(samples: list[float], *, seconds: float) -> None:
    """Check a recorded run of the sensor: one reading per second, walk and clamp respected.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param samples: readings in °C in the order received.
    :param seconds: simulated seconds the sensor ran.
    :raises CheckFailed: naming the first rule broken.
    """
    _samples_verdict(samples, seconds=seconds)
    passed(f'{len(samples)} readings, one every {course.PUBLISH_PERIOD_S} s, steps within '
           f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
           f'{course.MAX_TEMPERATURE_C}] °C.')


def _sensor_callback(judge: Session) -> str:
    subject, info = _new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                              attributes=('temperature',), seed=SENSOR_SEED)
    _sensor_verdict(info, judge.observer.endpoints(info['name'], info['namespace'],
                                                   info['endpoints']))
    readings, logged, fired = _run_sensor(judge, subject, info, CALLBACK_RUN_S, seed=SENSOR_SEED)
    if not readings:
        raise CheckFailed('publish_temperature ran but nothing arrived on /temperature: put the '
                          'new reading into a Float32 message and publish it with the publisher '
                          'from __init__.' if fired else
                          'The timer never called publish_temperature: check the timer in part 3.')
    if logged < len(readings):
        raise CheckFailed(f'{len(readings)} readings were published but {logged} logged: log each '
                          "reading with the node's logger, e.g. 'Publishing: 22.31C'.")
    _samples_verdict(readings, seconds=CALLBACK_RUN_S)
    for start_c, seed in zip(CLAMP_PROBES_C, (CEILING_SEED, FLOOR_SEED)):
        subject.request('set_attribute', name='temperature', value=start_c)
        probe, _, _ = _run_sensor(judge, subject, info, CLAMP_RUN_S, seed=seed)
        _samples_verdict(probe, seconds=CLAMP_RUN_S, start_c=start_c)
    return (f'{len(readings)} readings, one every {course.PUBLISH_PERIOD_S} s, from '
            f'{course.START_TEMPERATURE_C} °C in steps of at most ±{course.MAX_STEP_C} °C, held '
            f'inside [{course.MIN_TEMPERATURE_C}, {course.MAX_TEMPERATURE_C}] °C.')


def check_sensor_callback() -> None:
    """Check part 4 of ``temperature_publisher.py``: the timer callback.

    Runs your sensor for 20 simulated seconds and watches ``/temperature`` over ROS: one
    reading per second, the first within 0.5 °C of 22.0, steps of at most ±0.5 °C, one
    log line per reading; then starts the walk just inside each limit and checks that the
    clamp holds it in [18.0, 28.0] °C.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    _judged('check_sensor_callback', _sensor_callback)


def _sensor_hour(judge: Session) -> str:
    subject, info = _new_node(judge, course.PUBLISHER_FILE, course.SENSOR_CLASS,
                              attributes=('temperature',), seed=SENSOR_SEED + 1)
    _sensor_verdict(info, judge.observer.endpoints(info['name'], info['namespace'],
                                                   info['endpoints']))
    seconds = 3600
    readings, _, _ = _run_sensor(judge, subject, info, seconds, step_s=5.0)
    _samples_verdict(readings, seconds=seconds)
    return (f'an hour of simulated time: {len(readings)} readings, steps within '
            f'±{course.MAX_STEP_C} °C, all inside [{course.MIN_TEMPERATURE_C}, '
            f'{course.MAX_TEMPERATURE_C}] °C.')


def check_sensor_hour() -> None:
    """Hidden test of notebook 03: your sensor over one simulated hour (3600 readings).

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming the first rule broken.
    """
    _judged('check_sensor_hour', _sensor_hour)


# ------------------------------------------------------------------ main()
def _function(tree: ast.Module, name: str) -> Optional[ast.FunctionDef]:
    return next((s for s in tree.body if isinstance(s, ast.FunctionDef) and s.name == name), None)


def _calls(nodes: list[ast.stmt]) -> set[str]:
    names = set()
    for statement in nodes:
        for node in ast.walk(statement):
            if isinstance(node, ast.Call):
                func = node.func
                names.add(func.attr if isinstance(func, ast.Attribute) else
                          func.id if isinstance(func, ast.Name) else '')
    return names


def _cleanup_verdict(main: ast.FunctionDef) -> None:
    """main() must destroy its node and shut rclpy down, in a ``finally:`` block."""
    in_finally = _calls([s for node in ast.walk(main) if isinstance(node, ast.Try)
                         for s in node.finalbody])
    anywhere = _calls(main.body)
    if 'destroy_node' not in anywhere:
        raise CheckFailed('main() never destroys its node: call node.destroy_node() when the '
                          'spin ends (the tutorial\'s subscriber forgot it).')
    if not anywhere & {'try_shutdown', 'shutdown'}:
        raise CheckFailed('main() never shuts rclpy down: call rclpy.try_shutdown() when the '
                          'spin ends.')
    if 'destroy_node' not in in_finally or not in_finally & {'try_shutdown', 'shutdown'}:
        raise CheckFailed('main() cleans up only when the spin ends normally: destroy the node '
                          'and call rclpy.try_shutdown() in a finally: block.')


def _main(judge: Session, relative: str, node_name: str) -> str:
    path = judge.workspace / relative
    if not path.is_file():
        raise CheckFailed(f'{path.name} does not exist yet: run the %%part cells that write it.')
    try:
        tree = ast.parse(path.read_text())
    except SyntaxError as error:
        raise CheckFailed(f'{path.name} line {error.lineno}: SyntaxError: {error.msg}.') from None
    main = _function(tree, 'main')
    if main is None:
        raise CheckFailed(f'{path.name} has no main() function yet: write part 5.')
    observer = judge.observer
    judge.drop(('file', relative))  # the node runs alone, as in a terminal: one of its name
    proc, output = judge.start([sys.executable, str(path)], cwd=judge.workspace)
    # Ctrl+C once the node spins (it answers a parameter call), as a learner presses it
    # once the node runs: earlier, a busy machine would decide what the learner is told.
    observer.wait_until(lambda: proc.poll() is not None or observer.has_node(node_name),
                        ARRIVAL_TIMEOUT_S)
    if proc.poll() is None:
        observer.spins(node_name)
    if proc.poll() is not None:
        text = output.text()
        if 'NotImplementedError' in text:
            raise CheckFailed('main() still raises NotImplementedError: write part 5 where it '
                              'says YOUR CODE HERE.')
        if 'Traceback' in text:
            raise CheckFailed(f'{path.name} crashed before Ctrl+C ({_last_line(text)}): fix that '
                              'first; the checks of the parts above show where.')
        raise CheckFailed(f'{path.name} ended by itself before Ctrl+C (exit code '
                          f'{proc.returncode}); main() should spin until Ctrl+C.')
    interrupt(proc)
    try:
        code = proc.wait(EXIT_AFTER_CTRL_C_S)
    except subprocess.TimeoutExpired:
        kill_process_group(proc)
        raise CheckFailed(f'{path.name} did not stop within {EXIT_AFTER_CTRL_C_S:g} s of Ctrl+C: '
                          'let KeyboardInterrupt end the spin.') from None
    text = output.text()
    if code != 0 or 'Traceback' in text:
        last = _error_line(text)
        raise CheckFailed(f'{path.name} exited with code {code} after Ctrl+C ({last}): '
                          f'{_ctrl_c_advice(main, last)}.')
    _cleanup_verdict(main)
    return (f'{path.name} stops cleanly on Ctrl+C (exit code 0, no traceback) and cleans up in '
            'finally.')


def _caught(main: ast.FunctionDef) -> set[str]:
    """The exception names ``main()``'s ``except`` clauses catch."""
    names: set[str] = set()
    for node in ast.walk(main):
        if isinstance(node, ast.ExceptHandler) and node.type is not None:
            for part in ast.walk(node.type):
                if isinstance(part, (ast.Name, ast.Attribute)):
                    names.add(part.id if isinstance(part, ast.Name) else part.attr)
    return names


def _ctrl_c_advice(main: ast.FunctionDef, error: str) -> str:
    """What to change in main(), from how it failed after Ctrl+C and what it catches."""
    caught = _caught(main)
    if 'rcl_shutdown already called' in error and \
            {'KeyboardInterrupt', 'ExternalShutdownException'} <= caught:
        return ('shut down with rclpy.try_shutdown() instead of rclpy.shutdown(): on Jazzy '
                'Ctrl+C has already shut rclpy down')
    missing = [name for name in ('KeyboardInterrupt', 'ExternalShutdownException')
               if name not in caught]
    if missing:
        return (f'catch {" and ".join(missing)} around the spin (both end it on Jazzy), and shut '
                'down with rclpy.try_shutdown()')
    return 'clean up in a finally: block with node.destroy_node() and rclpy.try_shutdown()'


def _error_line(text: str) -> str:
    """The last line of a traceback, without module paths or rcl's C source location."""
    line = _last_line(text)
    line = re.sub(r'^(?:[A-Za-z_][\w]*\.)+(?=\w+(?:Error|Exception)\b)', '', line)
    return re.sub(r', at /\S+:\d+$', '', line)


def _last_line(text: str) -> str:
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    return lines[-1][:200] if lines else 'no output'


def check_sensor_main() -> None:
    """Check part 5 of ``temperature_publisher.py``: ``main()`` and Ctrl+C.

    Starts the file as a program (``python temperature_publisher.py``), presses Ctrl+C
    after 2 s and checks for exit code 0 and no traceback; then that ``main()`` destroys
    the node and shuts rclpy down in a ``finally:`` block.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    _judged('check_sensor_main', _main, relative=course.PUBLISHER_FILE,
            node_name=course.SENSOR_NODE)


def check_monitor_main() -> None:
    """Check part 5 of ``temperature_subscriber.py``: ``main()`` and Ctrl+C.

    As :func:`check_sensor_main`, for the monitor.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: with the process's last line.
    """
    _judged('check_monitor_main', _main, relative=course.SUBSCRIBER_FILE,
            node_name=course.MONITOR_NODE)


# ------------------------------------------------------------------ the monitor
def _monitor_verdict(info: dict, found: list) -> None:
    _node_name_verdict(info, course.MONITOR_NODE)
    _endpoint_verdict(info['name'], found, 'subscription', '/' + course.TOPIC,
                      course.MESSAGE_TYPE)


def _monitor_constructor(judge: Session) -> str:
    mark = len(judge.observer.logs)
    _subject, info = _new_node(judge, course.SUBSCRIBER_FILE, course.MONITOR_CLASS,
                               placeholders=('temperature_callback',))
    _monitor_verdict(info, judge.observer.endpoints(info['name'], info['namespace'],
                                                    info['endpoints']))
    _started_log_verdict(judge, info, mark, course.MONITOR_CLASS)
    return f'{info["name"]} subscribes to /{course.TOPIC} [{course.MESSAGE_TYPE}].'


def check_monitor_constructor() -> None:
    """Check part 3 of ``temperature_subscriber.py``: the monitor's ``__init__``.

    Creates your ``TemperatureMonitor`` and checks its name, its subscription (topic and
    type, from the ROS graph) and its start-up log line.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming your value and the expected one.
    """
    _judged('check_monitor_constructor', _monitor_constructor)


def _feed_monitor(judge: Session, readings: tuple[float, ...] | list[float]) -> list[list[str]]:
    """Publish readings to the learner's monitor (from the judge); return its lines per reading."""
    from std_msgs.msg import Float32
    observer = judge.observer
    mark = len(observer.logs)
    subject, info = _new_node(judge, course.SUBSCRIBER_FILE, course.MONITOR_CLASS)
    _monitor_verdict(info, observer.endpoints(info['name'], info['namespace'], info['endpoints']))
    _caught_up(judge, info, mark, info['started_lines'])
    publisher = judge.probe_publisher
    if not observer.wait_until(lambda: publisher.get_subscription_count() >= 1,
                               ARRIVAL_TIMEOUT_S):
        raise CheckFailed(f'The grader\'s publisher on /{course.TOPIC} never reached your '
                          'subscription: check its topic name and type.')
    per_reading = []
    before = subject.request('counts')
    for value in readings:
        mark = len(observer.logs)
        publisher.publish(Float32(data=value))
        reply = subject.request('wait_received', count=before['received'] + 1,
                                seconds=ARRIVAL_TIMEOUT_S)
        if reply['failure']:
            failure = reply['failure']
            raise learner_error(failure['callback'], failure, context=f' for {value} °C')
        if not reply['ok']:
            raise CheckFailed(f'The reading {value} °C never reached temperature_callback: is it '
                              'the subscription\'s callback?')
        per_reading.append(_caught_up(judge, info, mark, reply['logged'] - before['logged']))
        before = reply
    return per_reading


def _statuses_verdict(readings: tuple[float, ...] | list[float], lines: list[list[str]], *,
                      with_value: bool) -> None:
    words = re.compile(r'\b(High|Low|Normal)\b')
    for value, said in zip(readings, lines):
        want = course.monitor_status(value)
        if not said:
            raise CheckFailed(f'For a reading of {value} °C the monitor logged nothing: log one '
                              'line with the reading and its status.')
        if len(said) > 1:
            raise CheckFailed(f'For a reading of {value} °C the monitor logged {len(said)} lines; '
                              'log exactly one per message.')
        found = words.findall(said[0])
        if not found:
            lower = re.search(r'\b(high|low|normal)\b', said[0], re.IGNORECASE)
            if lower:
                raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}": write the '
                                  f'status {lower.group(0).capitalize()}, with a capital letter, '
                                  f'as High, Low and Normal are written.')
            raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}", without a status: '
                              'add High, Low or Normal to the line.')
        if found != [want]:
            rule = (f'only readings strictly above {course.HIGH_ABOVE_C} °C are High and strictly '
                    f'below {course.LOW_BELOW_C} °C Low')
            raise CheckFailed(f'For {value} °C the monitor said {", ".join(found)}; it should say '
                              f'{want}: {rule}.')
        if with_value and f'{value:.2f}' not in said[0]:
            raise CheckFailed(f'For {value} °C the monitor logged "{said[0]}": show the reading '
                              'with two decimals, e.g. 23.00.')


def _monitor_callback(judge: Session) -> str:
    lines = _feed_monitor(judge, BOUNDARY_READINGS_C)
    _statuses_verdict(BOUNDARY_READINGS_C, lines, with_value=False)
    return (f'one line with the right status for each of {len(BOUNDARY_READINGS_C)} readings, '
            f'including {course.LOW_BELOW_C} and {course.HIGH_ABOVE_C} °C (both Normal).')


def check_monitor_callback() -> None:
    """Check part 4 of ``temperature_subscriber.py``: the callback and its statuses.

    The judge publishes readings around both thresholds (19.99, 20.0, 26.0, 26.01 °C and
    more) to your monitor over ROS and reads its log lines from ``/rosout``: exactly one
    line per message, naming High, Low or Normal correctly.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming the reading, what your monitor said and the rule.
    """
    _judged('check_monitor_callback', _monitor_callback)


def _monitor_readings(judge: Session) -> str:
    import random
    chooser = random.Random(2024)
    readings = [round(chooser.uniform(17.0, 29.0), 2) for _ in range(30)]
    readings += [course.LOW_BELOW_C, course.HIGH_ABOVE_C, 19.995, 26.005]
    lines = _feed_monitor(judge, readings)
    _statuses_verdict(readings, lines, with_value=True)
    return f'the right status and the reading in one line for each of {len(readings)} readings.'


def check_monitor_readings() -> None:
    """Hidden test of notebook 04: 34 readings from the grader's own publisher.

    Random readings over the whole range and the boundaries; every one must give one line
    with the reading (two decimals) and the right status.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming the first reading handled wrongly.
    """
    _judged('check_monitor_readings', _monitor_readings)


# ------------------------------------------------------------------ the package
#: The grader's own stand-in nodes, so notebook 05 is graded on its own: they take the
#: place of temperature_publisher.py and temperature_subscriber.py in the judge's build.
#: Each is this program with its node's name and what the node does.
STAND_IN = '''\
"""Grader's stand-in {name}: a node that only {does}."""
import rclpy
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from std_msgs.msg import Float32


def main(args=None):
    rclpy.init(args=args)
    node = Node('{name}')
    {setup}
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()
'''
STAND_IN_PUBLISHER = STAND_IN.format(
    name=course.SENSOR_NODE, does='publishes a constant reading five times a second',
    setup="publisher = node.create_publisher(Float32, 'temperature', 10)\n"
          "    node.create_timer(0.2, lambda: publisher.publish(Float32(data=21.5)))")
STAND_IN_SUBSCRIBER = STAND_IN.format(
    name=course.MONITOR_NODE, does='logs every reading it hears',
    setup="node.create_subscription(Float32, 'temperature',\n"
          "                             lambda m: node.get_logger().info(f'heard {m.data:.2f}'), 10)")
PLACEHOLDER = 'raise NotImplementedError'


def _package_source(judge: Session) -> Path:
    source = judge.workspace / 'src' / course.PACKAGE
    if not (source / 'package.xml').is_file():
        raise CheckFailed(f'The package {course.PACKAGE} does not exist in your workspace: create '
                          'it (notebook 02, or run the catch_up cell at the top).')
    return source


def _console_scripts(setup_py: Path) -> Optional[list[Any]]:
    """The ``console_scripts`` list of ``setup(entry_points=...)`` as written, or None."""
    try:
        tree = ast.parse(setup_py.read_text())
    except (SyntaxError, OSError):
        return None  # the build says where
    for node in ast.walk(tree):
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values):
                if isinstance(key, ast.Constant) and key.value == 'console_scripts' \
                        and isinstance(value, ast.List):
                    return value.elts
    return None


def _entry_point_syntax_verdict(setup_py: Path) -> None:
    """Each console_scripts string must read ``NAME = package.module:function``."""
    from importlib.metadata import EntryPoint
    for element in _console_scripts(setup_py) or []:
        if not (isinstance(element, ast.Constant) and isinstance(element.value, str)):
            continue
        entry = element.value
        if entry.count('=') > 1:
            raise CheckFailed(f'"{entry[:70]}..." is two entries run together: end each string '
                              'in the console_scripts list with a comma.')
        name, _, target = entry.partition('=')
        match = EntryPoint.pattern.match(target.strip()) if name.strip() else None
        if match is None or not match.group('attr'):
            raise CheckFailed(f'"{entry}" is not written NAME = package.module:function: the '
                              'module is written with dots, like an import, without .py, and '
                              'the function follows a colon.')


def _built(judge: Session) -> Path:
    """Build a copy of the learner's package, with the grader's stand-in nodes; cached.

    :return: the copy's workspace (with ``install/``).
    :raises CheckFailed: with the build's cause in one line.
    """
    source = _package_source(judge)
    files = sorted(p for p in source.rglob('*') if p.is_file() and '__pycache__' not in p.parts)
    digest = sha256(b''.join(p.relative_to(source).as_posix().encode() + p.read_bytes()
                             for p in files)).hexdigest()[:12]
    if digest in judge.builds:
        return judge.builds[digest]
    for name in ('setup.py', 'setup.cfg'):
        if (source / name).is_file() and PLACEHOLDER in (source / name).read_text():
            raise CheckFailed(f'{name} still holds the placeholder "raise NotImplementedError()": '
                              'replace it with your lines and run that cell again.')
    _entry_point_syntax_verdict(source / 'setup.py')
    ws = judge.scratch / f'build-{digest}'
    package = ws / 'src' / course.PACKAGE
    shutil.copytree(source, package, ignore=shutil.ignore_patterns('__pycache__', '*.egg-info'))
    for module, text in ((course.PUBLISHER_EXECUTABLE, STAND_IN_PUBLISHER),
                         (course.SUBSCRIBER_EXECUTABLE, STAND_IN_SUBSCRIBER)):
        (package / course.PACKAGE / f'{module}.py').write_text(text)
    from .workspace import _build_cause, _venv_tool
    colcon = _venv_tool('colcon')
    if colcon is None:
        raise Ros2nbError('colcon is not installed: run `make lab` or `make test`.')
    code, output = judge.run([colcon, 'build'], seconds=300, cwd=ws)
    if code != 0:
        raise CheckFailed(f'colcon build of your package failed: '
                          f'{_build_cause(output.splitlines())}')
    judge.builds[digest] = ws
    return ws


def _entry_points(judge: Session) -> str:
    ws = _built(judge)
    found = sorted(ws.glob(f'install/{course.PACKAGE}/lib/python*/site-packages/'
                           f'{course.PACKAGE}*-info/entry_points.txt'))
    scripts: dict[str, str] = {}
    if found:
        config = configparser.ConfigParser()
        config.read(found[0])
        if config.has_section('console_scripts'):
            scripts = {k: v.strip() for k, v in config.items('console_scripts')}
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        want = f'{course.PACKAGE}.{executable}:main'
        if executable not in scripts:
            have = ', '.join(f'{k} = {v}' for k, v in sorted(scripts.items())) or 'none'
            raise CheckFailed(f'console_scripts has no entry named {executable} (it has: {have}); '
                              'the name left of = is what you pass to ros2 run.')
        if scripts[executable].replace(' ', '') != want:
            raise CheckFailed(f'{executable} = {scripts[executable]}: it should start main() in '
                              f'{course.PACKAGE}/{executable}.py, written {want}.')
    return (f'console_scripts gives {course.PUBLISHER_EXECUTABLE} and '
            f'{course.SUBSCRIBER_EXECUTABLE}, each starting main() of its module.')


def check_entry_points() -> None:
    """Check the ``console_scripts`` entry points in ``setup.py`` (notebook 05).

    Builds a copy of your package with colcon (the grader's stand-in nodes take the place
    of your two node files, so only this notebook's work counts) and reads the entry
    points setuptools installed.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the missing or wrong entry, or the build's cause.
    """
    _judged('check_entry_points', _entry_points)


def _setup_cfg(judge: Session) -> str:
    file = _package_source(judge) / 'setup.cfg'
    if not file.is_file():
        raise CheckFailed('setup.cfg is missing: without it ros2 run finds no executable; '
                          'write it (the cell above).')
    text = file.read_text()
    if PLACEHOLDER in text:
        raise CheckFailed('setup.cfg still holds the placeholder "raise NotImplementedError()": '
                          'write the two settings in its place.')
    config = configparser.ConfigParser()
    try:
        config.read_string(text)
    except configparser.Error as error:
        raise CheckFailed(f'setup.cfg cannot be read: {str(error).splitlines()[0]}') from None
    want = f'$base/lib/{course.PACKAGE}'
    for section, key in (('develop', 'script_dir'), ('install', 'install_scripts')):
        got = config.get(section, key, fallback=None)
        if got is None:
            raise CheckFailed(f'setup.cfg has no {key} in its [{section}] section; ros2 run '
                              f'looks in {want}.')
        if got.strip() != want:
            raise CheckFailed(f'[{section}] {key} is {got.strip()}; ros2 run looks in {want}.')
    ws = _built(judge)
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        if not (ws / 'install' / course.PACKAGE / 'lib' / course.PACKAGE / executable).is_file():
            raise CheckFailed(f'After the build there is no lib/{course.PACKAGE}/{executable}: '
                              'check the entry points in setup.py.')
    return f'setup.cfg installs the executables into lib/{course.PACKAGE}, where ros2 run looks.'


def check_setup_cfg() -> None:
    """Check ``setup.cfg``: executables go to ``lib/sensor_simulator``, where ros2 run looks.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: naming the setting and the expected value.
    """
    _judged('check_setup_cfg', _setup_cfg)


def _package_runs(judge: Session) -> str:
    from .workspace import find_executable, source_workspace
    ws = _built(judge)
    env = source_workspace(ws)
    argvs = []
    for executable in (course.PUBLISHER_EXECUTABLE, course.SUBSCRIBER_EXECUTABLE):
        try:
            argvs.append([str(find_executable(course.PACKAGE, executable, env))])
        except Ros2nbError as error:
            raise CheckFailed(f'ros2 run {course.PACKAGE} {executable}: {error}') from None
    env.update({k: v for k, v in subject_env().items()  # the judge's domain and transports
                if k.startswith(('ROS_', 'RCUTILS', 'FASTDDS', 'PYTHONUNBUFFERED'))})
    observer = judge.observer
    mark = len(observer.logs)
    started = [judge.start(argv, cwd=ws, env=env) for argv in argvs]
    procs, outputs = [proc for proc, _ in started], [output for _, output in started]
    try:
        heard = observer.wait_until(lambda: observer.lines_of(course.MONITOR_NODE, mark),
                                    ARRIVAL_TIMEOUT_S)
        for proc in procs:
            interrupt(proc)
        codes = []
        for proc in procs:
            try:
                codes.append(proc.wait(EXIT_AFTER_CTRL_C_S))
            except subprocess.TimeoutExpired:
                codes.append(kill_process_group(proc))
    finally:
        for proc in procs:
            kill_process_group(proc)
    if not heard:
        raise CheckFailed('ros2 run started both executables, but the monitor heard no reading: '
                          f'{_last_line(outputs[0].text())}')
    if codes != [0, 0]:
        raise CheckFailed(f'After Ctrl+C the executables exited with {codes}, expected [0, 0].')
    return 'ros2 run starts both entry points; they talk over /temperature and stop on Ctrl+C.'


def check_package_runs() -> None:
    """Hidden test of notebook 05: the built package runs with ``ros2 run``.

    Builds your package (with the grader's stand-in nodes), finds both executables the way
    ``ros2 run`` does, starts them, waits until the monitor hears the sensor, then sends
    Ctrl+C and expects exit code 0 from both.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: with the CLI's error or the exit codes.
    """
    _judged('check_package_runs', _package_runs)
