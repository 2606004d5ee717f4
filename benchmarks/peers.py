"""What ``make bench`` times, one measurement per run: ``python benchmarks/peers.py WHAT``.

Each run is a fresh process (its own ROS domain, nothing warm), prints one JSON line with
its wall-clock seconds (and, for the simulated hour, the CPU seconds of the process),
and is started by ``benchmarks/bench.py``, which interleaves the peers and repeats them.

- ``sim-hour-ros2nb``: one simulated hour of the course's sensor recorded in a kernel's way
  (``ros2nb.start(sim_time=True)``, ``ros2nb.add``, ``ros2nb.record``), as notebook 03 does.
- ``sim-hour-bare``: the same work in a bare rclpy program: the same sensor file, a recorder
  node, a ``/clock`` publisher and a ``SingleThreadedExecutor`` spun until each reading is in.
- ``sim-hour-kernel``: the same hour in a real Jupyter kernel, as a learner runs notebook 03:
  the wall seconds of the cell and the CPU seconds of the kernel (``patience.tree_cpu_seconds``:
  every thread, ipykernel's output thread too, which an in-process run never sees).
- ``first-message-kernel``: from creating the sensor in a kernel's runtime (wall clock) to
  the first reading received by a monitor node in the same process.
- ``first-message-processes``: from starting the sensor and the monitor as two processes
  (what ``ros2 run`` starts) to the monitor printing its first reading.
- ``idle-kernel``: a kernel's runtime between cells (the sensor and the monitor added, on
  simulated time, nothing to do): CPU seconds it uses per second of wall clock.
- ``idle-bare``: the same nodes in a bare rclpy program blocked in ``executor.spin()``.
- ``interrupt-kernel``: from interrupting a kernel (Stop) to the end of its cell, which spins
  a ticking node on the wall clock.
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import os
import random
import subprocess
import sys
import time
from pathlib import Path
from types import ModuleType

from ros2nb.temporary import owned_folder

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / 'src'))

from ros2nb import course  # noqa: E402

SIMULATED_S = 3600
SEED = 2024


def reference_module(name: str) -> ModuleType:
    """Import the course's reference node file ``name`` (e.g. ``temperature_publisher``)."""
    folder = owned_folder('ros2nb-bench-')
    path = folder / f'{name}.py'
    path.write_text(course.reference_source(f'{name}.py'))
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module  # as an import does (rclpy's logger looks its file up there)
    spec.loader.exec_module(module)
    return module


def sim_hour_ros2nb() -> tuple[float, float]:
    import ros2nb
    sensor = reference_module('temperature_publisher')
    with contextlib.redirect_stdout(io.StringIO()):
        ros2nb.start(sim_time=True)
        random.seed(SEED)
        ros2nb.add(sensor.TemperatureSensor())
        started = time.perf_counter(), time.process_time()
        _, values = ros2nb.record(course.TOPIC, SIMULATED_S)
        elapsed = time.perf_counter() - started[0], time.process_time() - started[1]
        ros2nb.shutdown()
    assert len(values) == SIMULATED_S, len(values)
    return elapsed


def sim_hour_kernel() -> tuple[float, float]:
    from jupyter_client.manager import start_new_kernel
    from ros2nb.patience import tree_cpu_seconds
    sensor = reference_module('temperature_publisher')
    manager, client = start_new_kernel(kernel_name='python3')
    try:
        def run(code: str) -> None:
            reply = client.execute_interactive(code, timeout=600, output_hook=lambda _msg: None)
            if reply['content']['status'] != 'ok':
                raise RuntimeError(f'the kernel failed: {reply["content"].get("evalue")}')

        run(f'import random, sys\nsys.path.insert(0, {str(Path(sensor.__file__).parent)!r})\n'
            'import ros2nb, temperature_publisher\n'
            'ros2nb.start(sim_time=True)\n'
            f'random.seed({SEED})\n'
            '_ = ros2nb.add(temperature_publisher.TemperatureSensor())')
        pid = manager.provisioner.process.pid
        started = time.perf_counter(), tree_cpu_seconds(pid)
        run(f'_, values = ros2nb.record({course.TOPIC!r}, {SIMULATED_S})\n'
            f'assert len(values) == {SIMULATED_S}, len(values)')
        return time.perf_counter() - started[0], tree_cpu_seconds(pid) - started[1]
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


