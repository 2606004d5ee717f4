"""Honest learners: the parts written in other valid styles, every one worth full marks.

Each is one notebook of :mod:`corpora`.  Styles ROS users write: the official tutorials'
(``timer_period`` locals), ros2/examples idioms (executors,
``spin_once`` loops), keyword arguments, lambdas, helpers, presets, a trailing slash.
"""

from corpora import Learner

SENSOR_KEYWORDS = '''
class TemperatureSensor(Node):
    """Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds."""

    def __init__(self):
        super().__init__(node_name='temperature_sensor')
        self.publisher_ = self.create_publisher(msg_type=Float32, topic=TOPIC,
                                                qos_profile=QUEUE_DEPTH)
        timer_period = PUBLISH_PERIOD_S  # seconds
        self.timer = self.create_timer(timer_period_sec=timer_period,
                                       callback=lambda: self.publish_temperature())
        self.temperature = START_TEMPERATURE_C
        self.get_logger().info('Temperature Sensor Node Started')
'''

SENSOR_HELPERS = '''    def publish_temperature(self):
        self.temperature = self._clamped(self.temperature + self._step())
        self.publisher_.publish(Float32(data=float(self.temperature)))
        self.get_logger().info('Publishing: %.2fC' % self.temperature)

    @staticmethod
    def _step():
        return (2 * random.random() - 1) * MAX_STEP_C

    @staticmethod
    def _clamped(value):
        return min(MAX_TEMPERATURE_C, max(MIN_TEMPERATURE_C, value))
'''

MAIN_SPIN_ONCE = '''
def main(args=None):
    rclpy.init(args=args)
    node = TemperatureSensor()
    try:
        while rclpy.ok():
            rclpy.spin_once(node, timeout_sec=0.1)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        _clean_up(node)


def _clean_up(node):
    node.destroy_node()
    rclpy.try_shutdown()


if __name__ == '__main__':
    main()
'''

MAIN_EXECUTOR = '''
def main(args=None):
    from rclpy.executors import SingleThreadedExecutor
    rclpy.init(args=args)
    node = TemperatureSensor()
    executor = SingleThreadedExecutor()
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == '__main__':
    main()
'''

MONITOR_LAMBDA = '''
class TemperatureMonitor(Node):
    """Logs every reading it receives with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        from rclpy.qos import QoSProfile
        self.subscription = self.create_subscription(
            msg_type=Float32, topic=TOPIC,
            callback=lambda msg: self.temperature_callback(msg),
            qos_profile=QoSProfile(depth=QUEUE_DEPTH))
        self.get_logger().info('Temperature Monitor Node Started')
'''

MONITOR_HELPER = '''    def temperature_callback(self, msg):
        reading = msg.data
        self.get_logger().info('Temperature: %.2fC - Status: %s' % (reading, self._status(reading)))

    @staticmethod
    def _status(reading):
        return 'High' if reading > HIGH_ABOVE_C else 'Low' if reading < LOW_BELOW_C else 'Normal'
'''

WORKER_TUPLE = '''
def responsive_worker():
    from rclpy.callback_groups import ReentrantCallbackGroup
    shared = ReentrantCallbackGroup()
    node, executor = Worker('responsive_worker', shared, shared), MultiThreadedExecutor(2)
    return node, executor
'''

