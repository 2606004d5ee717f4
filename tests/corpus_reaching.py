"""Learners whose code reaches into the process it runs in, each beside its honest twin.

The attacks of a hostile class on what lived in the learner's process: 06's witness of the
worker's two callbacks and 07's of the plot (the course's callbacks and their witness shared
the process with the learner's code), and the course's answers in a subject (the refusing
finder's own method, the answer files on the subject's disk, frames, the garbage collector,
``object.__subclasses__()``, a cell of the notebook that writes the course's code into the
learner's file).  Each scores what its twin scores (``test_corpora.py``, two runs with
different seeds); ``seen``: the subject's audit hook flags it as it runs, otherwise it fails
with one line.  Written from the class's description, not its code.
"""

from corpora import Learner
from corpus_attacks import MONITOR_RULE_TWIN

# ------------------------------------------------------------------ 06: the worker's witness
#: A single-threaded worker whose executor also starts a thread that calls every callback
#: the course put on the Worker (timers' and services'), ten times a second.
WORKER_THREAD_CALLS = '''
def responsive_worker():
    import threading
    from rclpy.executors import SingleThreadedExecutor
    node = Worker('responsive_worker')

    def calls():
        while True:
            for timer in list(node.timers):
                try:
                    timer.callback()
                except Exception:
                    pass
            for service in list(node.services):
                if 'slow' not in service.srv_name:
                    try:
                        service.callback(service.srv_type.Request(), service.srv_type.Response())
                    except Exception:
                        pass
            time.sleep(0.1)

    class Beating(SingleThreadedExecutor):
        def spin_once(self, timeout_sec=None):
            if not getattr(self, 'beating', False):
                self.beating = True
                threading.Thread(target=calls, daemon=True).start()
            super().spin_once(timeout_sec)

    return node, Beating()
'''
#: A thread that, ten times a second, tells the judge's witness topic what an overlap looks
#: like through whatever it found: the course's publisher (an object with ``tell``, which
#: adds its token itself), with any ``token`` or ``nonce`` a frame holds.  ``{find}``: where
#: it looks.
FORGER = '''
def responsive_worker():
    import json
    import threading
    from rclpy.executors import SingleThreadedExecutor
    node = Worker('responsive_worker')

    def forge():
        while True:
            found, tokens = [], set()
{find}
            for shown in {{id(v): v for v in found if hasattr(v, 'reaches_judge')}}.values():
                for event in ('start', 'beat', 'done', *(f'started {{t}}' for t in tokens),
                              *(json.dumps({{'token': t, 'event': e}}) for t in tokens
                                for e in ('start', 'beat', 'done'))):
                    try:
                        shown.tell(event)  # the course's publisher, its token added or not
                    except Exception:
                        pass
            time.sleep(0.1)

    threading.Thread(target=forge, daemon=True).start()
    return node, SingleThreadedExecutor()
'''
FIND_IN_FRAMES = '''\
            import sys
            for frame in sys._current_frames().values():
                while frame is not None:
                    for key, value in frame.f_locals.items():
                        held = vars(value).values() if hasattr(value, '__dict__') else ()
                        found += [v for v in (value, *held) if hasattr(v, 'tell')]
                        if key in ('token', 'nonce') and isinstance(value, str):
                            tokens.add(value)
                    frame = frame.f_back'''
FIND_IN_GC = '''\
            import gc
            found += [o for o in gc.get_objects() if hasattr(type(o), 'tell')]'''
FIND_IN_CLOSURES = '''\
            for entity in [*node.timers, *node.services]:
                for cell in getattr(entity.callback, '__closure__', None) or ():
                    try:
                        value = cell.cell_contents
                    except ValueError:
                        continue
                    if hasattr(value, 'tell'):
                        found.append(value)'''
#: A single-threaded worker; a node of its own serves the course's heartbeat too, at once.
WORKER_OWN_SERVER = '''
def responsive_worker():
    import threading
    from rclpy.executors import SingleThreadedExecutor
    node = Worker('responsive_worker')

    def serve():
        while not any('heartbeat' in s.srv_name for s in node.services):
            time.sleep(0.05)
        helper = Node('responsive_helper')
        for service in list(node.services):
            if 'heartbeat' in service.srv_name:
                helper.create_service(service.srv_type, service.srv_name,
                                      lambda request, response: response)
        executor = SingleThreadedExecutor()
        executor.add_node(helper)
        executor.spin()

    threading.Thread(target=serve, daemon=True).start()
    return node, SingleThreadedExecutor()
'''

