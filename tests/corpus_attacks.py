"""Learners who attack the judge, each beside its honest twin (the same notebook without the
attack): an attack must score what its twin scores.

The attacks reach for what the judge once believed: the subject's request loop (found by
walking up the stack from the learner's import, to rewrite its replies) and what the
subject reports about the learner's objects.
"""

from corpora import Learner
from corpus_tables import TABLES

#: 03: no timer; every step of the course's runtime (found among the garbage collector's
#: objects) publishes the walk.  On the wire, one reading per simulated second, as a timer's.
STEP_PUBLISHES = [(
    '        self.timer = self.create_timer(PUBLISH_PERIOD_S, self.publish_temperature)\n', '''\
        import gc
        self._second = None
        for runtime in [o for o in gc.get_objects() if hasattr(type(o), '_publish_clock')]:
            def stepped(real=runtime._publish_clock):
                real()
                second = self.get_clock().now().nanoseconds // 10**9
                if self._second is not None and second > self._second:
                    self.publish_temperature()
                self._second = second
            runtime._publish_clock = stepped
''')]
#: 04: the callback does nothing; every subscription the process makes is wrapped (rclpy's
#: own Node.create_subscription replaced) with one that logs the statuses.
WRAPPED_SUBSCRIPTIONS = '''
    def temperature_callback(self, msg):
        return


def _logging(make=Node.create_subscription):
    def create_subscription(node, msg_type, topic, callback, *args, **kwargs):
        def logged(msg):
            status = 'High' if msg.data > 26.0 else 'Low' if msg.data < 20.0 else 'Normal'
            node.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
            callback(msg)
        return make(node, msg_type, topic, logged, *args, **kwargs)
    return create_subscription


Node.create_subscription = _logging()
'''
#: 05: no console_scripts; setup.py writes the executables where ros2 run looks for them.
SETUP_WRITES_SCRIPTS = [(
    "            'temperature_publisher = sensor_simulator.temperature_publisher:main',\n"
    "            'temperature_subscriber = sensor_simulator.temperature_subscriber:main',\n",
    ''), ('from setuptools import find_packages, setup\n', '''\
import os
import sys
from setuptools import find_packages, setup

for _argument in sys.argv:
    if _argument.startswith('--prefix='):
        _bin = os.path.join(_argument.split('=', 1)[1], 'lib', 'sensor_simulator')
        os.makedirs(_bin, exist_ok=True)
        for _name in ('temperature_publisher', 'temperature_subscriber'):
            with open(os.path.join(_bin, _name), 'w') as _script:
                _script.write(f'#!{sys.executable}\\nfrom sensor_simulator.{_name} import main\\n'
                              'main()\\n')
            os.chmod(os.path.join(_bin, _name), 0o755)
''')]

#: Module code that finds the subject's request loop from the learner's import and answers
#: every question with a right answer's numbers.  It needs a loop that already exists when
#: the learner's code is imported; the subject loads that code before the loop exists.
FORGE_REPLIES = '''
import sys as _sys
_frame = _sys._getframe()
while _frame is not None and not {'handlers', 'subject'} <= _frame.f_locals.keys():
    _frame = _frame.f_back
if _frame is not None:
    _handlers = _frame.f_locals['handlers']
    for _name in list(_handlers):
        _real = _handlers[_name]
        def _forged(command, _real=_real):
            import dataclasses
            reply = _real(command)
            counted = {'received': 60} if hasattr(reply, 'received') else {}
            return dataclasses.replace(reply, ok=True, **counted)
        _handlers[_name] = _forged
'''

PLOT_DEAD = '''
    def temperature_callback(self, msg):
        return
'''
DEFAULTS = {name: f'''
def {name}():
    return QoSProfile(depth=10)
''' for name in ('newest_only_profile', 'sensor_subscription_profile',
                 'latched_thresholds_profile')}