HONEST = [
    Learner('03 keyword arguments, a lambda timer, helpers', '03',
            {'sensor-constructor': SENSOR_KEYWORDS, 'sensor-callback': SENSOR_HELPERS}),
    Learner('03 a timer of 1 (an int)', '03', {'sensor-constructor': [(
        'self.create_timer(PUBLISH_PERIOD_S,', 'self.create_timer(1,')]}),
    Learner('03 spin_once loop, cleanup in a helper called from finally', '03',
            {'sensor-main': MAIN_SPIN_ONCE}),
    Learner('03 an executor in main', '03', {'sensor-main': MAIN_EXECUTOR}),
    Learner('04 a lambda subscription, a QoSProfile, a status helper', '04',
            {'monitor-constructor': MONITOR_LAMBDA, 'monitor-callback': MONITOR_HELPER}),
    Learner('04 an executor in main', '04', {'monitor-main': MAIN_EXECUTOR.replace(
        'TemperatureSensor', 'TemperatureMonitor')}),
    Learner('05 setup.cfg with a trailing slash and spaces', '05', {'setup-cfg': '''
[develop]
script_dir = $base/lib/sensor_simulator/
[install]
install_scripts = $base/lib/sensor_simulator/
'''}),
    Learner('06 a worker made in one line, one reentrant group', '06',
            {'responsive-worker': WORKER_TUPLE}),
    Learner('06 room arguments spelt out', '06', {'room-arguments': '''
def room_arguments(room):
    return ['--ros-args', '--remap', '__ns:=/' + room]
'''}),
    Learner('07 the reading kept through a helper', '07', {'plot-callback': '''
    def temperature_callback(self, msg):
        self._keep(self.get_clock().now(), msg.data)

    def _keep(self, stamp, reading):
        self.times_s += [stamp.nanoseconds * 1e-9]
        self.temps_c += [reading]
        self.redraw()
'''}),
    Learner('09 presets and copies', '09', {
        'qos-newest-only': '''
def newest_only_profile():
    return QoSProfile(depth=1)
''',
        'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return qos_profile_sensor_data
''',
        'qos-latched-thresholds': '''
def latched_thresholds_profile():
    import copy
    profile = copy.copy(QoSProfile(depth=5))
    profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile
'''}),
    Learner('10 the bag read with rosbags.rosbag2', '10', {'read-temperatures': '''
def read_temperatures(bag_path):
    from rosbags.rosbag2 import Reader
    stamps, values = [], []
    with Reader(bag_path) as reader:
        for connection, stamp, raw in reader.messages():
            if connection.topic == '/temperature':
                stamps.append(stamp)
                values.append(TYPESTORE.deserialize_cdr(raw, connection.msgtype).data)
    return [(s - stamps[0]) / 1e9 for s in stamps], values
'''}),
]

# ---- more styles, one notebook each -------------------------------------------------------

SENSOR_TUTORIAL = '''    def publish_temperature(self):
        change = (random.random() - 0.5) * 2 * MAX_STEP_C
        self.temperature += change
        if self.temperature > MAX_TEMPERATURE_C:
            self.temperature = MAX_TEMPERATURE_C
        elif self.temperature < MIN_TEMPERATURE_C:
            self.temperature = MIN_TEMPERATURE_C
        msg = Float32()
        msg.data = float(self.temperature)
        self.publisher_.publish(msg)
        self.get_logger().info('Publishing: "%.2fC"' % msg.data)
'''
MONITOR_TUTORIAL = '''
class TemperatureMonitor(Node):
    """Logs every reading it receives with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        self.subscription = self.create_subscription(
            Float32,
            'temperature',
            self.temperature_callback,
            10)
        self.subscription  # prevent unused variable warning
        self.get_logger().info('Temperature Monitor Node Started')
'''
MONITOR_FORMAT = '''    def temperature_callback(self, msg):
        statuses = {True: 'High'}
        status = statuses.get(msg.data > HIGH_ABOVE_C) or ('Low' if msg.data < LOW_BELOW_C
                                                           else 'Normal')
        self.get_logger().info('Temperature: {:.2f}C - Status: {}'.format(msg.data, status))
'''
MAIN_SPIN_ONCE_MONITOR = MAIN_SPIN_ONCE.replace('TemperatureSensor', 'TemperatureMonitor')
FAN_KEYWORDS = '''
class FanController(Node):
    """Publishes one fan command for every reading it hears."""

    def __init__(self):
        super().__init__(node_name='fan_controller')
        self.publisher_ = self.create_publisher(msg_type=Bool, topic=FAN_TOPIC,
                                                qos_profile=QUEUE_DEPTH)
        self.subscription = self.create_subscription(
            msg_type=Float32, topic=TOPIC, callback=self.temperature_callback,
            qos_profile=QUEUE_DEPTH)
        self.get_logger().info('Fan Controller Node Started')

    def temperature_callback(self, msg):
        fan_on = bool(msg.data > HIGH_ABOVE_C)
        self.publisher_.publish(Bool(data=fan_on))
        self.get_logger().info('Fan %s at %.2fC' % ('on' if fan_on else 'off', msg.data))
'''
FAN_MAIN_EXECUTOR = MAIN_EXECUTOR.replace('TemperatureSensor', 'FanController')
COUNTER_LAMBDA = '''
class CountingMonitor(Node):
    """A monitor that only counts the readings it receives."""

    def __init__(self, name='counting_monitor'):
        super().__init__(name)
        self.received = 0
        self.subscription = self.create_subscription(Float32, TOPIC,
                                                     lambda msg: self.count(msg), QUEUE_DEPTH)

    def count(self, msg):
        self.received = self.received + 1
        self.get_logger().info('received %d' % self.received)
'''
WORKER_REENTRANT = '''
def responsive_worker():
    from rclpy.callback_groups import ReentrantCallbackGroup
    node = Worker('responsive_worker', ReentrantCallbackGroup(), ReentrantCallbackGroup())
    return node, MultiThreadedExecutor(num_threads=4)
'''
#: The Worker's slow work as a coroutine that awaits the call, on one thread (notebook 06's
#: third way).
WORKER_COROUTINE = '''
def responsive_worker():
    from rclpy.executors import SingleThreadedExecutor

    class WaitingWorker(Worker):
        async def slow_work(self):
            self.get_logger().info('slow work: start')
            await self.slow_client.call_async(Trigger.Request())
            self.get_logger().info('slow work: done')

    node = WaitingWorker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup(),
                         heartbeat_group=MutuallyExclusiveCallbackGroup())
    return node, SingleThreadedExecutor()
'''
WORKER_LAMBDA = '''
def responsive_worker():
    group = lambda: MutuallyExclusiveCallbackGroup()
    executor = MultiThreadedExecutor()
    return Worker(heartbeat_group=group(), name='responsive_worker', slow_group=group()), executor
'''
QOS_SPELT_OUT = {
    'qos-newest-only': '''
def newest_only_profile():
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.VOLATILE)
''',
    'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=5,
                      reliability=ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.VOLATILE)
''',
    'qos-latched-thresholds': '''
def latched_thresholds_profile():
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=5,
                      reliability=ReliabilityPolicy.RELIABLE,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)
'''}
QOS_CHANGED_AFTER = {
    'qos-newest-only': '''
def newest_only_profile():
    profile = QoSProfile(depth=10)
    profile.depth = 1
    return profile
''',
    'qos-sensor-subscription': '''
def sensor_subscription_profile():
    profile = QoSProfile(depth=5)
    profile.reliability = ReliabilityPolicy.BEST_EFFORT
    return profile
''',
    'qos-latched-thresholds': '''
def latched_thresholds_profile():
    profile = QoSProfile(depth=5)
    profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
    return profile
'''}
QOS_MODULE = {
    'qos-newest-only': '''
import rclpy.qos as qos


def newest_only_profile():
    return qos.QoSProfile(history=qos.QoSHistoryPolicy.KEEP_LAST, depth=1)
''',
    'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return _profile(5, reliability=qos.QoSReliabilityPolicy.BEST_EFFORT)


def _profile(depth, **policies):
    return qos.QoSProfile(depth=depth, **policies)
''',
    'qos-latched-thresholds': '''
def latched_thresholds_profile():
    return _profile(5, durability=qos.QoSDurabilityPolicy.TRANSIENT_LOCAL)
'''}

HONEST += [
    Learner("03 the official tutorial's style: if/elif clamp, %-formatting", '03',
            {'sensor-callback': SENSOR_TUTORIAL}),
    Learner("04 the official tutorial's style: literal topic and depth", '04',
            {'monitor-constructor': MONITOR_TUTORIAL}),
    Learner('04 a status table and str.format', '04', {'monitor-callback': MONITOR_FORMAT}),
    Learner('04 a spin_once loop in main', '04', {'monitor-main': MAIN_SPIN_ONCE_MONITOR}),
    Learner('06 keyword arguments and a Bool made in one call', '06',
            {'fan-controller': FAN_KEYWORDS}),
    Learner('06 an executor in the fan main', '06', {'fan-main': FAN_MAIN_EXECUTOR}),
    Learner('06 a lambda subscription that counts', '06', {'counting-monitor': COUNTER_LAMBDA}),
    Learner('06 two reentrant groups, four threads', '06', {'responsive-worker': WORKER_REENTRANT}),
    Learner('06 groups from a lambda, keyword arguments, the default thread count', '06',
            {'responsive-worker': WORKER_LAMBDA}),
    Learner('06 the slow work a coroutine of its own, on one thread', '06',
            {'responsive-worker': WORKER_COROUTINE}),
    Learner('06 room arguments from one string', '06', {'room-arguments': '''
def room_arguments(room):
    return '--ros-args --remap __ns:=/{}'.format(room).split()
'''}),
    Learner('09 every policy spelt out', '09', QOS_SPELT_OUT),
    Learner('09 profiles changed after they are made', '09', QOS_CHANGED_AFTER),
    Learner('09 rclpy.qos as a module, a helper', '09', QOS_MODULE),
]


# ---- presets, declare_parameters, more helpers ----------------------------------------------
# (ros2/examples' ``with rclpy.init(args=args):`` is not here: Jazzy's rclpy.init returns None.)

THRESHOLDS_PLURAL = '''
def _threshold(description):
    return ParameterDescriptor(description=description + ' (°C)', floating_point_range=[
        FloatingPointRange(from_value=MIN_THRESHOLD_C, to_value=MAX_THRESHOLD_C, step=0.0)])


class TemperatureMonitor(Node):
    """Logs every reading with its status; the thresholds are parameters."""

    def __init__(self):
        super().__init__('temperature_monitor')
        self.declare_parameters(namespace='', parameters=[
            ('high_above_c', HIGH_ABOVE_C, _threshold('Readings strictly above this are High')),
            ('low_below_c', LOW_BELOW_C, _threshold('Readings strictly below this are Low')),
        ])
        self.add_on_set_parameters_callback(self.on_set_thresholds)
        self.subscription = self.create_subscription(
            Float32, TOPIC, self.temperature_callback, QUEUE_DEPTH)
        self.get_logger().info(
            'Temperature Monitor Node Started: '
            f"Low below {self.get_parameter('low_below_c').value:.2f}C, "
            f"High above {self.get_parameter('high_above_c').value:.2f}C")
'''
ON_SET_LOOP = '''    def on_set_thresholds(self, parameters):
        high_c = self.get_parameter('high_above_c').value
        low_c = self.get_parameter('low_below_c').value
        for parameter in parameters:
            if parameter.name == 'high_above_c':
                high_c = parameter.value
            elif parameter.name == 'low_below_c':
                low_c = parameter.value
        result = SetParametersResult()
        result.successful = low_c < high_c
        if not result.successful:
            result.reason = 'low_below_c must stay below high_above_c'
        return result

    def temperature_callback(self, msg):
        high_c = self.get_parameter('high_above_c').value
        low_c = self.get_parameter('low_below_c').value
        temperature_c = msg.data
        if temperature_c > high_c:
            status = 'High'
        elif temperature_c < low_c:
            status = 'Low'
        else:
            status = 'Normal'
        self.get_logger().info(f'Temperature: {temperature_c:.2f}C - Status: {status}')
'''
QOS_PRESETS = {
    'qos-newest-only': '''
from rclpy.qos import QoSPresetProfiles


def newest_only_profile():
    return QoSProfile(history=1, depth=1)  # 1: KEEP_LAST, as rclpy numbers it
''',
    'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return QoSPresetProfiles.SENSOR_DATA.value
''',
    'qos-latched-thresholds': '''
def latched_thresholds_profile():
    services = QoSPresetProfiles.SERVICES_DEFAULT.value  # reliable, volatile, depth 10
    return QoSProfile(history=services.history, depth=5, reliability=services.reliability,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL)
'''}

HONEST += [
    Learner('07 the time from seconds_nanoseconds()', '07', {'plot-callback': '''
    def temperature_callback(self, msg):
        seconds, nanoseconds = self.get_clock().now().seconds_nanoseconds()
        self.times_s.extend([seconds + nanoseconds / 1e9])
        self.temps_c.extend([msg.data])
        self.redraw()
'''}),
    Learner('08 declare_parameters and a descriptor helper', '08',
            {'monitor-parameters': THRESHOLDS_PLURAL}),
    Learner('08 the on-set callback walks the parameters', '08',
            {'threshold-callback': ON_SET_LOOP}),
    Learner('09 preset profiles and a number for KEEP_LAST', '09', QOS_PRESETS),
]


# ---- one more of each, in other words ---------------------------------------------------

MONITOR_STATUS_METHOD = '''    def temperature_callback(self, msg):
        self.get_logger().info('Temperature: ' + format(msg.data, '.2f') + 'C - Status: '
                               + self.status(msg.data))

    def status(self, reading):
        if reading > HIGH_ABOVE_C:
            return 'High'
        if reading < LOW_BELOW_C:
            return 'Low'
        return 'Normal'
'''
MONITOR_HISTORY = '''
class TemperatureMonitor(Node):
    """Logs every reading it receives with its status."""

    def __init__(self):
        super().__init__('temperature_monitor')
        from rclpy.qos import HistoryPolicy, QoSProfile
        keep_last = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=QUEUE_DEPTH)
        self.subscription = self.create_subscription(Float32, TOPIC, self.temperature_callback,
                                                     keep_last)
        self.get_logger().info('Temperature Monitor Node Started')
'''
ON_SET_DICT = '''    def on_set_thresholds(self, parameters):
        current = {name: self.get_parameter(name).value for name in ('high_above_c', 'low_below_c')}
        current.update({parameter.name: parameter.value for parameter in parameters})
        ok = current['low_below_c'] < current['high_above_c']
        return SetParametersResult(successful=ok,
                                   reason='' if ok else 'low_below_c must stay below high_above_c')

    def temperature_callback(self, msg):
        high_c = self.get_parameter('high_above_c').value
        low_c = self.get_parameter('low_below_c').value
        status = 'High' if msg.data > high_c else 'Low' if msg.data < low_c else 'Normal'
        self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
'''

HONEST += [
    Learner('03 the clamp as the middle of three', '03', {'sensor-callback': [(
        '        self.temperature = max(MIN_TEMPERATURE_C,\n'
        '                               min(MAX_TEMPERATURE_C, self.temperature + step))',
        '        self.temperature = sorted([MIN_TEMPERATURE_C, self.temperature + step,\n'
        '                                   MAX_TEMPERATURE_C])[1]')]}),
    Learner('04 a status method with early returns, the line joined with +', '04',
            {'monitor-callback': MONITOR_STATUS_METHOD}),
    Learner('04 a KEEP_LAST profile for the subscription', '04',
            {'monitor-constructor': MONITOR_HISTORY}),
    Learner('05 entry points without spaces', '05', {'entry-points': [
        ("'temperature_publisher = sensor_simulator.temperature_publisher:main'",
         "'temperature_publisher=sensor_simulator.temperature_publisher:main'"),
        ("'temperature_subscriber = sensor_simulator.temperature_subscriber:main'",
         "'temperature_subscriber=sensor_simulator.temperature_subscriber:main'")]}),
    Learner('06 a fan command from a conditional expression', '06', {'fan-controller': [(
        '        command = Bool()\n        command.data = msg.data > HIGH_ABOVE_C\n',
        '        command = Bool(data=True if msg.data > HIGH_ABOVE_C else False)\n')]}),
    Learner('06 a slash added only when the room has none', '06', {'room-arguments': '''
def room_arguments(room):
    namespace = room if room.startswith('/') else '/' + room
    return ['--ros-args', '--remap', f'__ns:={namespace}']
'''}),
    Learner('06 the count logged with %d', '06', {'counting-monitor': [(
        "self.get_logger().info(f'received {self.received}')",
        "self.get_logger().info('received %d' % self.received)")]}),
    Learner('07 the time as a float of the clock, the reading as float()', '07',
            {'plot-callback': '''
    def temperature_callback(self, msg):
        now = self.get_clock().now()
        self.times_s.append(now.nanoseconds * 1e-9)
        self.temps_c.append(float(msg.data))
        self.redraw()
'''}),
    Learner('08 the on-set callback with a dict of current values', '08',
            {'threshold-callback': ON_SET_DICT}),
    Learner("09 policies as rclpy's numbers", '09', {
        'qos-newest-only': '''
def newest_only_profile():
    return QoSProfile(depth=1)  # KEEP_LAST is the default
''',
        'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return QoSProfile(depth=5, reliability=2)  # 2: BEST_EFFORT
''',
        'qos-latched-thresholds': '''
def latched_thresholds_profile():
    return QoSProfile(depth=5, durability=1)  # 1: TRANSIENT_LOCAL
'''}),
    Learner('09 one factory for the three profiles', '09', {
        'qos-newest-only': '''
def _profile(depth, reliable=True, latched=False):
    return QoSProfile(
        depth=depth,
        reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
        durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE)


def newest_only_profile():
    return _profile(1)
''',
        'qos-sensor-subscription': '''
def sensor_subscription_profile():
    return _profile(5, reliable=False)
''',
        'qos-latched-thresholds': '''
def latched_thresholds_profile():
    return _profile(5, latched=True)
'''}),
]

HONEST += [
    Learner('04 the status from a match statement', '04', {'monitor-callback': '''
    def temperature_callback(self, msg):
        match msg.data:
            case reading if reading > HIGH_ABOVE_C:
                status = 'High'
            case reading if reading < LOW_BELOW_C:
                status = 'Low'
            case _:
                status = 'Normal'
        self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
'''}),
    Learner('09 settings kept in dictionaries', '09', {
        'qos-newest-only': '''
NEWEST = {'history': HistoryPolicy.KEEP_LAST, 'depth': 1}


def newest_only_profile():
    return QoSProfile(**NEWEST)
''',
        'qos-sensor-subscription': '''
SENSOR = {'depth': 5, 'reliability': ReliabilityPolicy.BEST_EFFORT}


def sensor_subscription_profile():
    return QoSProfile(**SENSOR)
''',
        'qos-latched-thresholds': '''
LATCHED = {'depth': 5, 'durability': DurabilityPolicy.TRANSIENT_LOCAL}


def latched_thresholds_profile():
    return QoSProfile(**LATCHED)
'''}),
]
