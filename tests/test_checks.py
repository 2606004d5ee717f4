"""The checks of every part, against the mistakes learners make: one line each, never the answer.

Each case writes the course's reference node with one real mistake into a workspace and
runs the check as the grader does (a judge in this process, the learner's code in real
subject processes, verdicts from the judge's own ROS node). The reference itself passes,
so every failure below is the mistake's, and the test could not pass with a check that
says nothing.
"""

import contextlib
import json
import re
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pytest

from ros2nb import checks, course
from ros2nb.errors import CheckFailed, LearnerCodeError
from ros2nb.judge.subjects import SubjectHung

from judging import run_check
from waiting import wait_for

pytestmark = [pytest.mark.judge, pytest.mark.timeout(300)]

PUB, SUB = course.PUBLISHER_FILE, course.SUBSCRIBER_FILE
#: Fragments of the answers that no failure message may contain.
ANSWER_CODE = ('create_publisher(', 'create_timer(', 'create_subscription(', 'random.uniform(',
               'max(MIN_TEMPERATURE_C', '.publish(msg)', 'elif ', 'rclpy.spin(node)')
MESSAGES: list[str] = []
#: A line of the learner's own code as a message quotes it, ``(FILE line N: CODE)``, at the
#: end or mid-sentence: theirs, which a message may show, not the answer.  It ends at the
#: ``)`` that a word, a comma, a full stop or the message's end follows (the code's own
#: parentheses, even unbalanced in a line cut short, stay inside).
THEIR_LINE = re.compile(r' \((?:cell|[\w.]+\.py) line \d+: .*?\)(?=[,.:;]?(?:\s|$))')


def strangers(session) -> list[str]:
    """The course's nodes (a sensor, a monitor) running on the judge's domain now."""
    names = (course.SENSOR_NODE, course.MONITOR_NODE)
    return sorted(f'{ns.rstrip("/")}/{n}' for n, ns in session.observer.live_nodes()
                  if n in names)


def alone(session) -> None:
    """Wait until no node of an earlier subject runs on the judge's domain: a subject that was
    dropped leaves the graph at once when it ends cleanly, and within the DDS lease (20 s)
    when it had to be killed. The next check must not meet its node under the same name.
    (A name the graph keeps without endpoints after its process ended is no node: the
    checks look past it, see tests/test_checks_forged.py::test_a_main_that_never_starts_ros.)"""
    wait_for(lambda: not strangers(session), "the judge's domain free of earlier subjects' nodes",
             seen=lambda: strangers(session))


def mutated(session, relative: str, old, new) -> None:
    """Write the reference file with ``old`` replaced by ``new`` (or each of several pairs)."""
    path = session.workspace / relative
    text = course.reference_source(Path(relative).name)
    for before, after in zip(*((old, new) if isinstance(old, tuple) else ((old,), (new,)))):
        assert before in text, before
        text = text.replace(before, after)
    path.write_text(text)
    session.drop(('file', relative))
    alone(session)


def restore(session, relative: str) -> None:
    (session.workspace / relative).write_text(course.reference_source(Path(relative).name))
    session.drop(('file', relative))
    alone(session)


def fails(session, check, pattern: str, *args) -> str:
    """Run ``check(*args)`` with ``session`` as its judge; its one line must match ``pattern``."""
    with pytest.raises(CheckFailed) as caught:
        run_check(session, check, *args)
    message = str(caught.value)
    MESSAGES.append(message)
    assert re.search(pattern, message), message
    assert '\n' not in message
    return message


def test_reference_nodes_pass(session, capsys):
    for check in (checks.check_sensor_constructor, checks.check_sensor_callback,
                  checks.check_sensor_main, checks.check_monitor_constructor,
                  checks.check_monitor_callback, checks.check_monitor_main):
        run_check(session, check)
    out = capsys.readouterr().out
    assert out.count('Check passed:') == 6


