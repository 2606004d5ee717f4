"""Lookup-table answers, each beside its honest-wrong twin: right for exactly the inputs the
judge once fed every run (fixed, and readable in ``ros2nb.checks``), wrong in general.

Each table is built from those old inputs as a learner reading the course's code would have
built it: notebook 04's boundary readings and the hidden test's ``random.Random(2024)``
readings, 06's fan readings, counted readings, rooms and the counting monitor's name
('monitor_7'), 07's readings one second apart from 0 s, 08's three refused changes, 03's
clamp probes.  With fixed inputs each scored above its twin (the same answer without the
table); with inputs drawn for each run (:mod:`ros2nb.checks.drawn`) it scores what its twin
scores (``test_corpora.py``).
"""

import random

from corpora import Learner

#: Notebook 04's old inputs: the callback's boundary readings, the hidden test's readings.
_hidden = random.Random(2024)
OLD_04_READINGS_C = (19.99, 20.0, 23.0, 26.0, 26.01, 18.5, 27.5,
                     *(round(_hidden.uniform(17.0, 29.0), 2) for _ in range(30)),
                     20.0, 26.0, 19.995, 26.005)


def _status(value: float) -> str:
    return 'High' if value > 26.0 else 'Low' if value < 20.0 else 'Normal'


TABLE_04 = {value: _status(value) for value in OLD_04_READINGS_C}

#: 04: every reading called Normal, or, with the table, the status the table holds for it.
MONITOR_04 = '''
    def temperature_callback(self, msg):
        temperature_c = msg.data
        status = {table}.get(round(temperature_c, 3), 'Normal')
        self.get_logger().info(f'Temperature: {{temperature_c:.2f}}C - Status: {{status}}')
'''
#: 06: the fan never on / on for the old High readings; nothing counted / the count read off
#: the old readings (20.0 + n); no namespace / the old two rooms' namespaces.
FAN_06 = ('command.data = msg.data > HIGH_ABOVE_C', 'command.data = {}')
COUNT_06 = ('        self.received += 1\n'
            "        self.get_logger().info(f'received {self.received}')\n",
            "        self.get_logger().info(f'received {{{}}}')\n")
ROOMS_06 = ("    return ['--ros-args', '-r', f'__ns:=/{room}']\n", '    return {}\n')
ROOMS_TABLE = ("{'kitchen': ['--ros-args', '-r', '__ns:=/kitchen'], "
               "'attic': ['--ros-args', '-r', '__ns:=/attic']}.get(room, ['--ros-args'])")
#: 07: every point at 0 s / at the second the old readings came (1, 2, 3, 4 s).
TIMES_07 = ('self.times_s.append(self.get_clock().now().nanoseconds / 1e9)',
            'self.times_s.append({})')
#: 08: every change accepted / the old three inverted changes refused.
ON_SET_08 = ("""\
        new = {parameter.name: parameter.value for parameter in parameters}
        high_c = new.get('high_above_c', self.get_parameter('high_above_c').value)
        low_c = new.get('low_below_c', self.get_parameter('low_below_c').value)
        if low_c >= high_c:
            return SetParametersResult(
                successful=False,
                reason=f'low_below_c ({low_c}) must stay below high_above_c ({high_c})')
""", """\
        if any((parameter.name, parameter.value) in {} for parameter in parameters):
            return SetParametersResult(
                successful=False, reason='low_below_c must stay below high_above_c')
""")
#: 03: no clamp / a clamp only once the grader set the walk where the old probes started it.
#: It looks for a start the grader set (a jump no step makes), not for the value alone: a walk
#: passes through 27.95 on its own in a few percent of drawn probes, and an answer that then
#: clamps every reading asked of it rightly passes.
SENSOR_03 = '''
    def publish_temperature(self):
        set_by_grader = abs(self.temperature - getattr(self, 'walked', self.temperature)) \\
            > MAX_STEP_C
        if set_by_grader and round(self.temperature, 2) in {table}:
            self.clamping = True
        step = random.uniform(-MAX_STEP_C, MAX_STEP_C)
        walked = self.temperature + step
        if getattr(self, 'clamping', False):
            walked = max(MIN_TEMPERATURE_C, min(MAX_TEMPERATURE_C, walked))
        self.temperature = self.walked = walked
        msg = Float32()
        msg.data = self.temperature
        self.publisher_.publish(msg)
        self.get_logger().info(f'Publishing: {{self.temperature:.2f}}C')
'''


def _06(fan: str, count: str, rooms: str) -> dict:
    return {'fan-controller': [(FAN_06[0], FAN_06[1].format(fan))],
            'counting-monitor': [(COUNT_06[0], COUNT_06[1].format(count))],
            'room-arguments': [(ROOMS_06[0], ROOMS_06[1].format(rooms))]}


TABLES = [
    Learner('04 twin: every reading called Normal', '04',
            {'monitor-callback': MONITOR_04.format(table='{}')},
            loses=('monitor-callback', 'monitor-readings')),
    Learner('04 table: the statuses of the old readings', '04',
            {'monitor-callback': MONITOR_04.format(table=repr(TABLE_04))},
            twin='04 twin: every reading called Normal'),
    Learner('06 twin: fan off, nothing counted, no room', '06',
            _06('False', '0', "['--ros-args']"),
            loses=('fan-controller', 'counting-monitor', 'room-arguments')),
    Learner('06 table: the old fan readings, counts and rooms', '06',
            _06('round(msg.data, 2) in (26.01, 27.5)', 'round(msg.data) - 20', ROOMS_TABLE),
            twin='06 twin: fan off, nothing counted, no room'),
    Learner('06 twin: a counting monitor that ignores its name', '06', {'counting-monitor': [(
        '        super().__init__(name)\n', "        super().__init__('counting_monitor')\n")]},
            loses=('counting-monitor',)),
    Learner('06 table: a counting monitor named as the old check names it', '06', {
        'counting-monitor': [('        super().__init__(name)\n',
                              "        super().__init__('monitor_7')\n")]},
            twin='06 twin: a counting monitor that ignores its name'),
    Learner('07 twin: every point at 0 s', '07', {'plot-callback': [(
        TIMES_07[0], TIMES_07[1].format('0.0'))]}, loses=('plot-callback',)),
    Learner('07 table: the seconds the old readings came', '07', {'plot-callback': [(
        TIMES_07[0], TIMES_07[1].format('{21.5: 1.0, 26.25: 2.0, 19.75: 3.0, 23.0: 4.0}'
                                        '.get(msg.data, 0.0)'))]},
            twin='07 twin: every point at 0 s'),
    Learner('08 twin: every change accepted', '08',
            {'threshold-callback': [(ON_SET_08[0], ON_SET_08[1].format('()'))]},
            loses=('threshold-callback',)),
    Learner('08 table: the old three inverted changes refused', '08', {
        'threshold-callback': [(ON_SET_08[0], ON_SET_08[1].format(repr((
            ('low_below_c', 25.5), ('low_below_c', 25.0), ('high_above_c', 20.5)))))]},
            twin='08 twin: every change accepted'),
    Learner('03 twin: no clamp', '03', {'sensor-callback': SENSOR_03.format(table='()')},
            loses=('sensor-callback', 'sensor-hour')),
    Learner('03 table: a clamp once the walk was where the old probes start', '03',
            {'sensor-callback': SENSOR_03.format(table='(27.95, 18.05)')},
            twin='03 twin: no clamp'),
]
