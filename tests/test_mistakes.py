"""Beginner mistakes in a real Jupyter kernel: each gets one line naming the learner's
line and the fix.

Every case is a cell a learner could write. The kernel is a real IPython kernel with
ros2nb started as the notebooks start it; the test reads what the learner would see (the
error output's traceback lines, streams). docs/troubleshooting.md lists the same mistakes.
"""

import re

import pytest

from kernels import Kernel

pytestmark = [pytest.mark.kernel, pytest.mark.timeout(300)]


@pytest.fixture(scope='module')
def kernel(tmp_path_factory):
    kernel = Kernel(str(tmp_path_factory.mktemp('mistakes') / 'ws'))
    kernel.run('%load_ext ros2nb\nimport ros2nb, rclpy\nfrom rclpy.node import Node\n'
               'from std_msgs.msg import Float32, Float64, String')
    yield kernel
    kernel.close()


@pytest.fixture
def ros(kernel):
    kernel.run('_ = ros2nb.start(sim_time=True)')
    yield kernel
    kernel.run('ros2nb.shutdown()')


def test_node_before_start(kernel):
    kernel.run('ros2nb.shutdown()')
    kernel.one_line("node = Node('early')",
                    'ROS 2 is not up in this kernel yet: run ros2nb.start() first',
                    "cell line 1: node = Node('early')")


def test_rclpy_init_after_start(ros):
    ros.one_line('rclpy.init()', 'ros2nb.start() already brought ROS 2 up in this kernel: remove '
                                 'that call', 'cell line 1: rclpy.init()')


def test_main_run_in_the_notebook(ros):
    ros.run('def main(args=None):\n    rclpy.init(args=args)\n    node = Node("x")\n'
            '    rclpy.spin(node)\n')
    ros.one_line('main()', 'main() is for `ros2 run`', 'cell line 2:')


def test_rclpy_spin_in_a_cell(ros):
    ros.one_line("rclpy.spin(Node('spinner'))", 'rclpy.spin(node) never returns in a notebook cell',
                 'ros2nb.add(node)')


def test_continuing_after_rclpy_shutdown_and_the_way_back(kernel):
    kernel.run('_ = ros2nb.start(sim_time=True)')
    kernel.run('rclpy.shutdown()')
    kernel.one_line("Node('after')", 'ROS 2 was shut down in this kernel',
                    'run ros2nb.shutdown(); ros2nb.start()')
    back = kernel.run('ros2nb.shutdown(); _ = ros2nb.start(sim_time=True); '
                      "n = ros2nb.add(Node('after'))")
    assert back.error is None, back
    kernel.run('ros2nb.shutdown()')


@pytest.mark.parametrize('value, fragment', [
    ('22', "Float32's field 'data' takes 22.0 or float(...), not int 22"),
    ("'hot'", "Float32's field 'data' takes a decimal number such as 22.0, not str 'hot'"),
])
def test_wrong_value_in_a_message(ros, value, fragment):
    ros.one_line(f'msg = Float32()\nmsg.data = {value}', fragment,
                 f'cell line 2: msg.data = {value}')


def test_node_without_super_init(ros):
    ros.one_line("class Sensor(Node):\n    def __init__(self):\n"
                 "        self.pub = self.create_publisher(Float32, 'temperature', 10)\n\n"
                 'Sensor()', "Sensor.__init__ never calls super().__init__('node_name')",
                 "cell line 3: self.pub = self.create_publisher")


def test_message_instance_instead_of_type(ros):
    ros.one_line("class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n"
                 "        self.pub = self.create_publisher(Float32(), 'temperature', 10)\n\n"
                 'ros2nb.add(Sensor())', 'with a message Float32() instead of the message type: '
                                        'pass Float32 without the parentheses')


def test_float32_publisher_and_float64_subscription_in_one_kernel(ros):
    ros.run("class Sensor(Node):\n    def __init__(self):\n        super().__init__('sensor')\n"
            "        self.pub = self.create_publisher(Float32, 'temperature', 10)\n\n"
            'sensor = ros2nb.add(Sensor())')
    result = ros.run("class Monitor(Node):\n    def __init__(self):\n"
                     "        super().__init__('monitor')\n"
                     "        self.create_subscription(Float64, 'temperature', print, 10)\n\n"
                     'Monitor()')
    shown = result.error[1]
    assert shown == ['Ros2nbError: monitor would subscribe to /temperature as '
                     'std_msgs/msg/Float64, but /temperature already carries std_msgs/msg/Float32 '
                     'in this kernel: both sides of a topic must use the same message type.']
    assert 'invalid allocator' not in result.stderr + result.stdout  # no C error dump