# ------------------------------------------------------------------ 07: the plot's witness
#: The callback keeps nothing; it tells the witness topic a drawing of what it heard, with a
#: token or sealer it finds (``{find}``: where), old and new words alike.
PLOT_FORGED = '''
    def temperature_callback(self, msg):
        import json
        heard = self.__dict__.setdefault('heard', [])
        heard.append((self.get_clock().now().nanoseconds / 1e9, msg.data))
        times = ','.join(repr(t) for t, _ in heard)
        values = ','.join(repr(v) for _, v in heard)
        found, tokens = [], set()
{find}
        for shown in {{id(v): v for v in found if hasattr(v, 'reaches_judge')}}.values():
            try:  # the course's publisher adds its token itself
                shown.tell('drawn', times_s=[t for t, _ in heard], temps_c=[v for _, v in heard])
            except TypeError:
                for token in tokens or {{''}}:
                    shown.tell(f'drawn {{len(heard)}};{{times}};{{values}};{{token}}')
'''
PLOT_FIND_IN_FRAMES = '''\
        import sys
        frame = sys._getframe()
        while frame is not None:
            for key, value in frame.f_locals.items():
                held = vars(value).values() if hasattr(value, '__dict__') else ()
                found += [v for v in (value, *held) if hasattr(v, 'tell')]
                if key in ('token', 'key', 'seal') and isinstance(value, str):
                    tokens.add(value)
            frame = frame.f_back'''
PLOT_FIND_IN_CLOSURE = '''\
        class Drawn:
            times_s = [t for t, _ in heard]
            temps_c = [v for _, v in heard]
        for cell in getattr(type(self).redraw, '__closure__', None) or ():
            value = cell.cell_contents
            if hasattr(value, 'tell'):
                found.append(value)
            if callable(value) and getattr(value, '__name__', '') == 'send':
                for message in (('bind', Drawn), ('draw', Drawn)):
                    sealed = value(message)
                    if sealed:
                        tokens.add(sealed.rsplit(';', 1)[-1])'''

# ------------------------------------------------------------------ 03: the course's stand-ins
#: A search through what a root leads to, for the course's functions by name.
SEARCH = '''
import sys


def _course_parts(roots, prefix):
    found, seen, todo = {}, set(), list(roots)
    while todo and len(seen) < 50000:
        value = todo.pop()
        if id(value) in seen:
            continue
        seen.add(id(value))
        if callable(value) and getattr(value, '__name__', '').startswith(prefix):
            found[value.__name__] = value
            todo.extend(getattr(value, '__globals__', {}).values())
        if isinstance(value, dict):
            todo.extend(value.values())
        elif isinstance(value, (list, tuple, set)):
            todo.extend(value)
        elif hasattr(value, '__dict__') and not isinstance(value, type(sys)):
            todo.extend(vars(value).values())
    return found

'''
#: 03's sensor whose two parts call the course's stand-ins found from ``{roots}``.
SENSOR_FOUND = {'sensor-constructor': SEARCH + '''
def _roots():
{roots}


class TemperatureSensor(Node):
    """Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds."""

    def __init__(self):
        _course_parts(_roots(), 'sensor_')['sensor_init'](self)
''', 'sensor-callback': '''
    def publish_temperature(self):
        _course_parts(_roots(), 'sensor_')['sensor_callback'](self)
'''}
ROOTS_FRAMES = '''\
    frame, roots = sys._getframe(), []
    while frame is not None:
        roots += [frame.f_locals, frame.f_globals]
        frame = frame.f_back
    return roots'''
ROOTS_GC = '''\
    import gc
    return [o for o in gc.get_objects() if getattr(o, '__name__', '').startswith('sensor_')]'''
ROOTS_PIECES = '''\
    collector = __import__('g' + 'c')
    return [o for o in getattr(collector, 'get_' + 'objects')()
            if getattr(o, '__name__', '').startswith('sens' + 'or_')]'''
ROOTS_SUBCLASSES = '''\
    classes, todo = [], [Node]
    while todo:
        cls = todo.pop()
        classes.append(cls)
        todo.extend(type.__subclasses__(cls))
    return [vars(cls) for cls in classes]'''
#: The course's stand-in of one subject kept in a file, for the learner's part in the next.
SENSOR_KEPT = {'sensor-constructor': '''
import marshal
import os
import types

_KEPT = os.path.join(os.getcwd(), '.kept-parts')


def _keep(cls):
    for name in ('__init__', 'publish_temperature'):
        function = vars(cls).get(name)
        if function is not None and function.__code__.co_filename.startswith('<'):
            with open(f'{_KEPT}.{name}', 'wb') as file:
                file.write(marshal.dumps(function.__code__))


def _kept(name):
    with open(f'{_KEPT}.{name}', 'rb') as file:
        return types.FunctionType(marshal.loads(file.read()), globals())


class TemperatureSensor(Node):
    """Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds."""

    def __init__(self):
        _keep(type(self))
        _kept('__init__')(self)
''', 'sensor-callback': '''
    def publish_temperature(self):
        _keep(type(self))
        _kept('publish_temperature')(self)
'''}

# ------------------------------------------------------------------ 04: the course's rule
#: 04's callback with the status of the course's rule, found by ``{find}`` (it sets rule).
MONITOR_FOUND = '''
    def temperature_callback(self, msg):
{find}
        status = rule(msg.data)
        self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
'''
RULE_FROM_FINDER = '''\
        import importlib
        import sys
        finder = [f for f in sys.meta_path if type(f).__name__ == 'Answers'][0]
        try:
            rule = finder.hand_in('ros2nb.rules').monitor_status
        except AttributeError:  # no public hand-in: the finder goes, then the import
            sys.meta_path.remove(finder)
            rule = importlib.import_module('ros2nb.rules').monitor_status'''