#: The reference sensor's callback, part 4, as written.
PUBLISH_METHOD = course.reference_source(Path(PUB).name).split('    def publish_temperature')[1]
PUBLISH_METHOD = '    def publish_temperature' + PUBLISH_METHOD.split('\n\n\ndef main')[0]

SENSOR_MISTAKES = [
    ('placeholder', "        self.publisher_ = self.create_publisher",
     "        raise NotImplementedError()\n        self.publisher_ = self.create_publisher",
     checks.check_sensor_constructor, r'still raises NotImplementedError: write your code where '
                                      r'it says YOUR CODE HERE'),
    ('topic typo', "TOPIC = 'temperature'", "TOPIC = 'temprature'",
     checks.check_sensor_constructor, r'no publisher on /temperature \(it has: /temprature '
                                      r'\[std_msgs/msg/Float32\]\): did you mean /temperature\?'),
    ('message type', 'from std_msgs.msg import Float32',
     'from std_msgs.msg import Float64 as Float32',
     checks.check_sensor_constructor, r'uses std_msgs/msg/Float64, but the topic carries '
                                      r'std_msgs/msg/Float32'),
    ('period', 'PUBLISH_PERIOD_S = 1.0 ', 'PUBLISH_PERIOD_S = 2.0 ',
     checks.check_sensor_constructor, r'^The timer fires every 2.0 s \(temperature_publisher.py '
                                      r'line \d+: PUBLISH_PERIOD_S = 2.0 .*\): 3 readings in 6 s '
                                      r'of the grader.s clock, where the sensor publishes one '
                                      r'every 1.0 s \(6 in 6 s\): write PUBLISH_PERIOD_S = 1.0'),
    ('period a little short', 'PUBLISH_PERIOD_S = 1.0 ', 'PUBLISH_PERIOD_S = 0.99 ',
     checks.check_sensor_constructor, r'The readings came between the grader.s whole seconds: '
                                      r'the timer.s period is not 1.0 s: give the timer '
                                      r'PUBLISH_PERIOD_S'),
    ('period a little long', 'PUBLISH_PERIOD_S = 1.0 ', 'PUBLISH_PERIOD_S = 1.02 ',
     checks.check_sensor_constructor, r'The readings came between the grader.s whole seconds: '
                                      r'the timer.s period is not 1.0 s'),
    ('start value', 'self.temperature = START_TEMPERATURE_C', 'self.temperature = 0.0',
     checks.check_sensor_constructor, r'The first reading is 18.00 °C: the walk '
                                      r'starts at START_TEMPERATURE_C = 22.0 °C \(set '
                                      r'self.temperature to it in __init__\)'),
    ('callback called before part 4 exists',
     ('self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)',
      'def publish_temperature(self):'),
     ('self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature())',
      'def not_yet_written(self):'),
     checks.check_sensor_constructor, r'timer whose callback is None, not a function: '
                                      r'pass the method itself'),
    ('class typo', 'class TemperatureSensor(Node):', 'class TemperaturSensor(Node):',
     checks.check_sensor_constructor, r'defines no class TemperatureSensor \(it '
                                      r'defines TemperaturSensor'),
    ("the tutorial's floor", 'max(MIN_TEMPERATURE_C,', 'max(10.2,',
     checks.check_sensor_callback, r"below MIN_TEMPERATURE_C = 18.0 °C \(the "
                                   r"tutorial's floor of 10.2 °C"),
    ('no clamp', '''max(MIN_TEMPERATURE_C,
                               min(MAX_TEMPERATURE_C, self.temperature + step))''',
     'self.temperature + step',
     checks.check_sensor_callback, r'above MAX_TEMPERATURE_C = 28.0 °C: clamp every new reading'),
    ('step too big', 'random.uniform(-MAX_STEP_C, MAX_STEP_C)', 'random.uniform(-2.0, 2.0)',
     checks.check_sensor_callback, r'one step of at most ±0.5 °C|one step is at most ±0.5 °C'),
    ('no step', 'step = random.uniform(-MAX_STEP_C, MAX_STEP_C)', 'step = 0.0',
     checks.check_sensor_callback, r'Every reading is 22.00 °C: add a random step'),
    ('int message', 'msg.data = self.temperature', 'msg.data = int(self.temperature)',
     checks.check_sensor_callback, r"Float32's field 'data' takes \d+\.0 or float\(\.\.\.\), not "
                                   r"int \d+.*temperature_publisher.py line \d+: msg.data = int"),
    ('never published', '        self.publisher_.publish(msg)\n', '',
     checks.check_sensor_callback, r'publish_temperature ran but nothing arrived on /temperature'),
    ('self.TOPIC', 'self.create_publisher(Float32, TOPIC, QUEUE_DEPTH)',
     'self.create_publisher(Float32, self.TOPIC, QUEUE_DEPTH)',
     checks.check_sensor_constructor, r'TemperatureSensor\(\) raised: TOPIC is a constant of the '
                                      r'file, not of the node: write TOPIC, not self.TOPIC'),
    ('part 4 not indented', '    def publish_temperature(self):', 'def publish_temperature(self):',
     checks.check_sensor_callback, r'publish_temperature is written outside the class '
                                   r'TemperatureSensor: indent its part by four spaces'),
    ('log line without the reading',
     "self.get_logger().info(f'Publishing: {self.temperature:.2f}C')",
     "self.get_logger().info('Publishing a reading')",
     checks.check_sensor_callback, r'publish_temperature logged "Publishing a reading" for a '
                                   r'reading of \d+\.\d\d °C: show the reading in its line'),
    ('main() crashes before its spin', '    rclpy.init(args=args)\n', '',
     checks.check_sensor_main, r'crashed before Ctrl\+C: rclpy\.init\(\) was not called before '
                               r'this: call rclpy\.init\(args=args\) first in main\(\), before '
                               r'the node is created\. \(temperature_publisher\.py line \d+: '
                               r'node = TemperatureSensor\(\)\)'),
    ('shutdown instead of try_shutdown', 'rclpy.try_shutdown()  # rclpy.shutdown() would raise',
     'rclpy.shutdown()  # rclpy.shutdown() would raise',
     checks.check_sensor_main, r'exited with code 1 after Ctrl\+C \(Ctrl\+C had already shut '
                               r'rclpy down\): shut down with rclpy.try_shutdown\(\) instead '
                               r'of rclpy.shutdown\(\)'),
    ('a timer of 0.5 s', 'self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)',
     'self.create_timer(0.5, self.publish_temperature)',
     checks.check_sensor_constructor, r'^The timer fires every 0.5 s \(temperature_publisher.py '
                                      r'line \d+: self.timer = self.create_timer\(0.5, '
                                      r'self.publish_temperature\)\): 1[123] readings in 6 s of '
                                      r'the grader.s clock, where the sensor publishes one every '
                                      r'1.0 s \(6 in 6 s\): give the timer PUBLISH_PERIOD_S\.$'),
    ('the walk kept in a local', 'self.temperature = max(MIN_TEMPERATURE_C,',
     'temperature = max(MIN_TEMPERATURE_C,',
     checks.check_sensor_callback, r'publish_temperature never changes self.temperature: it sets '
                                   r'a local name temperature \(temperature_publisher.py line '
                                   r'\d+: temperature = max\(MIN_TEMPERATURE_C,\), which is gone '
                                   r'when it returns, so self.temperature stays where __init__ '
                                   r'set it'),
    ('a second of sleep in the timer callback', ('import random\n', '        step = random'),
     ('import random\nimport time\n', '        time.sleep(1.0)\n        step = random'),
     checks.check_sensor_callback, r'publish_temperature raised: time.sleep\(1.0\) in a callback '
                                   r'holds its node up.*\(temperature_publisher.py line \d+: '
                                   r'time.sleep\(1.0\)\)'),
    ('part 4 indented into __init__', PUBLISH_METHOD, '\n'.join(
        '    ' + line if line else line for line in PUBLISH_METHOD.split('\n')),
     checks.check_sensor_callback, r'TemperatureSensor has no method publish_temperature: it '
                                   r'is written inside __init__ \(temperature_publisher.py '
                                   r'line \d+: def publish_temperature\(self\):\), indented '
                                   r'one level too deep'),
    ('the class, not a node, in main()', 'node = TemperatureSensor()', 'node = TemperatureSensor',
     checks.check_sensor_main, r'node holds the class TemperatureSensor, not one made from it: '
                               r'create it with parentheses, node = TemperatureSensor\(\)\. '
                               r'\(temperature_publisher.py line \d+: node = TemperatureSensor\)'),
    ("the tutorial's main", '''    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C or a shutdown from outside: leave quietly
    finally:
        node.destroy_node()
        rclpy.try_shutdown()  # rclpy.shutdown() would raise if Ctrl+C already shut down''',
     '''    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.shutdown()''',
     checks.check_sensor_main, r'exited with code 1 after Ctrl\+C \(Ctrl\+C had already shut rclpy '
                               r'down\): catch ExternalShutdownException around the spin'),
]