def test_node_handed_to_nobody(ros):
    ros.run("class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n"
            "        self.create_timer(1.0, lambda: self.get_logger().info('tick'))\n\nSensor()")
    assert ros.run('_ = ros2nb.spin(5)').stdout == (
        'No nodes are running in this kernel: hand yours over with ros2nb.add(node), then spin.\n')


def test_class_instead_of_node(ros):
    ros.one_line("class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n\n"
                 'ros2nb.add(Sensor)', 'ros2nb.add() takes a node, not the class Sensor: create '
                                       'one first, ros2nb.add(Sensor()).')


@pytest.mark.parametrize('timer, fragment', [
    ('self.create_timer(1.0, self.tick())', "timer whose callback is None, not a function: pass "
                                            'the method itself'),
    ('self.create_timer(0, self.tick)', 'a timer with a period of 0 s for '),
])
def test_timer_mistakes(ros, timer, fragment):
    ros.one_line(f"class Ticker(Node):\n    def __init__(self):\n        super().__init__('t')\n"
                 f"        {timer}\n\n    def tick(self):\n        pass\n\nros2nb.add(Ticker())",
                 fragment)


def test_publishing_a_bare_value(ros):
    ros.run("class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n"
            "        self.pub = self.create_publisher(Float32, 'temperature', 10)\n"
            "        self.create_timer(1.0, lambda: self.pub.publish(22.5))\n\n"
            's = ros2nb.add(Sensor())')
    stderr = ros.run('_ = ros2nb.spin(2)').stderr
    assert 'publish() takes a Float32 message, not a bare value (float)' in stderr
    assert stderr.count('[ERROR] [s]') == 1  # reported once; the node is stopped


@pytest.mark.parametrize('published, fragments', [
    ('True', ('takes a Bool message, not a bare value (bool)', 'msg = Bool()')),
    # what the old advice (msg = Float32()) led to: told apart, never the same line again
    ('Float32(data=1.0)', ('created for Bool messages and was handed a Float32',
                           'create a Bool (msg = Bool())')),
])
def test_the_fan_publishing_what_its_bool_publisher_refuses(ros, published, fragments):
    """The advice names the publisher's own type (06's fan publishes Bool)."""
    ros.run('from std_msgs.msg import Bool\n'
            "fan = Node('fan_one')\nfan_pub = fan.create_publisher(Bool, 'fan_on', 10)")
    ros.one_line(f'fan_pub.publish({published})', *fragments)


def test_executor_spin_in_a_cell(ros):
    """06's executor spun in a cell: one line at once, not a hang until Stop."""
    ros.run('from rclpy.executors import MultiThreadedExecutor\n'
            "ex = MultiThreadedExecutor(num_threads=2)\nex.add_node(Node('worker_one'))")
    ros.one_line('ex.spin()', 'executor.spin() never returns in a notebook cell',
                 'ros2nb.add(node)', 'ros2nb.timer_runs(node, executor, seconds)')


def test_spin_until_future_complete_without_a_timeout(ros):
    ros.run('import rclpy.task\nfuture = rclpy.task.Future()\n'
            "waiter = Node('waiter_one')")
    ros.one_line('rclpy.spin_until_future_complete(waiter, future)',
                 'without timeout_sec blocks the cell', 'timeout_sec=5.0')
    done = ros.run('rclpy.spin_until_future_complete(waiter, future, timeout_sec=0.1)\n'
                   'print(future.done())')
    assert done.error is None and done.stdout.strip() == 'False', done  # a limit: runs


def test_a_part_before_its_file_name_was_set(kernel):
    kernel.run('%load_ext ros2nb')
    kernel.one_line('%%part {NOT_SET_YET} 1\nx = 1\n', 'NOT_SET_YET is not defined in this '
                                                      'kernel: run the cell near the top')


