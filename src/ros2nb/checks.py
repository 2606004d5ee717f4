"""Checks behind every Challenge: each raises :class:`CheckFailed` with what is still wrong.

The check cells learners run and the instructors' hidden tests call these same
functions, so the two cannot drift.  They test behaviour (what a node publishes, what a
function returns, how a process exits), never the text of the code.
"""

from __future__ import annotations

import math
import os
import random
import re
import signal
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any, Callable, Optional

from .graph import INFRASTRUCTURE_TOPICS
from .runtime import Ros2nbError

#: The course's clamp range for the simulated sensor (°C); the tutorial's 10.2 floor is fixed.
MIN_TEMPERATURE_C = 18.0
MAX_TEMPERATURE_C = 28.0
#: The monitor's thresholds (°C): strictly above HIGH is "High", strictly below LOW is "Low".
LOW_THRESHOLD_C = 20.0
HIGH_THRESHOLD_C = 26.0


class CheckFailed(AssertionError):
    """A challenge is not solved yet; the message says what to change."""


def passed(message: str) -> None:
    """Print the line a passing check shows."""
    print(f'Check passed: {message}')


def _call(function: Callable[..., Any], *args: Any) -> Any:
    try:
        return function(*args)
    except NotImplementedError:
        raise CheckFailed(f'{function.__name__}() still raises NotImplementedError: replace '
                          '"raise NotImplementedError()" with your code and run its cell '
                          'again.') from None


def _require_ros() -> None:
    """Raise CheckFailed when rclpy is not running in this kernel (e.g. after rclpy.shutdown())."""
    import rclpy
    if not rclpy.ok():
        raise CheckFailed('ROS 2 is not running in this kernel (was rclpy.shutdown() called?): '
                          'restart the kernel and run the notebook from the top; ros2nb.stop() '
                          'stops nodes without shutting ROS down.')


def _endpoint_names(node: Any, kind: str) -> dict[str, str]:
    entities = node.subscriptions if kind == 'subscription' else node.publishers
    return {node.resolve_topic_name(e.topic_name): e.msg_type.__module__.split('.')[0] + '/msg/'
            + e.msg_type.__name__ for e in entities}


def check_endpoint(node_class: Callable[[], Any], kind: str, topic: str, type_name: str) -> None:
    """Check that a node class makes a publisher or subscription on ``topic`` with ``type_name``.

    The node is created, inspected and destroyed again (ROS must be up).

    Introduced in ``00-setup-and-the-pubsub-idea.ipynb``.

    :param node_class: the class (or any callable returning a node), e.g. ``LoudListener``.
    :param kind: ``'publisher'`` or ``'subscription'``.
    :param topic: e.g. ``'/chatter'``.
    :param type_name: e.g. ``'std_msgs/msg/String'``.
    :raises CheckFailed: naming what the node has instead.
    """
    _require_ros()
    from rclpy.node import Node
    node = _call(node_class)
    if not isinstance(node, Node):
        raise CheckFailed(f'Expected a node, got {type(node).__name__}: pass your Node '
                          'subclass itself, e.g. LoudListener (no parentheses).')
    name = node.get_name()
    try:
        found = _endpoint_names(node, kind)
    finally:
        node.destroy_node()
    if topic not in found:
        have = ', '.join(sorted(found)) or 'none'
        raise CheckFailed(f'Node {name} has no {kind} on {topic} (it has: {have}); '
                          f'check the topic name passed to create_{kind}().')
    if found[topic] != type_name:
        raise CheckFailed(f'The {kind} on {topic} uses {found[topic]}, but the topic carries '
                          f'{type_name}: import and pass that type.')
    passed(f'{name} has a {kind} on {topic} [{type_name}].')


def check_expanded_path(make_path: Callable[[], Any], *, ends_with: str) -> None:
    """Check the path a function returns is absolute, inside home and ends with ``ends_with``.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param make_path: the learner's function (called with no arguments).
    :raises CheckFailed: e.g. for the tutorial's ``/Documents/...`` (no ``~``).
    """
    path = _call(make_path)
    if not isinstance(path, Path):
        raise CheckFailed(f'Return a pathlib.Path, not {type(path).__name__}.')
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
    """Return the ``<depend>`` entries of a package.xml, in order (the reference reader)."""
    return [d.text.strip() for d in ET.parse(package_xml).getroot().findall('depend')
            if d.text]