def interrupt_kernel() -> float:
    """From the kernel's interrupt (the Stop button) to the end of a cell spinning a ticking
    node on the wall clock for longer than anyone waits: what a learner waits after Stop."""
    from jupyter_client.manager import start_new_kernel
    manager, client = start_new_kernel(kernel_name='python3')
    try:
        client.execute_interactive('import ros2nb\n_ = ros2nb.start()', timeout=120,
                                   output_hook=lambda _msg: None)
        msg_id = client.execute("from rclpy.node import Node\n"
                                "ticker = Node('ticker')\n"
                                "ticker.create_timer(1.0, lambda: None)\n"
                                "ros2nb.add(ticker)\nprint('spinning', flush=True)\n"
                                "_ = ros2nb.spin(10 ** 7)\n")
        while True:  # the spin has begun once its cell printed
            msg = client.get_iopub_msg(timeout=120)
            if msg['parent_header'].get('msg_id') == msg_id and msg['msg_type'] == 'stream':
                break
        time.sleep(1.0)  # well inside the spin
        began, said = time.perf_counter(), ''
        manager.interrupt_kernel()
        while True:
            msg = client.get_iopub_msg(timeout=120)
            if msg['parent_header'].get('msg_id') != msg_id:
                continue
            if msg['msg_type'] in ('stream', 'error'):
                said += msg['content'].get('text', '') + msg['content'].get('evalue', '')
            if msg['msg_type'] == 'status' and msg['content']['execution_state'] == 'idle':
                took = time.perf_counter() - began
                if 'Interrupted after' not in said:
                    raise RuntimeError(f'the spin ended otherwise: {said!r}')
                return took
    finally:
        client.stop_channels()
        manager.shutdown_kernel(now=True)


def sim_hour_bare() -> tuple[float, float]:
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from rclpy.parameter import Parameter
    from rosgraph_msgs.msg import Clock
    from std_msgs.msg import Float32
    from ros2nb import domains
    sensor_module = reference_module('temperature_publisher')
    rclpy.init(args=['--ros-args', '--disable-stdout-logs', '--disable-external-lib-logs'],
               domain_id=domains.domain_id())  # a domain of its own, as ros2nb's
    random.seed(SEED)
    sensor = sensor_module.TemperatureSensor()
    sensor.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, True)])
    recorder = Node('recorder')
    values: list[float] = []
    recorder.create_subscription(Float32, course.TOPIC, lambda m: values.append(m.data), 10)
    clock = recorder.create_publisher(Clock, '/clock', 10)
    executor = SingleThreadedExecutor()
    executor.add_node(sensor)
    executor.add_node(recorder)
    tick = Clock()
    clock.publish(tick)  # time 0: the sensor's clock starts, its timer counts from here
    executor.spin_once(timeout_sec=0.1)
    for timer in sensor.timers:
        timer.reset()
    started = time.perf_counter(), time.process_time()
    for second in range(1, SIMULATED_S + 1):
        tick.clock.sec = second
        clock.publish(tick)
        while len(values) < second:
            executor.spin_once(timeout_sec=1.0)
    elapsed = time.perf_counter() - started[0], time.process_time() - started[1]
    executor.shutdown()
    sensor.destroy_node()
    recorder.destroy_node()
    rclpy.try_shutdown()
    assert len(values) == SIMULATED_S, len(values)
    return elapsed