def test_stop_during_a_simulated_spin_is_one_line(ros):
    # Ctrl+C from inside the spin (the node's first tick sends it), so that it lands while
    # the spin runs however busy the machine is, as the Stop button pressed mid-spin does.
    ros.run("import os, signal\n"
            "class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n"
            "        self.pressed = False\n"
            "        self.create_timer(1.0, self.press_stop_once)\n\n"
            "    def press_stop_once(self):\n        if not self.pressed:\n"
            "            self.pressed = True\n            os.kill(os.getpid(), signal.SIGINT)\n\n"
            "sensor = ros2nb.add(Sensor())")
    result = ros.run('_ = ros2nb.spin(10 ** 7)')
    assert result.error is None
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('Interrupted after '), result


def test_stop_during_a_wall_clock_spin_is_the_cells_last_line(kernel):
    # On the wall clock the nodes keep running after a spin, and this cell goes on for half a
    # second after it: before, their lines of that half second came after "Interrupted ...".
    # The node presses Stop itself, at its first tick while the cell's spin runs (it looks at
    # the kernel's main thread), so that the press lands mid-spin however busy the machine is.
    kernel.run('ros2nb.shutdown()\n_ = ros2nb.start(sim_time=False)')
    try:
        kernel.run("import os, signal, sys, threading\n"
                   "def spin_is_running():\n"
                   "    frame = sys._current_frames().get(threading.main_thread().ident)\n"
                   "    while frame is not None:\n"
                   "        if frame.f_code.co_name == '_run_on_the_wall_clock':\n"
                   "            return True\n"
                   "        frame = frame.f_back\n"
                   "    return False\n\n"
                   "class Ticker(Node):\n    def __init__(self):\n"
                   "        super().__init__('wall')\n"
                   "        self.ticks, self.pressed = 0, False\n"
                   "        self.create_timer(0.01, self.tick)\n\n"
                   "    def tick(self):\n        self.ticks += 1\n"
                   "        self.get_logger().info('tick')\n"
                   "        if not self.pressed and spin_is_running():\n"
                   "            self.pressed = True\n"
                   "            os.kill(os.getpid(), signal.SIGINT)\n\n"
                   "ticker = ros2nb.add(Ticker())")
        result = kernel.run('_ = ros2nb.spin(10 ** 7)\nimport time\nticks = ticker.ticks\n'
                            'time.sleep(0.5)')
        lines = result.stdout.strip().splitlines()
        assert result.error is None and lines[-1].startswith('Interrupted after '), result
        assert lines[-1].endswith(' s; the nodes keep running (ros2nb.stop() stops them).'), lines
        shown = [line for line in lines[:-1]  # the lines shown before it: ticks of this cell,
                 if not re.fullmatch(r'\(\d+ log lines made while no cell was running '
                                     r'were not shown\)', line)]  # and a count of earlier ones
        assert set(shown) <= {'[INFO] [wall]: tick'}, lines
        ran_on = kernel.run("print(f'ran on: {ticker.ticks - ticks}')").stdout
        assert int(re.search(r'ran on: (\d+)', ran_on).group(1)) > 0, ran_on  # the node ran on
    finally:
        kernel.run('ros2nb.shutdown()')


def test_a_check_that_fails_is_one_line(ros):
    result = ros.run('import ros2nb.checks\n'
                     'ros2nb.checks.check_expanded_path(lambda: "/Documents/W", ends_with="W")')
    assert result.error[1] == [
        "CheckFailed: <lambda>() returned str '/Documents/W'; return a pathlib.Path."]


# ---------------------------------------------------------------- rclpy's own exceptions
SENSOR_WITH = ("class Sensor(Node):\n    def __init__(self):\n        super().__init__('s')\n"
               "        {line}\n\n    def tick(self):\n        pass\n\nSensor()")