def test_an_error_in_the_learners_code_is_one_line_at_their_line(session):
    """Python's own error in the learner's callback: one line with the name meant and their
    line, never their traceback (issue 65: five lines and more, no fix)."""
    mutated(session, PUB, 'self.publisher_.publish(msg)', 'self.publisher_.publish(mgs)')
    try:
        with pytest.raises(CheckFailed) as caught:
            run_check(session, checks.check_sensor_callback)
    finally:
        restore(session, PUB)
    shown = caught.value._render_traceback_()
    assert not isinstance(caught.value, LearnerCodeError) and len(shown) == 1, shown
    assert re.search(r"publish_temperature raised: name 'mgs' is not defined, but msg is "
                     r'\(temperature_publisher\.py line \d+: msg = Float32\(\)\): spell a name the '
                     r'same where it is set and where it is used\. \(temperature_publisher\.py '
                     r'line \d+: self\.publisher_\.publish\(mgs\)\)', shown[0]), shown


MONITOR_MISTAKES = [
    ('boundaries included', 'if temperature_c > HIGH_ABOVE_C:', 'if temperature_c >= HIGH_ABOVE_C:',
     checks.check_monitor_callback, r'For 26.0 °C the monitor said High; it should say Normal'),
    ('lower case', "status = 'High'", "status = 'high'",
     checks.check_monitor_callback, r'write the status High, with a capital letter'),
    ('arguments out of order', 'Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)',
     'Float32, TOPIC, QUEUE_DEPTH, self.temperature_callback)',
     checks.check_monitor_constructor, r'TemperatureMonitor\(\) raised: create_subscription got '
                                       r'its arguments in the wrong order: 10 came where the '
                                       r'callback belongs and self\.temperature_callback '
                                       r'where the queue depth belongs; it takes the message '
                                       r'type, the topic, the callback and the queue depth'),
    ('a branch that sets no status', "status = 'High'", 'pass',
     checks.check_monitor_callback, r'^TemperatureMonitor.temperature_callback raised for '
                                    r'\d+\.\d\d °C: status has no value here: '
                                    r'temperature_callback sets it in the other branches of its '
                                    r'if/elif/else, but not in the branch where temperature_c > '
                                    r'HIGH_ABOVE_C, which this call took: set status there too\. '
                                    r'\(temperature_subscriber\.py line \d+: pass\)$'),
    ('the message for its value', 'temperature_c = msg.data', 'temperature_c = msg',
     checks.check_monitor_callback, r'temperature_callback raised for 19.99 °C: a Float32 message '
                                    r'is not its value: use its field \(data\), e.g. msg.data'),
    ('callback left unwritten', '        temperature_c = msg.data\n',
     '        raise NotImplementedError()\n',
     checks.check_monitor_callback, r'temperature_callback still raises '
                                    r'NotImplementedError: write your code'),
    ('two lines',
     "        self.get_logger().info(f'Temperature: {temperature_c:.2f}C - Status: {status}')",
     "        self.get_logger().info(f'Temperature: {temperature_c:.2f}C')\n"
     "        self.get_logger().info(f'Status: {status}')",
     checks.check_monitor_callback, r'logged 2 lines; log exactly one per message'),
    ('wrong topic', "TOPIC = 'temperature'", "TOPIC = 'temp'",
     checks.check_monitor_constructor, r'no subscription on /temperature \(it has: /temp '
                                       r'\[std_msgs/msg/Float32\]\)'),
    ("the tutorial's main", ('''    except (KeyboardInterrupt, ExternalShutdownException):
        pass  # Ctrl+C or a shutdown from outside: leave quietly
    finally:
        node.destroy_node()   # the tutorial's subscriber never did this
        rclpy.try_shutdown()  # nor this'''), ('''    except KeyboardInterrupt:
        pass'''),
     checks.check_monitor_main, r'exited with code 1 after a shutdown from outside '
                                r'\(SIGTERM\) \(.*ExternalShutdownException.*\): catch '
                                r'ExternalShutdownException around the spin'),
]


