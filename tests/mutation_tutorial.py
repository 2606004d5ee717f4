"""The tutorial's own mistakes, as answers a learner copying it would write.

The course mirrors one tutorial (``/work/shared/seeds/``) and fixes its mistakes
(``docs/tutorial-fixes.md``): the misspelt ``TemperaturSensor``, the 10.2 °C floor, a
``main()`` that calls ``rclpy.shutdown()`` after Ctrl+C or never cleans up, the path without
``~`` (its setup.py without setup.cfg is 05's own demonstration; setup.cfg's keys as the
older template dashed them are 05's mutants in ``mutation_operators``).  Each entry of
:data:`TUTORIAL` writes the learner's lines of one answer cell the tutorial's way (our own
wording of its code, with its literal values), or renames what the tutorial misspelt, found
with :mod:`tokenize`.  Some are equivalent on purpose (the tutorial's literals for the
course's constants): honest code in its style must pass.
"""

from __future__ import annotations

import io
import tokenize
from typing import Callable

from mutation_cells import Answer


def region_written(lines: str, region: int = 0) -> Callable[[Answer], str]:
    """The answer with the learner's lines of its ``region``-th region replaced by ``lines``
    (indented as written here)."""
    def text(answer: Answer) -> str:
        old = answer.source.split('\n')
        begin, end = answer.regions[region]
        return '\n'.join(old[:begin] + lines.strip('\n').split('\n') + old[end:])
    return text


def renamed(old: str, new: str, after: str) -> Callable[[Answer], str]:
    """The answer with the name ``old`` that follows the word ``after`` (``class``, ``=``)
    spelt ``new``, where tokenize finds it."""
    def text(answer: Answer) -> str:
        lines = answer.source.split('\n')
        start = 1 if answer.is_part else 0
        code = '\n'.join(lines[start:])
        previous = None
        for token in tokenize.generate_tokens(io.StringIO(code).readline):
            if token.type == tokenize.NAME and token.string == old and previous == after:
                row, col = token.start[0] - 1 + start, token.start[1]
                lines[row] = lines[row][:col] + new + lines[row][col + len(old):]
                return '\n'.join(lines)
            if token.type not in (tokenize.NL, tokenize.NEWLINE, tokenize.INDENT,
                                  tokenize.DEDENT, tokenize.COMMENT):
                previous = token.string
        raise LookupError(f'{old} after {after!r} is not in {answer.key}')
    return text


TUTORIAL_MAIN_SENSOR = '''
    rclpy.init(args=args)
    node = TemperaturSensor()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass
    node.destroy_node()
    rclpy.shutdown()
'''

#: (answer key, the mistake, the learner's cell as the tutorial would have it)
TUTORIAL: list[tuple[str, str, Callable[[Answer], str]]] = [
    ('01-create-a-workspace-challenge-1', "the tutorial's /Documents without ~",
     region_written("    return Path('/Documents/ROS2_and_RL_Tutorials')")),
    ('03-sensor-constructor', 'class TemperaturSensor, as the tutorial spells it',
     renamed('TemperatureSensor', 'TemperaturSensor', 'class')),
    ('03-sensor-constructor', "the tutorial's literals for the constants (equivalent)",
     region_written('''
        # a publisher on "temperature"
        self.publisher_ = self.create_publisher(Float32,'temperature',10)
        # a reading every second
        self.timer = self.create_timer(1.0,self.publish_temperature)
        self.temperature = 22.0
        self .get_logger().info("Temperature Sensor Node Started")''')),
    ('03-sensor-callback', "the tutorial's callback, its floor of 10.2 °C",
     region_written('''
        self.temperature += random.uniform(-0.5,0.5)
        self.temperature = max(10.2,min(28.0,self.temperature))
        msg = Float32()
        msg.data = self.temperature
        self.publisher_.publish(msg)
        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')''')),
    ('03-sensor-callback', "the tutorial's callback with 18.0 for its floor (equivalent)",
     region_written('''
        self.temperature += random.uniform(-0.5,0.5)
        self.temperature = max(18.0,min(28.0,self.temperature))
        msg = Float32()
        msg.data = self.temperature
        self.publisher_.publish(msg)
        self.get_logger().info(f'Publishing: {self.temperature:.2f}C')''')),
    ('03-sensor-main', "the tutorial's main(): TemperaturSensor(), rclpy.shutdown()",
     region_written(TUTORIAL_MAIN_SENSOR)),
    ('03-sensor-main', "the tutorial's main() with the class spelt right",
     region_written(TUTORIAL_MAIN_SENSOR.replace('TemperaturSensor', 'TemperatureSensor'))),
    ('04-monitor-constructor', "the tutorial's literals for the constants (equivalent)",
     region_written('''
        self .subscription = self.create_subscription(
            Float32,
            'temperature',
            self.temperature_callback,
            10
        )
        self.get_logger().info('Temperature Monitor Node Started')''')),
    ('04-monitor-callback', "the tutorial's callback: 'Status:{status}' without a space",
     region_written('''
        temp = msg.data
        if temp > 26.0:
            status = "High"
        elif temp < 20.0:
            status = "Low"
        else:
            status= "Normal"
        self.get_logger().info(f'Temperature: {temp:.2f}C - Status:{status}')''')),
    ('04-monitor-main', "the tutorial's main(): never destroys the node nor shuts down",
     region_written('''
    rclpy.init(args=args)
    node = TemperatureMonitor()
    try:
        rclpy.spin(node)
    except KeyboardInterrupt:
        pass''')),
]