@pytest.mark.parametrize('line, fragments', [
    ("self.create_publisher(Float32, 'temp-erature', 10)",
     ("'temp-erature' is not a valid ROS topic name", "write it as 'temp_erature'")),
    ('self.create_timer(-1.0, self.tick)',
     ('create_timer got a negative period: give the period in seconds as a positive number',)),
    ("self.create_publisher(Float32, 'temperature')",
     ('create_publisher() was called without the queue depth: create_publisher takes the '
      'message type, the topic and the queue depth, in that order.',)),
    ("self.create_publisher(Float32, 'temperature', -1)",
     ('the queue depth must be 0 or more (10 is usual)',)),
    ("self.create_publisher(Float32, 'temperature', qos_profile=10, depth=10)",
     ('create_publisher() takes no argument depth: create_publisher takes the message type, '
      'the topic and the queue depth',)),
    ("self.create_publisher(Float32, 'temperature', rclpy.qos.QoSProfile())",
     ('a QoSProfile needs its history depth: QoSProfile(depth=10)',)),
])
def test_rclpy_refuses_an_argument_in_one_line_at_the_learners_line(ros, line, fragments):
    ros.one_line(SENSOR_WITH.format(line=line), *fragments, f'cell line 4: {line}')


def test_a_node_name_with_a_space(ros):
    ros.one_line("sensor = Node('temp sensor')",
                 "'temp sensor' is not a valid ROS node name: node name must not contain "
                 "characters other than alphanumerics or '_'; write it as 'temp_sensor'",
                 "cell line 1: sensor = Node('temp sensor')")


def test_a_subscription_callback_without_the_message(ros):
    ros.one_line("class Monitor(Node):\n    def __init__(self):\n        super().__init__('m')\n"
                 "        self.create_subscription(Float32, 'reading', self.on_reading, 10)\n\n"
                 "    def on_reading(self):\n        pass\n\nMonitor()",
                 "the subscription's callback Monitor.on_reading() must take the message ROS hands "
                 'it: define it as def on_reading(self, msg)',
                 "cell line 4: self.create_subscription(Float32, 'reading', self.on_reading, 10)")


def test_a_timer_callback_that_asks_for_a_message(ros):
    ros.run("class Ticker(Node):\n    def __init__(self):\n        super().__init__('t')\n"
            "        self.create_timer(1.0, self.tick)\n\n"
            "    def tick(self, msg):\n        pass\n\nticker = ros2nb.add(Ticker())")
    stderr = ros.run('_ = ros2nb.spin(2)').stderr
    assert ('callback Ticker.tick raised ROS calls Ticker.tick() with no '
            'arguments (a timer callback): define it as def tick(self) and keep '
            'what it needs on self.') in stderr, stderr
    assert 'cell line 6: def tick(self, msg):' in stderr, stderr
    assert 'Traceback' not in stderr


# ---------------------------------------------------------------- silent cases speak
def test_a_misspelt_topic_in_a_subscription_is_named_after_the_spin(ros):
    ros.run("class Sensor(Node):\n    def __init__(self):\n        super().__init__('sensor')\n"
            "        self.pub = self.create_publisher(Float32, 'temperature', 10)\n\n"
            'sensor = ros2nb.add(Sensor())')
    ros.run("class Monitor(Node):\n    def __init__(self):\n        super().__init__('monitor')\n"
            "        self.create_subscription(Float32, 'temprature', print, 10)\n\n"
            'monitor = ros2nb.add(Monitor())')
    out = ros.run('_ = ros2nb.spin(2)').stdout
    assert ('monitor subscribes to /temprature, which has no publisher, but /temperature has one: '
            'check the topic name in create_subscription.') in out, out


# ---------------------------------------------------------------- misleading messages fixed
def test_plain_rclpy_spin_without_ros2nb_start_says_what_to_use(kernel):
    kernel.run('ros2nb.shutdown()')
    line = kernel.one_line("rclpy.init()\nnode = Node('plain')\nrclpy.spin(node)",
                           'rclpy.spin(node) never returns in a notebook cell (it would '
                           'block the kernel until you press Stop): run ros2nb.start() '
                           'instead of rclpy.init()')
    assert line.startswith('Ros2nbError: ')
    kernel.run('node.destroy_node(); rclpy.try_shutdown()')


def test_the_deliberate_mkdir_error_of_01_is_one_line(kernel, tmp_path):
    kernel.run(f'from pathlib import Path\nws = Path({str(tmp_path)!r})')
    kernel.one_line('ws.mkdir()',
                    f'{tmp_path} already exists, and mkdir() without exist_ok refuses',
                    'mkdir(parents=True, exist_ok=True) is mkdir -p', 'cell line 1: ws.mkdir()')


