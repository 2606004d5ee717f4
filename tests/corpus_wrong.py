"""Wrong learners: each wrong in behaviour in one part, and losing exactly that part.

Each is one notebook of :mod:`corpora`; ``loses`` names the part it gets wrong.
"""

from corpora import Learner

WRONG = [
    Learner('03 dead code: the timer under if False', '03', {'sensor-constructor': [(
        '        self.timer = self.create_timer(',
        '        if False:\n            self.timer = self.create_timer(')]},
        loses=('sensor-constructor',)),
    # A timer a little off the period: on a clock stepped once a period, 0.99 s fired as 1.0 s
    # does (6 of 6) and 1.02 s kept the constructor's points; each loses what a 2-s timer loses.
    *(Learner(f'03 a timer of {period} s', '03', {'sensor-constructor': [(
        'self.create_timer(PUBLISH_PERIOD_S,', f'self.create_timer({period},')]},
        loses=('sensor-constructor',)) for period in ('0.99', '1.02', '2.0')),
    Learner('03 a step of up to one degree', '03', {'sensor-callback': [(
        'random.uniform(-MAX_STEP_C, MAX_STEP_C)',
        'random.uniform(-2 * MAX_STEP_C, 2 * MAX_STEP_C)')]},
        loses=('sensor-callback', 'sensor-hour')),
    Learner('04 boundaries counted as High and Low', '04', {'monitor-callback': [
        ('temperature_c > HIGH_ABOVE_C', 'temperature_c >= HIGH_ABOVE_C'),
        ('temperature_c < LOW_BELOW_C', 'temperature_c <= LOW_BELOW_C')]},
        loses=('monitor-callback', 'monitor-readings')),
    Learner('07 the callback bumps redraws and never calls redraw()', '07', {'plot-callback': [(
        '        self.redraw()\n', '        self.redraws += 1\n')]},
        loses=('plot-callback',)),
    Learner('09 a best-effort subscription with a deadline', '09', {
        'qos-sensor-subscription': [(
            'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)',
            'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT, '
            'deadline=__import__("rclpy").duration.Duration(seconds=0.1))')]},
        loses=('qos-sensor-subscription',)),
    Learner('09 manual-by-topic liveliness', '09', {
        'qos-sensor-subscription': [(
            'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)',
            'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT, liveliness='
            '__import__("rclpy").qos.LivelinessPolicy.MANUAL_BY_TOPIC)')]},
        loses=('qos-sensor-subscription',)),
    Learner('09 latched with a 1 ms lifespan', '09', {
        'qos-latched-thresholds': [(
            'durability=DurabilityPolicy.TRANSIENT_LOCAL)',
            'durability=DurabilityPolicy.TRANSIENT_LOCAL, '
            'lifespan=__import__("rclpy").duration.Duration(nanoseconds=1_000_000))')]},
        loses=('qos-latched-thresholds',)),
    Learner('10 a replay of every topic', '10', {'replay': [(
        "ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])",
        'ros2nb.bag_play(bag_path, rate=rate)')]},
        loses=('replay',)),
    Learner('10 a replay that never stops the monitor', '10', {'replay': [(
        "ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])\n    ros2nb.stop()",
        "ros2nb.bag_play(bag_path, rate=rate, topics=['/temperature'])")]},
        loses=('replay',)),
]


def _qos(cell: str, old: str, new: str, name: str) -> Learner:
    """A 09 learner whose one profile differs from the solution's: ``old`` -> ``new``."""
    return Learner(name, '09', {cell: [(old, new)]}, loses=(cell,))


SENSOR_PROFILE = 'QoSProfile(depth=5, reliability=ReliabilityPolicy.BEST_EFFORT)'
NEWEST_PROFILE = 'QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1)'
LATCHED_DURABILITY = 'durability=DurabilityPolicy.TRANSIENT_LOCAL'

