"""The course's facts, defined once: names, files, the sensor's numbers, the monitor's thresholds.

The checks, the judge and the notebooks take every number from here; the monitor's rule
itself is an answer, in :mod:`ros2nb.rules`.  No ROS import.  The node files
the learner writes (and ``ros2nb/reference/``) are standalone ROS programs, so they carry
the same numbers as literals in their constants part; a test keeps them equal to these.

Also :func:`catch_up`, so any notebook can be run on its own, and :func:`unfinished_line`,
the one line that names what an earlier notebook left unwritten in a node file a later one
uses.  Introduced in ``01-create-a-workspace.ipynb``.
"""

from __future__ import annotations

import contextlib
import io
import os
import re
from importlib import resources
from pathlib import Path
from typing import Optional, Sequence

from .terminal.files import write_file
from . import unfinished
from .terminal.pkg_create import pkg_create
from .terminal.workspace import create_workspace, default_workspace, shown

# ------------------------------------------------------------------ the package
PACKAGE = 'sensor_simulator'
DEPENDENCIES = ('rclpy', 'std_msgs')
#: Maintainer used in the notebooks, so package.xml is the same on every machine.
MAINTAINER_NAME = 'learner'
MAINTAINER_EMAIL = 'learner@example.com'
#: Files the learner writes, relative to the workspace.
PUBLISHER_FILE = f'src/{PACKAGE}/{PACKAGE}/temperature_publisher.py'
SUBSCRIBER_FILE = f'src/{PACKAGE}/{PACKAGE}/temperature_subscriber.py'
SETUP_PY_FILE = f'src/{PACKAGE}/setup.py'
SETUP_CFG_FILE = f'src/{PACKAGE}/setup.cfg'
PACKAGE_XML_FILE = f'src/{PACKAGE}/package.xml'
#: Entry points (``ros2 run sensor_simulator <executable>``) and what they start.
PUBLISHER_EXECUTABLE = 'temperature_publisher'
SUBSCRIBER_EXECUTABLE = 'temperature_subscriber'
SENSOR_CLASS, SENSOR_NODE = 'TemperatureSensor', 'temperature_sensor'
MONITOR_CLASS, MONITOR_NODE = 'TemperatureMonitor', 'temperature_monitor'

# ------------------------------------------------------------------ the sensor
TOPIC = 'temperature'
MESSAGE_TYPE = 'std_msgs/msg/Float32'
QUEUE_DEPTH = 10              # messages kept for a slow subscription
PUBLISH_PERIOD_S = 1.0        # one reading per second
START_TEMPERATURE_C = 22.0    # room temperature
MAX_STEP_C = 0.5              # largest change between two readings
MIN_TEMPERATURE_C = 18.0      # the tutorial's 10.2 was a typo
MAX_TEMPERATURE_C = 28.0

# ------------------------------------------------------------------ the monitor
HIGH_ABOVE_C = 26.0           # strictly above: High
LOW_BELOW_C = 20.0            # strictly below: Low
STATUSES = ('Low', 'Normal', 'High')

# ------------------------------------------------------------------ notebook 06: the promises
FAN_FILE = f'src/{PACKAGE}/{PACKAGE}/fan_controller.py'
FAN_EXECUTABLE = 'fan_controller'
FAN_CLASS, FAN_NODE = 'FanController', 'fan_controller'
FAN_TOPIC, FAN_MESSAGE_TYPE = 'fan_command', 'std_msgs/msg/Bool'   # True: fan on (High)
PROMISES_FILE = f'src/{PACKAGE}/{PACKAGE}/promises.py'
COUNTING_CLASS, WORKER_CLASS = 'CountingMonitor', 'Worker'
WORKER_FUNCTION, ROOMS_FUNCTION = 'responsive_worker', 'room_arguments'
HEARTBEAT_PERIOD_S = 0.1      # the worker's quick timer: 10 Hz
SLOW_PERIOD_S = 0.5           # the worker's slow timer, whose callback waits for ...
SLOW_SERVICE = 'slow_job'     # ... the answer of this service (std_srvs/srv/Trigger), ...
SLOW_WORK_S = 0.45            # ... which works this long before it answers
WORKER_NODE = 'responsive_worker'
ROOMS = ('kitchen', 'attic')