def check_dependencies(reader: Callable[[Path], list[str]], package_xml: Path) -> None:
    """Check a learner's package.xml reader against the real file.

    Introduced in ``02-create-a-package.ipynb``.

    :raises CheckFailed: when the result differs from the file's ``<depend>`` tags.
    """
    if not Path(package_xml).is_file():
        raise CheckFailed(f'{package_xml} does not exist: run the pkg_create cell above first.')
    got = _call(reader, Path(package_xml))
    want = package_dependencies(Path(package_xml))
    if not isinstance(got, list):
        raise CheckFailed(f'Return a list of names, not {type(got).__name__}.')
    if got != want:
        raise CheckFailed(f'Got {got}, but package.xml declares {want}: read the text of each '
                          '<depend> element, in order (test_depend is not a depend).')
    passed(f'package.xml depends on {", ".join(want)}.')


def check_clamp(clamp: Callable[[float], float]) -> None:
    """Check the sensor's clamp keeps readings inside [18.0, 28.0] °C and leaves others alone.

    Introduced in ``03-write-the-publisher.ipynb``.

    :raises CheckFailed: naming the first input that gave a wrong value.
    """
    cases = [(22.3, 22.3), (10.2, MIN_TEMPERATURE_C), (17.99, MIN_TEMPERATURE_C),
             (18.0, 18.0), (28.0, 28.0), (31.5, MAX_TEMPERATURE_C), (-40.0, MIN_TEMPERATURE_C)]
    for value, want in cases:
        got = _call(clamp, value)
        if not isinstance(got, (int, float)) or not math.isclose(got, want, abs_tol=1e-9):
            raise CheckFailed(f'{clamp.__name__}({value}) returned {got!r}, expected {want}: '
                              f'keep values inside [{MIN_TEMPERATURE_C}, {MAX_TEMPERATURE_C}] '
                              'with min() and max().')
    passed(f'readings stay inside [{MIN_TEMPERATURE_C}, {MAX_TEMPERATURE_C}] °C.')


def check_publisher_samples(samples: list[float], *, seconds: float) -> None:
    """Check a recorded run of the sensor: one reading per second, walk and clamp respected.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param samples: readings in °C in the order received.
    :param seconds: simulated seconds the sensor ran.
    :raises CheckFailed: naming the first rule broken.
    """
    if abs(len(samples) - seconds) > 1:
        raise CheckFailed(f'{len(samples)} readings in {seconds:g} s; expected one per second: '
                          'check the timer period.')
    if samples and abs(samples[0] - 22.0) > 0.5 + 1e-4:
        raise CheckFailed(f'The first reading is {samples[0]:.2f} °C; it should be within '
                          '0.5 °C of the 22.0 °C start.')
    for i, (a, b) in enumerate(zip(samples, samples[1:]), start=2):
        if abs(b - a) > 0.5 + 1e-4:
            raise CheckFailed(f'Reading {i} jumps {b - a:+.2f} °C; one step is at most ±0.5 °C.')
    outside = [s for s in samples if not MIN_TEMPERATURE_C - 1e-4 <= s <= MAX_TEMPERATURE_C + 1e-4]
    if outside:
        raise CheckFailed(f'{len(outside)} readings are outside [{MIN_TEMPERATURE_C}, '
                          f'{MAX_TEMPERATURE_C}] °C (e.g. {outside[0]:.2f}): check the clamp.')
    passed(f'{len(samples)} readings, one per second, steps within ±0.5 °C, all inside '
           f'[{MIN_TEMPERATURE_C}, {MAX_TEMPERATURE_C}] °C.')


def reference_status(temperature_c: float) -> str:
    """The monitor's rule: ``High`` above 26.0 °C, ``Low`` below 20.0 °C, else ``Normal``."""
    if temperature_c > HIGH_THRESHOLD_C:
        return 'High'
    if temperature_c < LOW_THRESHOLD_C:
        return 'Low'
    return 'Normal'


def check_classify(classify: Callable[[float], str]) -> None:
    """Check a status function exactly, including the 20.0 and 26.0 °C boundaries.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :raises CheckFailed: naming the first temperature classified wrongly.
    """
    for value in (10.0, 19.99, 20.0, 20.01, 23.0, 25.99, 26.0, 26.01, 30.0):
        got = _call(classify, value)
        want = reference_status(value)
        if got != want:
            raise CheckFailed(f'{classify.__name__}({value}) returned {got!r}, expected '
                              f'{want!r}: "above 26" means > 26.0 and "below 20" means < 20.0.')
    passed('every status is right, including 20.0 and 26.0 (both Normal).')


