"""The checks behind every part you write: each says in one line what is still wrong.

A check passes with one ``Check passed: ...`` line, or raises :class:`CheckFailed` whose
one line names your value, the expected one and what to change; when your own code
raised, you see its traceback (your lines only) instead.  Checks test behaviour (what a
node publishes and logs, what a function returns, how a process exits on Ctrl+C); they
never print the answer's code.

Checks of your files (notebooks 03-07) run in a judge process of their own
(:mod:`ros2nb.judge`, started by name), on a ROS domain of their own, so the nodes
running in your kernel neither disturb them nor are disturbed.  The grader runs the very same functions, in the
same way, on your submitted work; the points come from there, never from your kernel.
Checks of a function or class you defined in a cell (notebooks 00-02) call it right here
in the kernel; the grader runs those from the source of your answer cell.

One module per lesson (``lesson00`` ... ``lesson10``) on a small shared vocabulary:
``base`` (a check's parts and the judge it asks), ``dispatch`` (kernel to judge and back),
``verdicts``, ``answers`` (answer cells), ``nodes`` (a node from a file), ``mains``
(``main()`` and Ctrl+C).  A new lesson adds a module and its names here.
"""

from ..errors import CheckFailed
from .lesson00 import check_endpoint
from .lesson01 import check_expanded_path
from .lesson02 import check_dependencies, package_dependencies
from .lesson03 import (check_publisher_samples, check_sensor_callback, check_sensor_constructor,
                       check_sensor_hour, check_sensor_main)
from .lesson04 import (check_monitor_callback, check_monitor_constructor, check_monitor_main,
                       check_monitor_readings)
from .lesson05 import check_entry_points, check_package_runs, check_setup_cfg
from .lesson06 import (check_counting_monitor, check_fan_controller, check_fan_main,
                       check_responsive_worker, check_room_arguments)
from .lesson07 import check_plot_callback
from .lesson08 import check_monitor_parameters, check_threshold_callback
from .lesson09 import check_latched_thresholds, check_newest_only, check_sensor_subscription
from .lesson10 import check_readings, check_recording, check_replay

__all__ = [
    'CheckFailed', 'check_counting_monitor', 'check_dependencies', 'check_endpoint',
    'check_entry_points', 'check_expanded_path', 'check_fan_controller', 'check_fan_main',
    'check_latched_thresholds', 'check_monitor_callback', 'check_monitor_constructor',
    'check_monitor_main', 'check_monitor_parameters', 'check_monitor_readings',
    'check_newest_only', 'check_package_runs', 'check_plot_callback', 'check_readings',
    'check_recording', 'check_replay',
    'check_publisher_samples', 'check_responsive_worker', 'check_room_arguments',
    'check_sensor_callback', 'check_sensor_constructor', 'check_sensor_hour',
    'check_sensor_main', 'check_sensor_subscription', 'check_setup_cfg',
    'check_threshold_callback',
    'package_dependencies',
]