def first_message_kernel() -> float:
    import ros2nb
    from rclpy.node import Node
    from std_msgs.msg import Float32
    sensor_module = reference_module('temperature_publisher')
    with contextlib.redirect_stdout(io.StringIO()):
        ros2nb.start(sim_time=False)
        heard: list[float] = []
        monitor = Node('bench_monitor')
        monitor.create_subscription(Float32, course.TOPIC,
                                    lambda m: heard.append(time.perf_counter()), 10)
        ros2nb.add(monitor)
        started = time.perf_counter()
        ros2nb.add(sensor_module.TemperatureSensor())
        while not heard:
            time.sleep(0.001)
        ros2nb.shutdown()
    return heard[0] - started


def first_message_processes() -> float:
    from ros2nb import domains
    folder = owned_folder('ros2nb-bench-')
    files = []
    for name in ('temperature_publisher', 'temperature_subscriber'):
        files.append(folder / f'{name}.py')
        files[-1].write_text(course.reference_source(f'{name}.py'))
    env = dict(os.environ, PYTHONUNBUFFERED='1', ROS_DOMAIN_ID=str(domains.domain_id()),
               ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST')
    started = time.perf_counter()
    procs = [subprocess.Popen([sys.executable, str(f)], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, start_new_session=True)
             for f in files]
    try:
        for line in procs[1].stdout:
            if 'Temperature:' in line:
                return time.perf_counter() - started
        raise RuntimeError('the monitor process ended without hearing a reading')
    finally:
        for proc in procs:
            proc.kill()
            proc.wait()


#: Wall-clock seconds an idle runtime is watched.
IDLE_S = 5.0


def _idle_cpu_share() -> tuple[float, float]:
    """(IDLE_S, CPU seconds per wall second of this process over IDLE_S seconds)."""
    time.sleep(0.5)  # what starting the nodes left to do
    started = time.process_time()
    time.sleep(IDLE_S)
    return IDLE_S, (time.process_time() - started) / IDLE_S


def idle_kernel() -> tuple[float, float]:
    import ros2nb
    sensor = reference_module('temperature_publisher')
    monitor = reference_module('temperature_subscriber')
    with contextlib.redirect_stdout(io.StringIO()):
        ros2nb.start(sim_time=True)
        ros2nb.add(sensor.TemperatureSensor())
        ros2nb.add(monitor.TemperatureMonitor())
        measured = _idle_cpu_share()
        ros2nb.shutdown()
    return measured


def idle_bare() -> tuple[float, float]:
    import threading
    import rclpy
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.parameter import Parameter
    sensor = reference_module('temperature_publisher')
    monitor = reference_module('temperature_subscriber')
    rclpy.init()
    executor = SingleThreadedExecutor()
    nodes = [sensor.TemperatureSensor(), monitor.TemperatureMonitor()]
    for node in nodes:
        node.set_parameters([Parameter('use_sim_time', Parameter.Type.BOOL, True)])
        executor.add_node(node)
    spinning = threading.Thread(target=executor.spin)
    spinning.start()
    measured = _idle_cpu_share()
    executor.shutdown()  # spin() returns
    spinning.join()
    for node in nodes:
        node.destroy_node()
    rclpy.shutdown()
    return measured


MEASURES = {'sim-hour-ros2nb': sim_hour_ros2nb, 'sim-hour-bare': sim_hour_bare,
            'sim-hour-kernel': sim_hour_kernel,
            'first-message-kernel': first_message_kernel,
            'first-message-processes': first_message_processes,
            'idle-kernel': idle_kernel, 'idle-bare': idle_bare,
            'interrupt-kernel': interrupt_kernel}

if __name__ == '__main__':
    if len(sys.argv) != 2 or sys.argv[1] not in MEASURES:
        sys.exit(f'Usage: peers.py {"|".join(MEASURES)}')
    measured = MEASURES[sys.argv[1]]()
    wall, cpu = measured if isinstance(measured, tuple) else (measured, None)
    print(json.dumps({'seconds': wall, 'cpu_seconds': cpu}))