MISTAKES = [(PUB, *m) for m in SENSOR_MISTAKES] + [(SUB, *m) for m in MONITOR_MISTAKES]


@pytest.mark.parametrize('file, label, old, new, check, pattern', MISTAKES,
                         ids=[f'{Path(m[0]).stem}: {m[1]}' for m in MISTAKES])
def test_a_mistake_gets_one_line(session, file, label, old, new, check, pattern):
    mutated(session, file, old, new)
    try:
        fails(session, check, pattern)
    finally:
        restore(session, file)


def test_a_part_run_out_of_order_is_named_by_the_check(session):
    """Part 3 (the class) saved, parts 1-2 (imports, constants) never run: the check names them."""
    record = session.workspace / '.ros2nb-parts.json'
    text = course.reference_source(Path(PUB).name)
    part3 = text[text.index('class TemperatureSensor'):]
    record.write_text(json.dumps({PUB: {'3': part3}}))
    (session.workspace / PUB).write_text(part3)
    session.drop(('file', PUB))
    try:
        fails(session, checks.check_sensor_constructor,
              r'temperature_publisher.py is missing parts 1, 2: '
              r'run the %%part cells for them')
    finally:
        record.unlink()
        restore(session, PUB)


#: The monitor's main() with rclpy's SIGTERM race made certain.  rclpy (Jazzy) handles SIGTERM
#: in a thread of its own that wakes the spin, then shuts the context down; here the shutdown
#: comes from a thread of the program's, with nothing woken, as when the spin had looked
#: again in between (seen once in make test beside two CPU burners).
RACED_SHUTDOWN = ('    rclpy.init(args=args)\n', '''    import signal, threading
    from rclpy.signals import SignalHandlerOptions
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGTERM})  # every thread from here on
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.SIGINT)

    def shut_down_from_outside():
        signal.sigwait({signal.SIGTERM})
        rclpy.get_default_context().handle.shutdown()  # rcl's own: no spin is woken

    threading.Thread(target=shut_down_from_outside, daemon=True).start()
''')