# ------------------------------------------------------------------ notebook 07: a live plot
LIVE_PLOT_FILE = f'src/{PACKAGE}/{PACKAGE}/live_plot.py'
PLOT_CLASS, PLOT_NODE = 'PlotFeeder', 'plot_feeder'

# ------------------------------------------------------------------ parameters (notebook 08)
#: The monitor's thresholds as parameters: name -> default (°C); both may be set from
#: MIN_TEMPERATURE_C to MAX_TEMPERATURE_C (the sensor's clamp range) while the node runs.
HIGH_PARAMETER, LOW_PARAMETER = 'high_above_c', 'low_below_c'
THRESHOLD_DEFAULTS_C = {HIGH_PARAMETER: HIGH_ABOVE_C, LOW_PARAMETER: LOW_BELOW_C}
#: The sensor's parameters: its period (read-only: the timer is made once) and start value.
PERIOD_PARAMETER, START_PARAMETER = 'publish_period_s', 'start_temperature_c'
MIN_PERIOD_S, MAX_PERIOD_S = 0.1, 10.0

# ------------------------------------------------------------------ notebook 10: bags
#: What a recording holds: one simulated hour of the sensor (s); the monitor's statuses
#: travel in its log messages on /rosout.
RECORD_S = 3600.0
ROSOUT_TOPIC = '/rosout'

#: Notebook number -> the package files its checks judge, as its ``%%part`` cells write them
#: (a pass of one of its checks goes stale when one changes: ros2nb.checks.evidence).
JUDGED_FILES = {3: (PUBLISHER_FILE,), 4: (SUBSCRIBER_FILE,), 5: (SETUP_PY_FILE, SETUP_CFG_FILE),
                6: (FAN_FILE, PROMISES_FILE), 7: (LIVE_PLOT_FILE,),
                8: (PUBLISHER_FILE, SUBSCRIBER_FILE)}

#: Environment variable the grader sets: the course's reference code never stands in.
GRADING_ENV = 'ROS2NB_GRADING'
#: Notebook number -> what must exist before it starts.
STEPS = {1: (), 2: ('workspace',), 3: ('workspace', 'package'),
         4: ('workspace', 'package', 'publisher'),
         5: ('workspace', 'package', 'publisher', 'subscriber'),
         6: ('workspace', 'package', 'publisher', 'subscriber'),
         7: ('workspace', 'package', 'publisher', 'subscriber'),
         8: ('workspace', 'package', 'publisher', 'subscriber', 'entry_points'),
         10: ('workspace', 'package', 'publisher', 'subscriber', 'entry_points')}
#: Where each part of the two node files later notebooks use is written: file -> its class,
#: and each name (the class, a method, ``main``, a parameter the class declares) -> the
#: (notebook, part) cells that write it; notebook 08 writes some parts again, its way.
WRITTEN_IN: dict[str, tuple[str, dict[str, tuple[tuple[int, int], ...]]]] = {
    PUBLISHER_FILE: (SENSOR_CLASS, {
        SENSOR_CLASS: ((3, 3), (8, 3)), 'publish_temperature': ((3, 4),), 'main': ((3, 5),),
        PERIOD_PARAMETER: ((8, 3),), START_PARAMETER: ((8, 3),)}),
    SUBSCRIBER_FILE: (MONITOR_CLASS, {
        MONITOR_CLASS: ((4, 3), (8, 3)), 'temperature_callback': ((4, 4), (8, 4)),
        'main': ((4, 5),), 'on_set_thresholds': ((8, 4),), HIGH_PARAMETER: ((8, 3),),
        LOW_PARAMETER: ((8, 3),)}),
}
#: Notebooks that start the node files as programs (``ros2 run``): their ``main()`` counts.
RUN_AS_PROGRAMS = (5, 6, 8)