def test_a_part_not_written_yet_says_so_in_one_line(kernel, tmp_path):
    """A demo cell run before its part is written met the bare placeholder (an empty
    NotImplementedError, nothing said): now it names the part and what to do."""
    placeholder = tmp_path / 'unwritten_sensor.py'
    placeholder.write_text('class TemperatureSensor:\n    def __init__(self):\n'
                           '        # YOUR CODE HERE\n        raise NotImplementedError()\n')
    kernel.run(f'import sys\nsys.path.insert(0, {str(tmp_path)!r})\nimport unwritten_sensor')
    kernel.one_line('sensor = unwritten_sensor.TemperatureSensor()',
                    'NotImplementedError (unwritten_sensor.py line 4: raise '
                    'NotImplementedError()): TemperatureSensor() is not written yet: write your '
                    'code where it says YOUR CODE HERE')
    kernel.one_line('raise NotImplementedError()', 'this cell is not written yet')
    shown = kernel.run('raise NotImplementedError("not for ROS 1")').error[1]
    assert 'not for ROS 1' in shown[-1] and 'not written yet' not in ''.join(shown)


def test_a_long_simulated_spin_interrupted_is_one_line_not_its_log_lines(ros):
    ros.run("import os, signal\n"
            "class Sensor(Node):\n    def __init__(self):\n        super().__init__('loud')\n"
            "        self.ticks = 0\n"
            "        self.create_timer(1.0, self.tick)\n\n"
            "    def tick(self):\n        self.ticks += 1\n"
            "        self.get_logger().info(f'tick {self.ticks}')\n"
            "        if self.ticks == 600:\n            os.kill(os.getpid(), signal.SIGINT)\n\n"
            "sensor = ros2nb.add(Sensor())")
    result = ros.run('_ = ros2nb.spin(10 ** 7)')
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('Interrupted after 600.0 of 1e+07 simulated s '
                                                   '(its log lines are not shown)'), lines[:3]


def test_a_callback_left_due_by_the_stop_button_adds_no_line_after_it(ros):
    # The Stop button lands after a step of /clock made two timers due and before the second
    # ran. Run later, by the thread that spins between cells, its line would come after
    # "Interrupted ..." in the same cell (a learner's Lab showed it). The first timer
    # presses Stop itself, so the interrupt lands there however busy the machine is.
    ros.run("import os, signal, time\n"
            "class Sensor(Node):\n    def __init__(self):\n        super().__init__('slow')\n"
            "        self.ticks = 0\n"
            "        self.create_timer(1.0, self.press_stop_at_three)\n"
            "        self.create_timer(1.0, self.tick)\n\n"
            "    def press_stop_at_three(self):\n        self.ticks += 1\n"
            "        if self.ticks == 3:\n            os.kill(os.getpid(), signal.SIGINT)\n\n"
            "    def tick(self):\n        time.sleep(0.3)\n"
            "        self.get_logger().info('tick')\n\n"
            "sensor = ros2nb.add(Sensor())")
    result = ros.run('_ = ros2nb.spin(10 ** 7)\n'
                     'from ros2nb.runtime import current_runtime\n'
                     'waited = time.monotonic()\n'  # until the third tick's line is back
                     "while current_runtime().log_counts['slow'] < 3 "
                     "and time.monotonic() - waited < 60:\n"
                     '    time.sleep(0.01)\n')
    lines = result.stdout.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith('Interrupted after 3.0 of 1e+07 simulated s '
                                                   '(its log lines are not shown)'), lines
    assert ros.run("print(current_runtime().log_counts['slow'])").stdout.strip() == '3'


def test_a_part_run_out_of_order_says_which_part_is_missing(kernel, tmp_path):
    kernel.run(f"ros2nb.create_workspace({str(tmp_path / 'ws')!r}, allow_outside_course=True)")
    out = kernel.run('%%part scripts/order.py 3\nc = 3\n').stdout
    assert out.strip().endswith('part 3 saved (parts 3; 1 lines; parts 1, 2 not saved yet: run '
                                'their cells too)'), out