def test_a_shutdown_from_outside_that_the_spin_missed_still_ends_it(session):
    """An honest main() whose spin missed the shutdown from outside still passes: the judge
    calls its node once (mains.WAKE_AFTER_S), the spin wakes and ends with
    ExternalShutdownException.  Without that call it waited until the check gave up, and an
    honest learner was told their main() did not stop."""
    mutated(session, SUB, *RACED_SHUTDOWN)
    try:
        run_check(session, checks.check_monitor_main)
    finally:
        restore(session, SUB)


#: A program that works for 1.5 CPU seconds at a third of a CPU, as beside two CPU burners.
SLOW_PROGRAM = """
import time
start = time.process_time()
while time.process_time() - start < 1.5:
    burst = time.process_time()
    while time.process_time() - burst < 0.02:
        pass
    time.sleep(0.04)
"""


def test_a_program_the_judge_runs_is_given_work_not_wall_time(session, tmp_path):
    """What the judge runs itself (notebook 05's colcon build, its sourcing) may take longer
    than its seconds on a busy machine: they count its work.  A program that only waits is
    ended once it waited them."""
    began = time.monotonic()
    code, _output = session.run([sys.executable, '-c', SLOW_PROGRAM], seconds=2, cwd=tmp_path)
    assert code == 0 and time.monotonic() - began > 2  # a limit on the wall clock cut it
    began = time.monotonic()
    with pytest.raises(SubjectHung, match=r'^sleep did not finish within 2 s\.$'):
        session.run(['sleep', '3600'], seconds=2, cwd=tmp_path)
    assert 2 <= time.monotonic() - began < 60