def reference_source(name: str) -> str | None:
    """Return a reference node file's text (e.g. ``'temperature_publisher.py'``), or None.

    None while grading, or where the reference files are not installed: then the course's
    code never stands in for the learner's.
    """
    if os.environ.get(GRADING_ENV):
        return None
    try:
        return resources.files('ros2nb.reference').joinpath(name).read_text()
    except (FileNotFoundError, ModuleNotFoundError):
        return None


def package_path(workspace: Path) -> Path:
    """Return ``<workspace>/src/sensor_simulator``."""
    return workspace / 'src' / PACKAGE


def _entry_points_missing(package: Path) -> bool:
    setup_py = package / 'setup.py'
    text = setup_py.read_text() if setup_py.is_file() else ''
    return not all(f'{name} =' in text or f'{name}=' in text
                   for name in (PUBLISHER_EXECUTABLE, SUBSCRIBER_EXECUTABLE))


def _write_entry_points(package: Path) -> None:
    """Notebook 05's two entry points in setup.py, as the course writes them (never over
    a setup.py you edited yourself: write_file refuses)."""
    setup_py = package / 'setup.py'
    entries = ''.join(f"            '{name} = {PACKAGE}.{name}:main',\n"
                      for name in (PUBLISHER_EXECUTABLE, SUBSCRIBER_EXECUTABLE))
    text = setup_py.read_text().replace("'console_scripts': [\n",
                                        "'console_scripts': [\n" + entries, 1)
    write_file(setup_py, text)


def _where(parts: list[tuple[int, int]]) -> str:
    """``notebook 08, part 4`` (``notebook 08, parts 3 and 4``; notebooks joined by ``;``)."""
    by_notebook: dict[int, list[int]] = {}
    for notebook, part in sorted(set(parts)):
        by_notebook.setdefault(notebook, []).append(part)
    return '; '.join(f'notebook {notebook:02d}, part{"s" if len(numbers) > 1 else ""} '
                     f'{" and ".join(map(str, numbers))}'
                     for notebook, numbers in by_notebook.items())


def unfinished_line(workspace: Path, relative: str, notebook: int) -> Optional[str]:
    """The one line naming what earlier notebooks left unwritten in a node file, or None.

    Read from the file's text (:func:`ros2nb.unfinished.missing`), never run; what it names
    and where each part is written come from :data:`WRITTEN_IN`.  It also says how to take
    the course's version instead (:func:`catch_up`), except while grading.

    Introduced in ``04-write-the-subscriber.ipynb``.

    :param workspace: the learner's workspace.
    :param relative: a node file of :data:`WRITTEN_IN`, relative to the workspace.
    :param notebook: the notebook about to use it (its number, as for :func:`catch_up`).
    """
    class_name, parts = WRITTEN_IN[relative]
    name = Path(relative).name
    take = ('' if reference_source(name) is None else
            f', or take the course\'s version with ros2nb.course.catch_up({notebook}, '
            f'take=[\'{name}\']) (yours is kept as {name}.bak)')
    try:
        text = (workspace / relative).read_text()
        found = unfinished.missing(text, class_name, parts, programs=notebook in RUN_AS_PROGRAMS)
    except (OSError, UnicodeDecodeError, ValueError):
        return None  # missing (catch_up writes it) or unreadable: its own use says why
    except SyntaxError as error:
        return (f'{name} does not load (line {error.lineno}: {error.msg}): fix the %%part cell '
                f'that wrote that line and run it again{take}.')
    if not found:
        return None
    whats = [what for _names, what in found]
    listed = '; '.join(whats)
    # The file is at the newest notebook whose own names it holds: a part that notebook
    # writes again is to be written there (08's temperature_callback, not 04's).
    words = set(re.findall(r'\w+', text))
    newest = max((places[0][0] for part, places in parts.items() if part in words), default=0)
    names = [part for names, _what in found for part in names]
    where = [max((p for p in parts[part] if p[0] <= newest), default=parts[part][0])
             for part in names]
    return (f'{name} is not finished: it lacks {listed} ({_where(where)}): write '
            f'{"them" if len(names) > 1 else "it"} there and run '
            f'{"those cells" if len(set(where)) > 1 else "that cell"}{take}.')


