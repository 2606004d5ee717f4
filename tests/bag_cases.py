"""What the checks of notebook 10 (record and replay) are tested against: shared by two files.

The answers are the solution notebook's answer cells, so they never go stale; each mistake
is one edit of an answer and the line its check must give. Each mistake runs twice, as the
kernel runs it (``test_checks_bag_kernel.py``: the learner's function called in the test
process, with ROS up there on simulated time) and as the grader runs it
(``test_checks_bag_judge.py``: the test process is the judge; the answer cell runs in a real
subject). Two files, two processes: a kernel never has a judge listening in its own process,
and the two halves run side by side.
"""

from __future__ import annotations

import os
from typing import Optional

from ros2nb import checks, course

from judging import answer_cells

HERE = os.path.dirname(__file__)
SOLUTION = os.path.join(HERE, '..', 'solutions', '10-record-and-replay.ipynb')
LEARNER = os.path.join(HERE, '..', 'notebooks', '10-record-and-replay.ipynb')
CHECKS = {'record_hour': checks.check_recording, 'replay': checks.check_replay,
          'read_temperatures': checks.check_readings}

CONTEXT, ANSWERS = answer_cells(SOLUTION)
#: The grading-context cell without its ``ros2nb.start``: the test module starts ROS itself.
CONTEXT_WITHOUT_START = CONTEXT.replace('_ = ros2nb.start', '# ')

#: (answer, label, text of the answer, its replacement, the check's line as a regex).
MISTAKES = [
    ('record_hour', 'no /rosout', "'/temperature', '/rosout')", "'/temperature')",
     r"^The bag holds /temperature but not /rosout \(the monitor's statuses\): record both "
     r'/temperature and /rosout\.$'),
    ('record_hour', 'a minute', 'spin(HOUR_S,', 'spin(60,',
     r'^60 readings went out on /temperature while record_hour\(bag_path\) ran; one simulated '
     r'hour of the sensor is 3600'),
    ('record_hour', 'another folder', 'bag_record(bag_path,',
     "bag_record(Path(tempfile.mkdtemp()) / 'elsewhere',",
     r'^record_hour\(bag_path\) wrote no bag at the path it was given: pass bag_path'),
    ('record_hour', 'no seed', '    random.seed(SEED)\n', '',
     r'^record_hour\(bag_path\) recorded an hour starting [\d., ]+ °C, but the sensor seeded '
     r'with random\.seed\(SEED\) starts [\d., ]+ °C: call random\.seed\(SEED\) in record_hour'),
    ('record_hour', 'no monitor', '    ros2nb.add(sub.TemperatureMonitor())\n', '',
     r'^temperature_monitor logged no status while record_hour\(bag_path\) ran: add your monitor'),
    ('replay', 'no monitor', '    ros2nb.add(sub.TemperatureMonitor())\n', '',
     r'^temperature_monitor logged no status during the replay: add your monitor before '
     r'bag_play'),
    ('replay', 'monitor after play', "    ros2nb.add(sub.TemperatureMonitor())\n    "
     "ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])\n",
     "    ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])\n"
     '    ros2nb.add(sub.TemperatureMonitor())\n',
     r'^temperature_monitor logged no status during the replay'),
    ('replay', 'monitor never stopped', 'ros2nb.stop()', 'pass',
     r'^replay\(bag_path, rate\) returned with /?temperature_monitor still running: end it with '
     r'ros2nb\.stop\(\), as the task says, so that it stops the nodes it added\.$'),
    ('read_temperatures', 'absolute times', '(stamp - first) / 1e9', 'stamp / 1e9',
     r'^read_temperatures\(\) returned times \[1\.0, 2\.0, 3\.0\]\.\.\.; expected seconds since '
     r'the first reading'),
    ('read_temperatures', 'one list', 'return times_s, temperatures_c', 'return temperatures_c',
     r'^read_temperatures\(\) returned list; return two lists: \(times_s, temperatures_c\)\.$'),
    ('read_temperatures', 'another type', 'reader.deserialize(raw, connection.msgtype)',
     "reader.deserialize(raw, 'std_msgs/msg/Float64')",
     r'this bag holds no std_msgs/msg/Float64 messages \(.*/temperature.*std_msgs/msg/Float32\): '
     r'deserialize each message with the type its connection names, '
     r'reader\.deserialize\(raw, connection\.msgtype\)\.(?: \(.*line \d+: .*\))?$'),
    ('read_temperatures', 'every connection', 'reader.messages(chosen)',
     'reader.messages(reader.connections)',
     r"this message came from /rosout \(rcl_interfaces/msg/Log: a log line, with no data\): "
     r"read only the /temperature connections, reader\.messages\(\[c for c in "
     r"reader\.connections if c\.topic == '/temperature'\]\)\.(?: \(.*line \d+: .*\))?$"),
]
MISTAKE_IDS = [f'{m[0]}: {m[1]}' for m in MISTAKES]

#: Simulated seconds a mistake of ``record_hour`` records, unless the mistake is the length
#: itself: ``course.RECORD_S`` and the notebook's ``HOUR_S`` are both set to it for that test.
#: Which line a mistake gets does not depend on how long the recording runs, and the full
#: hour of the sensor and the monitor would cost each mistake an hour in the kernel and
#: another in the judge and its subject (docs/decisions.md).  ``test_the_solutions_pass``
#: records the full hour, both ways.
SHORT_RECORD_S = 120
#: The grading context's line that sets the hour (the course's own length).
HOUR_LINE = f'HOUR_S = {int(course.RECORD_S)}\n'


def recording_length(name: str, old: str) -> Optional[int]:
    """The shorter length (s) the mistake ``old`` of answer ``name`` records, or None for
    the full hour (any other answer, or a mistake in the length itself)."""
    return SHORT_RECORD_S if name == 'record_hour' and 'HOUR_S' not in old else None


def with_hour(context: str, seconds: Optional[int]) -> str:
    """The grading context with its ``HOUR_S`` set to ``seconds`` (None: as it is)."""
    if seconds is None:
        return context
    assert HOUR_LINE in context, HOUR_LINE
    return context.replace(HOUR_LINE, f'HOUR_S = {seconds}\n')


def edited(name: str, old: str, new: str) -> str:
    """The solution's answer ``name`` with its first ``old`` replaced by ``new``."""
    answer = ANSWERS[name]
    assert old in answer, old
    return answer.replace(old, new, 1)