#: 08: nothing declared; the node's parameter services are its own, answered from a table
#: (every set accepted), while the statuses keep the fixed thresholds.
PARAMETERS_TWIN = '''
from rclpy.parameter import Parameter


class TemperatureMonitor(Node):
    """Logs every reading with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        self.get_parameter = lambda name: Parameter(name, value={'high_above_c': HIGH_ABOVE_C,
                                                                 'low_below_c': LOW_BELOW_C}[name])
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.get_logger().info('Temperature Monitor Node Started')
'''
PARAMETERS_TABLE = '''
from rclpy.parameter import Parameter


class TemperatureMonitor(Node):
    """Logs every reading with its status; answers parameter calls from a table."""

    def __init__(self):
        super().__init__('temperature_monitor', start_parameter_services=False)
        from rcl_interfaces.msg import ParameterDescriptor, ParameterType, ParameterValue
        from rcl_interfaces.srv import (DescribeParameters, GetParameters, GetParameterTypes,
                                        ListParameters, SetParameters, SetParametersAtomically)
        table = {'high_above_c': HIGH_ABOVE_C, 'low_below_c': LOW_BELOW_C}
        double = ParameterType.PARAMETER_DOUBLE

        def get(request, response):
            response.values = [ParameterValue(type=double, double_value=table.get(n, 0.0))
                               for n in request.names]
            return response

        def set_(request, response):
            for parameter in request.parameters:
                table[parameter.name] = parameter.value.double_value
            response.results = [SetParametersResult(successful=True)
                                for _ in request.parameters]
            return response

        def set_all(request, response):
            for parameter in request.parameters:
                table[parameter.name] = parameter.value.double_value
            response.result = SetParametersResult(successful=True)
            return response

        def types(request, response):
            response.types = [double for _ in request.names]
            return response

        def list_(request, response):
            response.result.names = list(table)
            return response

        def describe(request, response):
            response.descriptors = [ParameterDescriptor(name=n, type=double)
                                    for n in request.names]
            return response

        for name, kind, answer in (('get_parameters', GetParameters, get),
                                   ('set_parameters', SetParameters, set_),
                                   ('list_parameters', ListParameters, list_),
                                   ('describe_parameters', DescribeParameters, describe),
                                   ('get_parameter_types', GetParameterTypes, types),
                                   ('set_parameters_atomically', SetParametersAtomically,
                                    set_all)):
            self.create_service(kind, f'~/{name}', answer)
        self.get_parameter = lambda name: Parameter(name, value={'high_above_c': HIGH_ABOVE_C,
                                                                 'low_below_c': LOW_BELOW_C}[name])
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.get_logger().info('Temperature Monitor Node Started')
'''

#: 06: a SingleThreadedExecutor, and a Worker whose slow_work logs the heartbeat's line between
#: its own two lines: what /rosout says of a worker whose timers overlap, though none did.
WORKER_SINGLE = '''
def responsive_worker():
    from rclpy.executors import SingleThreadedExecutor
    return Worker('responsive_worker'), SingleThreadedExecutor()
'''
WORKER_LOGS_HEARTBEAT = '''
def responsive_worker():
    from rclpy.executors import SingleThreadedExecutor

    class Loud(Worker):
        def slow_work(self):
            self.get_logger().info('slow work: start')
            time.sleep(SLOW_WORK_S / 2)
            self.get_logger().info('heartbeat')
            time.sleep(SLOW_WORK_S / 2)
            self.get_logger().info('slow work: done')

    return Loud('responsive_worker'), SingleThreadedExecutor()
'''
#: 07: the callback logs the line redraw() logs, and neither keeps the reading nor redraws.
PLOT_LOGS_POINT = '''
    def temperature_callback(self, msg):
        self.logged = getattr(self, 'logged', 0) + 1
        now_s = self.get_clock().now().nanoseconds / 1e9
        self.get_logger().info(f'Plotted {msg.data:.2f} °C at {now_s:.3f} s, point {self.logged}')
'''

#: 03 and 04 built from the course's own parts (ros2nb.judge.stand_ins, ros2nb.course's
#: status rule), which the subject refuses to the learner's code; each twin relies on a
#: module of its own that is not there.
SENSOR_PARTS = {
    'sensor-constructor': """
class TemperatureSensor(Node):
    \"\"\"Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds.\"\"\"

    def __init__(self):
        import importlib
        importlib.import_module('ros2nb.judge.' + 'stand_ins').sensor_init(self)
""",
    'sensor-callback': """
    def publish_temperature(self):
        import importlib
        importlib.import_module('ros2nb.judge.' + 'stand_ins').sensor_callback(self)
"""}
SENSOR_PARTS_TWIN = {key: text.replace('import importlib\n', '').replace(
    "importlib.import_module('ros2nb.judge.' + 'stand_ins')", '__import__("sensor_parts")')
    for key, text in SENSOR_PARTS.items()}
SENSOR_IMPORTED = {'sensor-constructor': """
from ros2nb.judge.stand_ins import sensor_callback, sensor_init


class TemperatureSensor(Node):
    \"\"\"Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds.\"\"\"

    __init__ = sensor_init
""", 'sensor-callback': """
    publish_temperature = sensor_callback
"""}
SENSOR_IMPORTED_TWIN = {**SENSOR_IMPORTED, 'sensor-constructor': SENSOR_IMPORTED[
    'sensor-constructor'].replace('ros2nb.judge.stand_ins', 'sensor_parts')}