WRONG += [
    _qos('qos-newest-only', NEWEST_PROFILE, 'QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=2)',
         '09 newest only keeps two'),
    _qos('qos-newest-only', NEWEST_PROFILE, 'QoSProfile(history=HistoryPolicy.KEEP_ALL, depth=1)',
         '09 newest only keeps all'),
    # What a best-effort subscription keeps of a burst varies from run to run: the task's
    # "reliable" must fail it in every run, not in some.
    _qos('qos-newest-only', NEWEST_PROFILE,
         'QoSProfile(depth=1, reliability=ReliabilityPolicy.BEST_EFFORT)',
         '09 newest only, best effort'),
    _qos('qos-sensor-subscription', SENSOR_PROFILE,
         'QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE)',
         '09 a reliable subscription to a best-effort sensor'),
    _qos('qos-sensor-subscription', SENSOR_PROFILE,
         'QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)',
         '09 a sensor subscription that keeps ten'),
    _qos('qos-latched-thresholds', LATCHED_DURABILITY, 'durability=DurabilityPolicy.VOLATILE',
         '09 thresholds not latched'),
    _qos('qos-latched-thresholds', 'QoSProfile(depth=5, reliability=ReliabilityPolicy.RELIABLE',
         'QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE',
         '09 latched, but only the last setting'),
    Learner('06 room arguments without the leading slash', '06', {'room-arguments': [(
        "f'__ns:=/{room}'", "f'__ns:={room}'")]}, loses=('room-arguments',)),
    Learner('06 room arguments as a parameter', '06', {'room-arguments': [(
        "'-r', f'__ns:=/{room}'", "'-p', f'__ns:=/{room}'")]}, loses=('room-arguments',)),
    Learner('06 the fan turned on when it is cool', '06', {'fan-controller': [(
        'command.data = msg.data > HIGH_ABOVE_C', 'command.data = msg.data <= HIGH_ABOVE_C')]},
        loses=('fan-controller',)),
    Learner('06 every reading counted twice', '06', {'counting-monitor': [(
        'self.received += 1', 'self.received += 2')]}, loses=('counting-monitor',)),
    Learner('06 one mutually exclusive group for both timers', '06', {'responsive-worker': [(
        "node = Worker('responsive_worker', slow_group=MutuallyExclusiveCallbackGroup(),\n"
        "                  heartbeat_group=MutuallyExclusiveCallbackGroup())",
        "group = MutuallyExclusiveCallbackGroup()\n"
        "    node = Worker('responsive_worker', slow_group=group, heartbeat_group=group)")]},
        loses=('responsive-worker',)),
    Learner('06 a single-threaded executor for the worker', '06', {'responsive-worker': [(
        'executor = MultiThreadedExecutor(num_threads=2)',
        'executor = __import__("rclpy").executors.SingleThreadedExecutor()')]},
        loses=('responsive-worker',)),
    Learner('04 statuses shouted', '04', {'monitor-callback': [
        ("status = 'High'", "status = 'HIGH'"), ("status = 'Low'", "status = 'LOW'")]},
        loses=('monitor-callback', 'monitor-readings')),
    Learner('04 High and Low swapped', '04', {'monitor-callback': [
        ("status = 'High'", "status = 'Hot'"), ("status = 'Low'", "status = 'High'"),
        ("status = 'Hot'", "status = 'Low'")]},
        loses=('monitor-callback', 'monitor-readings')),
    Learner('03 no clamp', '03', {'sensor-callback': [(
        'max(MIN_TEMPERATURE_C,\n                               min(MAX_TEMPERATURE_C, '
        'self.temperature + step))', 'self.temperature + step')]},
        loses=('sensor-callback', 'sensor-hour')),
]

WRONG += [
    Learner('08 the on-set callback accepts every change', '08', {'threshold-callback': [(
        "        if low_c >= high_c:\n", "        if False:\n")]}, loses=('threshold-callback',)),
    Learner('08 refusals without a reason', '08', {'threshold-callback': [(
        "                reason=f'low_below_c ({low_c}) must stay below high_above_c ({high_c})')",
        "                reason='')")]}, loses=('threshold-callback',)),
    Learner('08 thresholds without a range', '08', {'monitor-parameters': [(
        ",\n            floating_point_range=in_clamp_range)", ')')]},
        loses=('monitor-parameters',)),
    Learner('08 thresholds declared as whole numbers', '08', {'monitor-parameters': [(
        "self.declare_parameter('high_above_c', HIGH_ABOVE_C,",
        "self.declare_parameter('high_above_c', int(HIGH_ABOVE_C),")]},
        loses=('monitor-parameters',)),
    Learner('07 times in milliseconds', '07', {'plot-callback': [(
        'self.get_clock().now().nanoseconds / 1e9', 'self.get_clock().now().nanoseconds / 1e6')]},
        loses=('plot-callback',)),
    Learner('04 main catches only KeyboardInterrupt', '04', {'monitor-main': [(
        'except (KeyboardInterrupt, ExternalShutdownException):', 'except KeyboardInterrupt:')]},
        loses=('monitor-main',)),
    Learner('04 readings logged with one decimal', '04', {'monitor-callback': [(
        "{temperature_c:.2f}C", "{temperature_c:.1f}C")]},
        loses=('monitor-callback', 'monitor-readings')),
    Learner('06 the fan publishes twice per reading', '06', {'fan-controller': [(
        '        self.publisher_.publish(command)\n',
        '        self.publisher_.publish(command)\n        self.publisher_.publish(command)\n')]},
        loses=('fan-controller',)),
]