@dataclass(frozen=True)
class PackageFiles:
    """What ``package_files`` hands a test.

    :ivar setup_cfg: the workspace's setup.cfg.
    :ivar generated_cfg: its text as pkg_create wrote it.
    :ivar entries: writes setup.py as pkg_create wrote it, with the given console_scripts lines.
    """

    setup_cfg: Path
    generated_cfg: str
    entries: Callable[..., None]


@pytest.fixture
def package_files(session):
    """setup.py and setup.cfg as pkg_create wrote them, and a writer of console_scripts lines;
    both files (and the publisher) are put back afterwards.  The package's checks are split in
    two tests: each builds the package five to seven times, and together they outran one test's
    time limit on a busy machine."""
    setup_py = session.workspace / course.SETUP_PY_FILE
    setup_cfg = session.workspace / course.SETUP_CFG_FILE
    generated_py, generated_cfg = setup_py.read_text(), setup_cfg.read_text()
    empty = "        'console_scripts': [\n        ],\n"
    assert empty in generated_py

    def entries(*lines: str) -> None:
        """setup.py as pkg_create wrote it, with these lines in its console_scripts list."""
        setup_py.write_text(generated_py.replace(empty, "        'console_scripts': [\n" + ''.join(
            f'            {line}\n' for line in lines) + '        ],\n'))

    try:
        yield PackageFiles(setup_cfg, generated_cfg, entries)
    finally:
        setup_py.write_text(generated_py)
        setup_cfg.write_text(generated_cfg)
        restore(session, PUB)


PUBLISHER_ENTRY = "'temperature_publisher = sensor_simulator.temperature_publisher:main'"
SUBSCRIBER_ENTRY = "'temperature_subscriber = sensor_simulator.temperature_subscriber:main'"


def test_entry_point_checks(session, package_files):
    entries = package_files.entries
    entries('# YOUR CODE HERE', 'raise NotImplementedError()')
    fails(session, checks.check_entry_points, r'setup.py still holds the placeholder')
    entries()
    fails(session, checks.check_entry_points,
          r'ros2 run sensor_simulator temperature_publisher: No '
          r'executable found: console_scripts has no entry named '
          r'temperature_publisher')
    entries(PUBLISHER_ENTRY, SUBSCRIBER_ENTRY + ',')  # no comma after the first
    fails(session, checks.check_entry_points,
          r'is two entries run together: end each string in the '
          r'console_scripts list with a comma')
    entries("'temperature_publisher = sensor_simulator/temperature_publisher.py:main',")
    fails(session, checks.check_entry_points, r'is not written NAME = package.module:function: the '
                                     r'module is written with dots')
    entries("'temperature_publisher = sensor_simulator.publisher:main',", SUBSCRIBER_ENTRY + ',')
    said = fails(session, checks.check_entry_points, r'did not start main\(\) of '
                 r'sensor_simulator.temperature_publisher \(ModuleNotFound'
                 r"Error: No module named 'sensor_simulator.publisher'\): "
                 r'temperature_publisher = sensor_simulator.publisher:main: '
                 r'it should start main\(\) in sensor_simulator/temperature_publisher.py; left '
                 r'of the colon, name that file as a module')
    assert 'sensor_simulator.temperature_publisher:main' not in said  # the line says how, not what
    entries("'temperature_publisher = sensor_simulator.temperature_publisher:start',",
            SUBSCRIBER_ENTRY + ',')
    fails(session, checks.check_entry_points, r'temperature_publisher = sensor_simulator.'
          r'temperature_publisher:start: right of the colon goes the function that starts the '
          r'node, main, as temperature_publisher.py defines it\.$')