@pytest.mark.parametrize('profile, fragments', [
    ("QoSProfile(depth=1, reliability='best_effort')",
     ("reliability takes a QoSReliabilityPolicy, not str 'best_effort'",
      'reliability=QoSReliabilityPolicy.BEST_EFFORT')),
    ("QoSProfile(depth='1')", ("depth takes a whole number, not str '1'", 'no quotes')),
    # rclpy's own warning under "Check passed" before: Fast DDS's default depth happens to be 1
    ('QoSProfile(depth=0)', ("depth=0 with KEEP_LAST does not mean 'keep none'", 'depth=1')),
])
def test_a_qos_setting_of_the_wrong_type_in_09(ros, profile, fragments):
    """rclpy's bare assert (an empty AssertionError 40 lines down rclpy) becomes one line
    at the learner's own line."""
    ros.run(f'from rclpy.qos import QoSProfile\ndef newest_only_profile():\n    return {profile}')
    line = ros.one_line('ros2nb.checks.check_newest_only(newest_only_profile)', *fragments)
    assert 'cell line 3' in line, line


def test_plt_pause_in_a_plot_callback_is_one_line_not_a_minute_of_copies(ros):
    """07: plt.pause in the callback holds every message up for its interval (a live cell of
    a second runs for a minute) and draws a copy each time; the node stops at the first
    message with one line at the learner's line."""
    ros.run('import matplotlib.pyplot as plt\n'
            'class Pausing(Node):\n'
            '    def __init__(self):\n'
            "        super().__init__('pausing_plot')\n"
            "        self.create_subscription(Float32, 'temperature', self.on_reading, 10)\n"
            '    def on_reading(self, msg):\n'
            '        plt.pause(0.5)\n'
            "feeder = Node('feeding_sensor')\n"
            "out = feeder.create_publisher(Float32, 'temperature', 10)\n"
            'feeder.create_timer(1.0, lambda: out.publish(Float32(data=21.0)))\n'
            'ros2nb.add(Pausing()); ros2nb.add(feeder)')
    stderr = ros.run('_ = ros2nb.spin(5)').stderr
    assert 'plt.pause() in a callback waits its interval on every message' in stderr, stderr
    assert 'cell line 7: plt.pause(0.5)' in stderr and stderr.count('[ERROR]') == 1, stderr
    shown = ros.run('plt.show()')  # outside a callback, pyplot's own
    assert shown.error is None, shown


def test_an_error_inside_the_learners_bag_reader_in_10(ros):
    """An error in the learner's own function is one line: the error, what to do and their
    own line, never a traceback through the check, rosbags or rclpy (nor through their own
    frames: issue 65 counted five lines and more, without a fix)."""
    ros.run('def read_temperatures(bag_path):\n'
            '    readings = {}\n'
            "    return readings['temperature']\n")
    line = ros.one_line('ros2nb.checks.check_readings(read_temperatures)',
                        "read_temperatures(bag_path) raised: KeyError: 'temperature': the line "
                        'reads a key that is not there: check its spelling, or read it with '
                        '.get(key, default).', "(cell line 3: return readings['temperature'])")
    assert 'ros2nb/checks' not in line and 'site-packages' not in line, line


PARAMETER_NODE = '''
from rcl_interfaces.msg import SetParametersResult

class Thresholds(Node):
    def __init__(self, **kwargs):
        super().__init__('thresholds_one', **kwargs)
        {body}

    def on_parameters_set(self, parameters):
        return SetParametersResult(successful=True)
'''


@pytest.mark.parametrize('body, made, fragments', [
    ("self.high = self.get_parameter('high_above_c').value\n"
     "        self.declare_parameter('high_above_c', 26.0)", 'Thresholds()',
     ("the parameter 'high_above_c' was read (or set) before it was declared",
      "self.declare_parameter('high_above_c', default) first")),
    ("self.add_on_set_parameters_callback(self.on_parameters_set(None))", 'Thresholds()',
     ('add_on_set_parameters_callback takes the callback itself', 'without ()')),
    ("self.add_on_set_parameters_callback(self.on_parameters_set())", 'Thresholds()',
     ('on_parameters_set() was called here, with nothing for its parameters',
      'pass the method itself, without (): self.on_parameters_set')),
    ("self.declare_parameter('high_above_c', 26.0)",
     "Thresholds(cli_args=['--ros-args', '-p', 'high_above_c:=25'])",
     ("the parameter 'high_above_c' holds a double", "'25' is an integer",
      '-p high_above_c:=25.0')),
])
def test_the_classic_parameter_mistakes_of_08(ros, body, made, fragments):
    ros.run(PARAMETER_NODE.format(body=body))
    ros.one_line(made, *fragments)