def check_clean_shutdown(*command: str, seconds: float = 3.0,
                         workspace_path: Optional[Path] = None) -> None:
    """Run ``ros2 run PACKAGE EXECUTABLE`` (or ``python SCRIPT.py``), press Ctrl+C, check the exit.

    Clean means exit code 0 and no traceback, which on Jazzy needs ``main()`` to catch
    ``KeyboardInterrupt`` and ``ExternalShutdownException`` and call ``rclpy.try_shutdown()``.

    Introduced in ``05-entry-points-and-run.ipynb``.

    :raises CheckFailed: with the process's last error line.
    """
    from .workspace import find_executable, node_process_env, source_workspace, workspace_file
    if len(command) == 1 and command[0].endswith('.py'):
        script = workspace_file(command[0])
        if not script.is_file():
            raise CheckFailed(f'{script.name} does not exist yet: run the cells that write it.')
        argv, env, executable = [sys.executable, str(script)], dict(os.environ), script.name
    elif len(command) == 2:
        package, executable = command
        try:
            env = source_workspace(workspace_path)
            argv = [str(find_executable(package, executable, env))]
        except Ros2nbError as error:
            raise CheckFailed(f'{error}: build the package first (the colcon_build cell).') \
                from None
    else:
        raise ValueError('Pass PACKAGE, EXECUTABLE or a single SCRIPT.py.')
    proc = subprocess.Popen(argv, env=node_process_env(env), text=True, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, start_new_session=True)
    time.sleep(seconds)
    os.killpg(proc.pid, signal.SIGINT)
    try:
        output, _ = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)  # the whole group: nothing outlives the check
        output, _ = proc.communicate()
        raise CheckFailed(f'{executable} did not stop within 10 s of Ctrl+C: '
                          'let KeyboardInterrupt end rclpy.spin().') from None
    if 'NotImplementedError' in output:
        raise CheckFailed(f'{executable}: main() still raises NotImplementedError: write it.')
    if proc.returncode != 0 or 'Traceback' in output:
        last = [line for line in output.splitlines() if line.strip()][-1:] or ['(no output)']
        raise CheckFailed(f'{executable} exited with code {proc.returncode} after Ctrl+C '
                          f'({last[0].strip()}): catch KeyboardInterrupt and '
                          'ExternalShutdownException, then destroy the node and call '
                          'rclpy.try_shutdown().')
    passed(f'{executable} stopped cleanly on Ctrl+C (exit code 0, no traceback).')


# --------------------------------------------------------------- behaviour (hidden tests)
#: Readings the monitor check publishes: both boundaries and their neighbours (°C).
MONITOR_PROBES_C = (19.5, 19.99, 20.0, 20.01, 23.0, 25.99, 26.0, 26.01, 27.5)
STATUS_WORDS = re.compile(r'\b(High|Low|Normal)\b')


def _node_class(path: Any, class_name: str, module_name: str) -> type:
    from .workspace import import_file
    try:
        module = import_file(path, module_name)
    except Ros2nbError as error:
        raise CheckFailed(str(error)) from None
    except Exception as error:  # the learner's file itself fails to import
        raise CheckFailed(f'{Path(path).name} does not import: {type(error).__name__}: {error}.') \
            from None
    cls = getattr(module, class_name, None)
    if cls is None:
        raise CheckFailed(f'{Path(path).name} defines no class {class_name}: check its spelling '
                          '(the tutorial wrote TemperaturSensor in places).')
    return cls


def _expect_endpoint(node: Any, kind: str, topic: str, type_name: str) -> None:
    found = _endpoint_names(node, kind)
    if found.get(topic) != type_name:
        have = ', '.join(f'{t} [{ty}]' for t, ty in sorted(found.items())
                         if t not in INFRASTRUCTURE_TOPICS) or 'none'
        raise CheckFailed(f'{node.get_name()} needs a {kind} on {topic} [{type_name}]; it has: '
                          f'{have}.')


def check_publisher_behaviour(path: Any, *, seconds: int = 3600) -> None:
    """Run the learner's TemperatureSensor on simulated time and check what it publishes.

    Float32 on ``/temperature``, once per simulated second, starting within 0.5 °C of
    22.0, steps of at most 0.5 °C, always inside the clamp.  Needs ``ros2nb.start(sim_time=True)``.

    Introduced in ``03-write-the-publisher.ipynb`` (hidden test).

    :param path: the learner's ``temperature_publisher.py`` (relative to the workspace).
    :param seconds: simulated seconds to record.
    :raises CheckFailed: naming the first rule broken.
    """
    _require_ros()
    from . import graph
    from .runtime import add, stop
    cls = _node_class(path, 'TemperatureSensor', 'graded_temperature_publisher')
    random.seed(0)
    node = add(_call(cls))
    try:
        _expect_endpoint(node, 'publisher', '/temperature', 'std_msgs/msg/Float32')
        times, values = graph.record('temperature', seconds, 'std_msgs/msg/Float32')
    finally:
        stop(node.get_name())
    gaps = {round(b - a, 6) for a, b in zip(times, times[1:])}
    if gaps and gaps != {1.0}:
        raise CheckFailed(f'Readings came {sorted(gaps)} s apart; expected exactly 1 s: use a '
                          '1.0 s timer period.')
    check_publisher_samples(values, seconds=seconds)