def test_setup_cfg_checks(session, package_files, capsys):
    setup_cfg, generated_cfg, entries = (package_files.setup_cfg, package_files.generated_cfg,
                                         package_files.entries)
    entries(PUBLISHER_ENTRY + ',', SUBSCRIBER_ENTRY + ',')
    setup_cfg.write_text(generated_cfg.replace('$base/lib/sensor_simulator', '$base/bin'))
    fails(session, checks.check_setup_cfg,
          r'\[develop\] script_dir is \$base/bin; ros2 run looks in '
          r'\$base/lib/sensor_simulator')
    setup_cfg.write_text(generated_cfg.replace('=$base/lib/sensor_simulator',
                                               '=$base/lib/sensor_simulator/'))
    # a trailing slash: the same folder, ros2 run finds them
    run_check(session, checks.check_setup_cfg)
    setup_cfg.write_text(generated_cfg.replace('script_dir', 'script-dir'))  # older template
    fails(session, checks.check_setup_cfg,
          r'^setup.cfg spells script-dir with a dash: setuptools reads it '
          r'with a deprecation warning .* a coming release refuses it, as '
          r'78\.0\.0 did until 78\.0\.2 took that back .*: write '
          r'script_dir\.$')
    setup_cfg.unlink()
    fails(session, checks.check_setup_cfg, r'setup.cfg is missing')
    setup_cfg.write_text(generated_cfg)
    # The grader's stand-ins take the place of the nodes: a broken node costs nothing here.
    (session.workspace / PUB).write_text('raise SystemExit("broken")\n')
    capsys.readouterr()
    run_check(session, checks.check_entry_points)
    run_check(session, checks.check_setup_cfg)
    run_check(session, checks.check_package_runs)
    assert capsys.readouterr().out.count('Check passed:') == 3


def test_no_message_prints_the_answer():
    assert len(MESSAGES) >= len(SENSOR_MISTAKES) + len(MONITOR_MISTAKES)
    for message in MESSAGES:
        own_line = re.sub(THEIR_LINE, '', message)
        assert not any(code in own_line for code in ANSWER_CODE), message


def test_a_check_from_the_kernel_runs_in_a_judge_process(tmp_path, monkeypatch, capsys):
    """The kernel's path: a judge process of its own, on a domain of its own."""
    import ros2nb
    from ros2nb.terminal import workspace as ws_module
    monkeypatch.setenv('ROS2NB_WORKSPACE', str(tmp_path / 'ws'))
    monkeypatch.setattr(ws_module, '_current', None)
    ros2nb.course.catch_up(5)
    capsys.readouterr()
    checks.check_sensor_constructor()
    assert capsys.readouterr().out.startswith('Check passed: temperature_sensor publishes')
    shutil.copy(tmp_path / 'ws' / SUB, tmp_path / 'ws' / PUB)  # a monitor where the sensor belongs
    with pytest.raises(CheckFailed, match='defines no class TemperatureSensor \\(it defines '
                                          'TemperatureMonitor'):
        checks.check_sensor_constructor()


# ------------------------------------------------------------------ 00-02 in the kernel
def unsolved(*_args):
    raise NotImplementedError()