@pytest.mark.parametrize('arguments, fragments', [
    ("['--ros-args', '-r', '__ns:=kitchen']", ("the remap rule '-r __ns:=kitchen'",
                                              'a namespace starts with a slash: __ns:=/kitchen')),
    ("['--ros-args', '-p', '__ns:=/kitchen']", ('__ns is not a parameter but a remap',
                                               '-r __ns:=/kitchen')),
    ("['--ros-args', '-r', 'temperature=kitchen_temperature']", ('written FROM:=TO, with :=',)),
])
def test_rcl_refusing_a_rule_is_one_line_with_the_rule_written_right(ros, arguments, fragments):
    """06's room arguments as beginners write them: rcl's 'Expected lexeme type 19, got 18 at
    index 6' becomes what is wrong and how the rule is written."""
    line = ros.one_line(f"Node('fan_in_a_room', cli_args={arguments})", *fragments)
    assert 'lexeme' not in line, line


def test_nodes_left_running_are_named_not_blamed_on_the_replay(ros):
    """10: the live sensor of an earlier cell still up when the replay is checked: the line
    names the nodes left running and what to do, never the learner's (here empty) replay."""
    ros.run("leftover = ros2nb.add(Node('temperature_sensor'))\n"
            'def replay(bag_path, rate):\n    pass')
    line = ros.one_line('ros2nb.checks.check_replay(replay)',
                        'still running in this kernel (/temperature_sensor)',
                        'Run ros2nb.stop(), then this check again')
    assert 'replay(' in line and 'add the monitor' not in line, line


@pytest.mark.parametrize('cell, fragments', [
    ('import random\nstep = random.randint(-0.5, 0.5)',
     ('random.randint draws whole numbers only', 'random.uniform(-0.5, 0.5)')),
    ("t = 22.5\nNode('logs_like_print').get_logger().info('T:', t)",
     ('get_logger().info() takes one string, not a list of values as print does',)),
    ("class Ticking(Node):\n    def __init__(self):\n        super().__init__('ticking')\n"
     '        self.create_timer(1.0, publish_temperature)\n\n'
     '    def publish_temperature(self):\n        pass\n\nTicking()',
     ('publish_temperature is a method of Ticking: inside the class, name it '
      'self.publish_temperature.', 'cell line 4')),
])
def test_python_used_the_way_another_tool_is_in_03(ros, cell, fragments):
    """01-05, new kinds: randint for a decimal step, a logger called like print, a method
    named without self."""
    ros.one_line(cell, *fragments)


@pytest.mark.parametrize('cell, fragments', [
    ('from std_msgs.msg import Bool\nHIGH_ABOVE_C = 26.0\n\ndef command(reading):\n'
     '    return Bool(reading > HIGH_ABOVE_C)\n\ncommand(27.0)',
     ('a Bool message takes its fields by name, not in order: write '
      'Bool(data=reading > HIGH_ABOVE_C) (its fields: data)', 'cell line 5')),
    ('class Counting:\n    def __init__(self):\n        self.received = 0\n\n'
     '    def on_reading(self, msg):\n        received += 1\n\nCounting().on_reading(None)',
     ("received here is a new local name of this method, not the node's count (the node keeps "
      'it as self.received): write self.received', 'cell line 6')),
])
def test_python_used_the_way_another_tool_is_in_06(cell, fragments, kernel):
    """06: a message given its field in order, a node's count without self.: Python's own
    error, at the learner's line, with the fix."""
    kernel.one_line(cell, *fragments)


def test_plt_show_in_a_loop_is_one_line_not_a_copy_per_pass(ros):
    """07: plt.show() in a loop (outside any callback) drew one more copy of the live figure
    under the cell on every pass, silently; the second show of it in one cell is one line."""
    ros.run('%matplotlib widget\nimport matplotlib.pyplot as plt\nfig, ax = plt.subplots()')
    try:
        ros.one_line('for _ in range(3):\n    plt.show()',
                            'plt.show() showed this figure again in the same cell',
                            'keep one figure and update it', 'fig.canvas.draw_idle()')
        assert ros.run('plt.show()').error is None  # the next cell shows it once, as asked
    finally:
        ros.run("plt.close('all')\n%matplotlib inline")