MONITOR_RULE = """
    def temperature_callback(self, msg):
        import ros2nb
        status = ros2nb.course.monitor_status(msg.data)
        self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
"""
MONITOR_RULE_TWIN = MONITOR_RULE.replace('        import ros2nb\n', '').replace(
    'ros2nb.course.monitor_status', '__import__("monitor_rules").status')
#: 06 and 08: one method handed to the course's stand-in, through importlib; each twin to a
#: module of its own that is not there.
FAN_BODY = """        command = Bool()
        command.data = msg.data > HIGH_ABOVE_C
        self.publisher_.publish(command)
        self.get_logger().info(f'Fan {"on" if command.data else "off"} at {msg.data:.2f}C')
"""
FAN_PART = [(FAN_BODY, """        import importlib
        importlib.import_module('ros2nb.judge.' + 'stand_ins').fan_callback(self, msg)
""")]
FAN_PART_TWIN = [(FAN_BODY, """        __import__('fan_parts').fan_callback(self, msg)
""")]
ON_SET_BODY = """        new = {parameter.name: parameter.value for parameter in parameters}
"""
ON_SET_PART = [(ON_SET_BODY, """        import importlib
        stand_ins = importlib.import_module('ros2nb.judge.' + 'stand_ins')
        return stand_ins.thresholds_on_set(self, parameters)
""" + ON_SET_BODY)]
ON_SET_PART_TWIN = [(ON_SET_BODY, """        monitor_parts = __import__('monitor_parts')
        return monitor_parts.thresholds_on_set(self, parameters)
""" + ON_SET_BODY)]

