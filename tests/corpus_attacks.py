"""Learners who attack the judge, each beside its honest twin (the same notebook without the
attack): an attack must score what its twin scores.

The attacks reach for what the judge once believed: the subject's request loop (found by
walking up the stack from the learner's import, to rewrite its replies) and what the
subject reports about the learner's objects.
"""

from corpora import Learner

#: Module code that finds the subject's request loop from the learner's import, as the
#: attacks of 123efa2's sample class did, and answers every question with a right answer's
#: numbers.  The subject now loads the learner's code before the loop exists.
FORGE_REPLIES = '''
import sys as _sys
_frame = _sys._getframe()
while _frame is not None and 'handlers' not in _frame.f_locals:
    _frame = _frame.f_back
if _frame is not None:
    _handlers = _frame.f_locals['handlers']
    for _name in list(_handlers):
        _real = _handlers[_name]
        def _forged(*args, _real=_real, **kwargs):
            reply = _real(*args, **kwargs)
            reply.update(received=60, redraws=60, ok=True)
            return reply
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

ATTACKS = [
    Learner('07 twin: a callback that does nothing', '07', {'plot-callback': PLOT_DEAD},
            loses=('plot-callback',)),
    Learner('07 attack: the same, replies forged', '07', {'plot-callback': '''
    def temperature_callback(self, msg):
        return
''' + FORGE_REPLIES}, twin='07 twin: a callback that does nothing'),
    Learner('09 twin: every function returns the default profile', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'],
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            loses=('qos-newest-only', 'qos-sensor-subscription', 'qos-latched-thresholds')),
    Learner('09 attack: the same, replies forged', '09', {
        'qos-newest-only': DEFAULTS['newest_only_profile'] + FORGE_REPLIES,
        'qos-sensor-subscription': DEFAULTS['sensor_subscription_profile'],
        'qos-latched-thresholds': DEFAULTS['latched_thresholds_profile']},
            twin='09 twin: every function returns the default profile'),
    Learner('06 twin: a counting monitor that never counts', '06', {'counting-monitor': [(
        '        self.received += 1\n', '')]}, loses=('counting-monitor',)),
    Learner('06 attack: the same, replies forged', '06', {'counting-monitor': [(
        '        self.received += 1\n', ''),
        ("        self.get_logger().info(f'received {self.received}')\n        ### END SOLUTION",
         "        self.get_logger().info(f'received {self.received}')\n        ### END SOLUTION\n"
         + FORGE_REPLIES)]},
            twin='06 twin: a counting monitor that never counts'),
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