def check_monitor_behaviour(path: Any) -> None:
    """Publish readings around both thresholds to the learner's monitor and read its logs.

    Every reading must give exactly one log line naming the right status (High above
    26.0 °C, Low below 20.0 °C, Normal otherwise, boundaries included).

    Introduced in ``04-write-the-subscriber.ipynb`` (hidden test).

    :param path: the learner's ``temperature_subscriber.py``.
    :raises CheckFailed: naming the first reading handled wrongly.
    """
    _require_ros()
    from rclpy.node import Node
    from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
    from rcl_interfaces.msg import Log
    from std_msgs.msg import Float32
    from .runtime import add, spin, stop
    cls = _node_class(path, 'TemperatureMonitor', 'graded_temperature_subscriber')
    monitor = add(_call(cls))
    logger = monitor.get_logger().name
    heard: list[str] = []
    probe = Node('ros2nb_grading_probe')
    publisher = probe.create_publisher(Float32, 'temperature', 10)
    probe.create_subscription(
        Log, '/rosout', lambda m: heard.append(m.msg) if m.name == logger else None,
        QoSProfile(depth=1000, reliability=ReliabilityPolicy.RELIABLE,
                   durability=DurabilityPolicy.VOLATILE))
    add(probe)
    try:
        _expect_endpoint(monitor, 'subscription', '/temperature', 'std_msgs/msg/Float32')
        spin(0)
        for value in MONITOR_PROBES_C:
            heard.clear()
            publisher.publish(Float32(data=value))
            spin(0)
            statuses = [STATUS_WORDS.findall(line) for line in heard]
            statuses = [s for s in statuses if s]
            want = reference_status(value)
            if len(statuses) != 1:
                raise CheckFailed(f'For a reading of {value} °C the monitor logged {len(statuses)} '
                                  'status lines; expected exactly one per message.')
            if statuses[0] != [want]:
                raise CheckFailed(f'For {value} °C the monitor logged {statuses[0]}, expected '
                                  f'{want!r} ("above 26" is > 26.0, "below 20" is < 20.0).')
    finally:
        stop(probe.get_name())
        stop(monitor.get_name())
    passed(f'the monitor logged the right status for {len(MONITOR_PROBES_C)} readings, '
           'boundaries included.')


def check_package(workspace_path: Optional[Path] = None, *, package: str = 'sensor_simulator',
                  executables: tuple[str, ...] = ('temperature_publisher',
                                                  'temperature_subscriber')) -> None:
    """Check the package: dependencies, setup.cfg, a colcon build and both entry points.

    Introduced in ``05-entry-points-and-run.ipynb`` (hidden test).

    :raises CheckFailed: naming what is missing.
    """
    import configparser
    from .workspace import (ColconBuildError, colcon_build, find_executable,
                            source_workspace, workspace)
    ws = Path(workspace_path) if workspace_path is not None else workspace()
    root = ws / 'src' / package
    if not (root / 'package.xml').is_file():
        raise CheckFailed(f'{root / "package.xml"} is missing: create the package (notebook 02).')
    missing = [d for d in ('rclpy', 'std_msgs') if d not in package_dependencies(root / 'package.xml')]
    if missing:
        raise CheckFailed(f'package.xml lacks <depend> on {", ".join(missing)}.')
    config = configparser.ConfigParser()
    config.read(root / 'setup.cfg')
    if config.get('install', 'install_scripts', fallback='') != f'$base/lib/{package}':
        raise CheckFailed(f'setup.cfg must set [install] install_scripts=$base/lib/{package}, '
                          'or ros2 run finds no executable.')
    try:
        colcon_build('--packages-select', package, workspace_path=ws)
    except ColconBuildError as error:
        raise CheckFailed(str(error)) from None
    env = source_workspace(ws)
    for executable in executables:
        try:
            find_executable(package, executable, env)
        except Ros2nbError:
            raise CheckFailed(f"ros2 run {package} {executable}: No executable found; add "
                              f"'{executable} = {package}.{executable}:main' to console_scripts "
                              'in setup.py and build again.') from None
    passed(f'{package} declares rclpy and std_msgs, builds, and installs '
           f'{", ".join(executables)}.')