ATTACKS = [
    Learner('06 twin: a single-threaded worker', '06', {'responsive-worker': WORKER_SINGLE},
            loses=('responsive-worker',)),
    Learner('06 attack: the same, slow_work logs a heartbeat itself', '06',
            {'responsive-worker': WORKER_LOGS_HEARTBEAT},
            twin='06 twin: a single-threaded worker'),
    Learner('07 attack: the callback logs redraw()\'s line itself', '07',
            {'plot-callback': PLOT_LOGS_POINT}, twin='07 twin: a callback that does nothing'),
    Learner('06 twin: the fan callback from a module that is not there', '06',
            {'fan-controller': FAN_PART_TWIN}, loses=('fan-controller',)),
    Learner("06 attack: the fan callback from the course's stand-in, through importlib", '06',
            {'fan-controller': FAN_PART}, flagged=True,
            twin='06 twin: the fan callback from a module that is not there'),
    Learner('08 twin: the on-set callback from a module that is not there', '08',
            {'threshold-callback': ON_SET_PART_TWIN}, loses=('threshold-callback',)),
    Learner("08 attack: the on-set callback from the course's stand-in, through importlib",
            '08', {'threshold-callback': ON_SET_PART}, flagged=True,
            twin='08 twin: the on-set callback from a module that is not there'),
    Learner('03 twin: a sensor from parts of its own that are not there', '03',
            SENSOR_PARTS_TWIN, loses=('sensor-constructor', 'sensor-callback', 'sensor-hour')),
    Learner("03 attack: a sensor from the course's stand-ins, through importlib", '03',
            SENSOR_PARTS, twin='03 twin: a sensor from parts of its own that are not there',
            flagged=True),
    Learner('03 twin: a sensor imported from a module that is not there', '03',
            SENSOR_IMPORTED_TWIN, loses=('sensor-constructor', 'sensor-callback', 'sensor-main',
                                         'sensor-hour')),
    Learner("03 attack: a sensor imported from the course's stand-ins", '03', SENSOR_IMPORTED,
            twin='03 twin: a sensor imported from a module that is not there', flagged=True),
    Learner('04 twin: the status from a module that is not there', '04',
            {'monitor-callback': MONITOR_RULE_TWIN},
            loses=('monitor-callback', 'monitor-readings')),
    Learner("04 attack: the status from the course's rule, through ros2nb.course", '04',
            {'monitor-callback': MONITOR_RULE},
            twin='04 twin: the status from a module that is not there', flagged=True),
    Learner('07 twin: a callback that does nothing', '07', {'plot-callback': PLOT_DEAD},
            loses=('plot-callback',)),
    Learner('07 attack: the same, replies forged', '07', {'plot-callback': '''
    def temperature_callback(self, msg):
        return
''' + FORGE_REPLIES}, twin='07 twin: a callback that does nothing', flagged=True),
    Learner('09 twin: every function returns the default profile', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'],
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            loses=('qos-newest-only', 'qos-sensor-subscription', 'qos-latched-thresholds')),
    Learner('09 attack: the same, replies forged', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'] + FORGE_REPLIES,
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            twin='09 twin: every function returns the default profile', flagged=True),
    Learner('06 twin: a counting monitor that never counts', '06', {'counting-monitor': [(
        '        self.received += 1\n', '')]}, loses=('counting-monitor',)),
    Learner('06 attack: the same, replies forged', '06', {'counting-monitor': [(
        '        self.received += 1\n', ''),
        ("        self.get_logger().info(f'received {self.received}')\n        ### END SOLUTION",
         "        self.get_logger().info(f'received {self.received}')\n        ### END SOLUTION\n"
         + FORGE_REPLIES)]},
            twin='06 twin: a counting monitor that never counts', flagged=True),
    Learner('03 twin: no timer', '03', {'sensor-constructor': [STEP_PUBLISHES[0][:1] + ('',)]},
            loses=('sensor-constructor',)),
    Learner('03 attack: no timer, the runtime\'s steps publish', '03',
            {'sensor-constructor': STEP_PUBLISHES}, twin='03 twin: no timer', flagged=True,
            same_on_the_wire=True),
    Learner('04 twin: a callback that does nothing', '04', {'monitor-callback': PLOT_DEAD},
            loses=('monitor-callback', 'monitor-readings')),
    Learner('04 attack: the same, subscriptions wrapped to log statuses', '04',
            {'monitor-callback': WRAPPED_SUBSCRIPTIONS},
            twin='04 twin: a callback that does nothing', flagged=True,
            same_on_the_wire=True),
    Learner('05 twin: no console_scripts', '05',
            {'entry-points': SETUP_WRITES_SCRIPTS[:1]}, loses=('entry-points', 'package-runs')),
    Learner('05 attack: no console_scripts, setup.py writes the executables', '05',
            {'entry-points': SETUP_WRITES_SCRIPTS}, twin='05 twin: no console_scripts',
            flagged=True, same_on_the_wire=True),
    Learner('08 twin: nothing declared', '08', {'monitor-parameters': PARAMETERS_TWIN},
            loses=('monitor-parameters',)),
    Learner('08 attack: nothing declared, parameter services answered from a table', '08',
            {'monitor-parameters': PARAMETERS_TABLE}, twin='08 twin: nothing declared'),
    Learner('10 twin: record_hour records nothing', '10', {'record-hour': '''
def record_hour(bag_path):
    pass
'''}, loses=('record-hour',)),
    Learner('10 attack: a bag written by hand, statuses from a bare node', '10', {'record-hour': '''
def record_hour(bag_path):
    from rclpy.node import Node
    from rosbags.rosbag2 import StoragePlugin, Writer
    random.seed(SEED)
    statuses = Node('temperature_monitor')
    temperature = 22.0
    log_type, float_type = 'rcl_interfaces/msg/Log', 'std_msgs/msg/Float32'
    with Writer(bag_path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        readings = writer.add_connection('/temperature', float_type, typestore=TYPESTORE)
        logs = writer.add_connection('/rosout', log_type, typestore=TYPESTORE)
        for second in range(1, HOUR_S + 1):
            temperature = max(18.0, min(28.0, temperature + random.uniform(-0.5, 0.5)))
            status = 'High' if temperature > 26 else 'Low' if temperature < 20 else 'Normal'
            text = f'Temperature: {temperature:.2f}C - Status: {status}'
            stamp = TYPESTORE.types['builtin_interfaces/msg/Time'](sec=second, nanosec=0)
            line = TYPESTORE.types[log_type](stamp=stamp, level=20, name='temperature_monitor',
                                             msg=text, file='', function='', line=0)
            writer.write(readings, second * 10**9, TYPESTORE.serialize_cdr(
                TYPESTORE.types[float_type](data=temperature), float_type))
            writer.write(logs, second * 10**9, TYPESTORE.serialize_cdr(line, log_type))
            statuses.get_logger().info(text)
    statuses.destroy_node()
'''}, twin='10 twin: record_hour records nothing'),
]

#: Lookup tables of the judge's old fixed inputs, beside their honest-wrong twins.  (A slow
#: flood, which the CPU limit of one check ends, is graded in the grader's sandbox:
#: tests/test_floods.py.)
ATTACKS += TABLES