def catch_up(notebook: int, *, take: Sequence[str] = ()) -> Path:
    """Create whatever earlier notebooks would have made, if it is missing, and say in one
    line per file what earlier notebooks left unwritten in the nodes this one uses
    (:func:`unfinished_line`).

    Each step creates only what is missing and never changes a file you wrote, unless you
    name it in ``take``.  The nodes it writes are the course's reference code (the
    tutorial's, with its mistakes fixed); while grading it writes none, so only your own
    nodes are graded.

    Introduced in ``01-create-a-workspace.ipynb``.

    :param notebook: the number of the notebook about to run (1-8, 10).
    :param take: node files to replace with the course's version now, e.g.
        ``['temperature_subscriber.py']``; yours is kept beside it as ``<name>.bak``.
    :return: the workspace path.
    :raises ValueError: for a notebook number without steps, or a file ``take`` cannot give.
    """
    if notebook not in STEPS:
        raise ValueError(f'notebook must be one of {sorted(STEPS)} (got {notebook}).')
    steps = STEPS[notebook]
    done, missing = [], []
    for name in take:
        done.append(_take_course_file(name))
    if 'workspace' in steps and not default_workspace().is_dir():
        done.append(shown(default_workspace()))
    ws = create_workspace()  # also re-creates any missing sub-folder, like mkdir -p
    package = package_path(ws)
    if 'package' in steps and not package.exists():
        with contextlib.redirect_stdout(io.StringIO()):  # notebook 02 shows pkg create's lines
            pkg_create(PACKAGE, destination=ws / 'src', dependencies=list(DEPENDENCIES),
                       maintainer_name=MAINTAINER_NAME, maintainer_email=MAINTAINER_EMAIL)
        done.append(shown(package))
    for step in ('publisher', 'subscriber'):
        target = package / PACKAGE / f'temperature_{step}.py'
        if step not in steps or target.exists():
            continue
        text = reference_source(target.name)
        if text is None:
            missing.append(target.name)
            continue
        write_file(target, text)
        target.chmod(0o755)
        done.append(shown(target))
    if 'entry_points' in steps and _entry_points_missing(package):
        if reference_source(PUBLISHER_FILE.rsplit('/', 1)[1]) is None:
            missing.append('the entry points in setup.py')
        else:
            _write_entry_points(package)
            done.append(shown(package / 'setup.py'))
    if done:
        print('Caught up: created ' + ', '.join(done))
    elif not missing:
        print(f'Nothing to catch up: {shown(ws)} has what notebook {notebook:02d} needs.')
    if missing:
        print(f'Not created: {", ".join(missing)} (only your own nodes count here); the '
              'cells that use them will fail until you write them.')
    _say_unfinished(ws, notebook, steps)
    return ws


def _say_unfinished(ws: Path, notebook: int, steps: tuple[str, ...]) -> None:
    """One line for each node file among ``steps`` that earlier notebooks left unfinished."""
    for step, relative in (('publisher', PUBLISHER_FILE), ('subscriber', SUBSCRIBER_FILE)):
        line = unfinished_line(ws, relative, notebook) if step in steps else None
        if line:
            print(line)


def _take_course_file(name: str) -> str:
    """Replace a node file with the course's version (yours kept as ``.bak``); its name shown.

    :raises ValueError: for a name that is not a node file of the course's, or while grading.
    """
    relative = {Path(r).name: r for r in WRITTEN_IN}.get(Path(name).name)
    text = reference_source(Path(name).name) if relative else None
    if relative is None or text is None:
        raise ValueError(f'take= names the course\'s node files, '
                         f'{" or ".join(repr(Path(r).name) for r in WRITTEN_IN)} (got {name!r}); '
                         'the course gives none while grading.')
    target = create_workspace() / relative
    write_file(target, text, overwrite=True)
    target.chmod(0o755)
    return shown(target) + ' (the course\'s version)'