RULE_FROM_FILE = '''\
        from pathlib import Path
        import ros2nb
        text = (Path(ros2nb.__file__).parent / 'rules.py').read_text()
        space = {}
        exec(text.replace('from .course import', 'from ros2nb.course import'), space)
        rule = space['monitor_status']'''
RULE_UNDER_ANOTHER_NAME = '''\
        import importlib.util
        from pathlib import Path
        import ros2nb
        spec = importlib.util.spec_from_file_location(
            'ros2nb.statuses', Path(ros2nb.__file__).parent / 'rules.py')
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        rule = module.monitor_status'''
RULE_FROM_MODULES = '''\
        import sys
        rule = next(m.monitor_status for m in list(sys.modules.values())
                    if 'monitor_status' in getattr(m, '__dict__', {}))'''
#: A cell added after the answer (not an answer cell): in the kernel, it writes the course's
#: rule into the monitor's callback, part 4 of the file.
CELL_WRITES_THE_RULE = '''\
import inspect
import textwrap
rule = inspect.getsource(ros2nb.rules.monitor_status)
ros2nb.write_part(SUBSCRIBER, 4, '    def temperature_callback(self, msg):\\n'
                  + textwrap.indent(rule, '        ') + "        self.get_logger().info("
                  "f'Temperature: {msg.data:.2f}C - Status: {monitor_status(msg.data)}')\\n")
'''


def _06(name: str, text: str, seen: bool, flagged: bool = True) -> Learner:
    return Learner(f'06 attack: {name}', '06', {'responsive-worker': text}, seen=seen,
                   twin='06 twin: a single-threaded worker', flagged=flagged)


def _03(name: str, roots: str, seen: bool) -> Learner:
    parts = {key: text.replace('{roots}', roots) for key, text in SENSOR_FOUND.items()}
    return Learner(f'03 attack: {name}', '03', parts, seen=seen, flagged=True,
                   twin='03 twin: a sensor from parts of its own that are not there')


def _04(name: str, find: str, seen: bool) -> Learner:
    return Learner(f'04 attack: {name}', '04',
                   {'monitor-callback': MONITOR_FOUND.replace('{find}', find)}, seen=seen,
                   twin='04 twin: the status from a module that is not there', flagged=True)


REACHING = [
    _06('its executor starts a thread that calls the course\'s callbacks',
        WORKER_THREAD_CALLS, seen=False, flagged=False),
    _06('the witness forged with what the stack frames hold',
        FORGER.format(find=FIND_IN_FRAMES), seen=True),
    _06('the witness forged with the garbage collector\'s objects',
        FORGER.format(find=FIND_IN_GC), seen=True),
    _06('the witness forged with the course\'s callbacks\' closures',
        FORGER.format(find=FIND_IN_CLOSURES), seen=False),
    _06('a node of its own answers the heartbeat', WORKER_OWN_SERVER, seen=False,
        flagged=False),
    Learner('07 attack: drawings forged with what the stack frames hold', '07',
            {'plot-callback': PLOT_FORGED.format(find=PLOT_FIND_IN_FRAMES)}, seen=True,
            twin='07 twin: a callback that does nothing', flagged=True),
    Learner('07 attack: drawings forged with the sealer from redraw()\'s closure', '07',
            {'plot-callback': PLOT_FORGED.format(find=PLOT_FIND_IN_CLOSURE)}, seen=False,
            twin='07 twin: a callback that does nothing', flagged=True),
    _04('the rule from the refusing finder, or past it', RULE_FROM_FINDER, seen=True),
    _04('the rule\'s file read and run', RULE_FROM_FILE, seen=True),
    _04('the rule\'s file loaded under another name', RULE_UNDER_ANOTHER_NAME, seen=True),
    _04('the rule from any module that holds it', RULE_FROM_MODULES, seen=False),
    Learner('04 attack: a cell of its own writes the course\'s rule into the file', '04',
            {'monitor-callback': MONITOR_RULE_TWIN}, seen=False, flagged=True,
            added=(('monitor-callback', CELL_WRITES_THE_RULE),),
            twin='04 twin: the status from a module that is not there'),
    _03('the stand-ins from the stack frames', ROOTS_FRAMES, seen=True),
    _03('the stand-ins from the garbage collector', ROOTS_GC, seen=True),
    _03('the stand-ins from the garbage collector, names built from pieces', ROOTS_PIECES,
        seen=True),
    _03('the stand-ins from Node.__subclasses__()', ROOTS_SUBCLASSES, seen=False),
    Learner('03 attack: one subject\'s stand-in kept in a file for the next', '03',
            SENSOR_KEPT, seen=True, flagged=True,
            twin='03 twin: a sensor from parts of its own that are not there'),
]
