"""Wrong learners: each wrong in behaviour in one part, and losing exactly that part.

Each is one notebook of :mod:`corpora`; ``loses`` names the part it gets wrong.
"""

from corpora import Learner

WRONG = [
    Learner('03 dead code: the timer under if False', '03', {'sensor-constructor': [(
        '        self.timer = self.create_timer(',
        '        if False:\n            self.timer = self.create_timer(')]},
        loses=('sensor-constructor',)),
    Learner('03 a step of up to one degree', '03', {'sensor-callback': [(
        'random.uniform(-MAX_STEP_C, MAX_STEP_C)', 'random.uniform(-2 * MAX_STEP_C, 2 * MAX_STEP_C)')]},
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
]