def test_cell_answers_in_the_kernel(tmp_path):
    with pytest.raises(CheckFailed, match='still raises NotImplementedError'):
        checks.check_expanded_path(unsolved, ends_with='W')
    checks.check_expanded_path(lambda: Path('~/Documents/W').expanduser(), ends_with='Documents/W')
    with pytest.raises(CheckFailed, match='root of the disk'):
        checks.check_expanded_path(lambda: Path('/Documents/W'), ends_with='Documents/W')
    with pytest.raises(CheckFailed, match='expanduser'):
        checks.check_expanded_path(lambda: Path('~/Documents/W'), ends_with='Documents/W')
    xml = tmp_path / 'p' / 'package.xml'
    xml.parent.mkdir()
    xml.write_text('<package format="3"><name>p</name><version>1.0.0</version>'
                   '<description>d</description><maintainer email="a@example.com">a</maintainer>'
                   '<license>MIT</license><depend>rclpy</depend><test_depend>x</test_depend>'
                   '<depend>std_msgs</depend></package>')
    assert checks.package_dependencies(xml) == ['rclpy', 'std_msgs']  # read with catkin_pkg
    checks.check_dependencies(lambda p: ['rclpy', 'std_msgs'], xml)
    with pytest.raises(CheckFailed, match='test_depend is not a depend'):
        checks.check_dependencies(lambda p: ['rclpy', 'x', 'std_msgs'], xml)
    import xml.etree.ElementTree as ElementTree  # the elements, not their text
    with pytest.raises(CheckFailed, match=r"returned a list of Element objects, not of "
                                          r"names: return each <depend> element's text, "
                                          r"e\.g\. \[element\.text"):
        checks.check_dependencies(lambda p: list(ElementTree.parse(p).getroot().iter('depend')),
                                  xml)


def test_endpoint_in_the_kernel():
    import ros2nb
    from rclpy.node import Node
    from std_msgs.msg import String

    class Listener(Node):
        def __init__(self):
            super().__init__('loud_listener')
            self.create_subscription(String, 'chater', lambda m: None, 10)

    ros2nb.start()
    try:
        with pytest.raises(CheckFailed, match='no subscription on /chatter'):
            checks.check_endpoint(Listener, 'subscription', '/chatter', 'std_msgs/msg/String')
        with pytest.raises(CheckFailed, match='uses std_msgs/msg/String, but the topic carries '
                                              'std_msgs/msg/Float32'):
            checks.check_endpoint(Listener, 'subscription', '/chater', 'std_msgs/msg/Float32')
        checks.check_endpoint(Listener, 'subscription', '/chater', 'std_msgs/msg/String')
    finally:
        ros2nb.shutdown()


def test_checks_say_when_ros_was_shut_down():
    from rclpy.node import Node
    with pytest.raises(CheckFailed, match=r'was rclpy.shutdown\(\) called\?'):
        checks.check_endpoint(Node, 'subscription', '/chatter', 'std_msgs/msg/String')


def test_links_out_of_the_workspace_are_never_followed(session, tmp_path):
    """A workspace file may be a link to a file a subject can rewrite, or that only the
    judge may read. The judge reads the learner's source as text only to word a failure,
    and refuses such a link then too (before, it read whatever it pointed to); a build copies
    it as a link (before, it copied the target's text where the learner's setup.py runs)."""
    outside = tmp_path / 'elsewhere.py'
    outside.write_text(course.reference_source(Path(PUB).name).replace(
        '        self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)\n', ''))
    (session.workspace / PUB).unlink()
    (session.workspace / PUB).symlink_to(outside)
    try:
        fails(session, checks.check_sensor_constructor,
              r'temperature_publisher.py is a link to .*, '
              r'outside your workspace: the grader reads your '
              r'files in the workspace only')
    finally:
        (session.workspace / PUB).unlink()
        restore(session, PUB)
    secret = tmp_path / 'judge-only.txt'
    secret.write_text('what only the judge may read\n')
    link = session.workspace / 'src' / course.PACKAGE / 'notes.txt'
    link.symlink_to(secret)
    try:
        with contextlib.suppress(CheckFailed):  # the build is what counts here, not its entries
            run_check(session, checks.check_entry_points)
        copies = list(session.scratch.glob(f'build-*/src/{course.PACKAGE}/notes.txt'))
        assert copies and all(c.is_symlink() for c in copies), \
            [c.read_text() for c in copies if not c.is_symlink()]
    finally:
        link.unlink()
