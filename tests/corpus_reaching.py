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
from corpus_attacks import MONITOR_RULE_TWIN, ON_SET_BODY, PLOT_DEAD

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
    # Concurrency of another kind, which docs/decisions.md's row for 06 accepts: the heartbeat
    # keeps coming while the judge holds the slow job, so it scores what honest workers score.
    Learner('06 attack: its executor starts a thread that calls the course\'s callbacks', '06',
            {'responsive-worker': WORKER_THREAD_CALLS}, seen=False, flagged=False,
            twin='06 a worker made in one line, one reentrant group'),
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
    # Not seen at run time: in the grader's sandbox the rules are on no disk, and a failed
    # importlib.import_module raises no audit event (only __import__ does); the hook only
    # detects, and its silence proves nothing.  The score is the twin's all the same.
    _04('the rule from the refusing finder, or past it', RULE_FROM_FINDER, seen=False),
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


# ================================================================== the sixth class
# Each cause the sixth hostile class found, as an attacker beside its honest twin, written from
# the class's description (graded in the grader's sandbox, with two seeds new in every run:
# test_corpora.py).  In the design they met, the judge's instruments lived in the learner's
# process; now a point is what the judge observes from outside it, and each scores its twin's.

# ---- 06: the course's slow work and heartbeat were objects the learner's executor could
# replace.  Now the Worker's slow work calls the judge's service, which the judge holds open.
#: Its executor makes the slow work a coroutine that returns at once (never asks the slow
#: job), and gives each timer a group of its own, before it spins.
WORKER_NEVER_ASKS = '''
def responsive_worker():
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
    from rclpy.executors import SingleThreadedExecutor
    node = Worker('responsive_worker')

    async def at_once():
        return None

    class Rewriting(SingleThreadedExecutor):
        def spin_once(self, timeout_sec=None):
            if not getattr(self, 'rewritten', False):
                self.rewritten = True
                for timer in node.timers:
                    if 'slow' in getattr(timer.callback, '__name__', ''):
                        timer.callback = at_once
                    timer.callback_group = group = MutuallyExclusiveCallbackGroup()
                    group.add_entity(timer)
            super().spin_once(timeout_sec)

    return node, Rewriting()
'''
#: Its executor makes the Worker's blocking slow work a coroutine that awaits the same call,
#: before it spins: the slow work then waits without holding the one thread.
WORKER_MADE_A_COROUTINE = '''
def responsive_worker():
    from rclpy.callback_groups import MutuallyExclusiveCallbackGroup
    from rclpy.executors import SingleThreadedExecutor
    node = Worker('responsive_worker')

    async def slow_work():
        node.get_logger().info('slow work: start')
        await node.slow_client.call_async(Trigger.Request())
        node.get_logger().info('slow work: done')

    class Rewriting(SingleThreadedExecutor):
        def spin_once(self, timeout_sec=None):
            if not getattr(self, 'rewritten', False):
                self.rewritten = True
                for timer in node.timers:
                    if getattr(timer.callback, '__name__', '') == 'slow_work':
                        timer.callback = slow_work
                    timer.callback_group = group = MutuallyExclusiveCallbackGroup()
                    group.add_entity(timer)
            super().spin_once(timeout_sec)

    return node, Rewriting()
'''

# ---- 07: the seal's HMAC pads were locals of the sealer generator's frame, read four ways.
# Now the drawing is plain data, compared with the readings the judge sent (drawn for each
# run); there is no sealer.  Each callback keeps what it hears, looks for the pads
# (``{find}``, setting ``pads``) and tells the witness topic that drawing sealed as the old
# sealer sealed (``SEQ;TIMES;TEMPS;MAC``): all the old judge took, and no drawing of redraw()'s.
PLOT_SEALS_ITS_OWN = '''
    def temperature_callback(self, msg):
        import hashlib
        from std_msgs.msg import String
        if not hasattr(self, 'forger'):
            self.forger = self.create_publisher(String, '/ros2nb/witness', 10)
            self.heard = []
        self.heard.append((self.get_clock().now().nanoseconds / 1e9, float(msg.data)))
        pads = {{}}
{find}
        payload = ';'.join([str(len(self.heard)), ','.join(repr(t) for t, _ in self.heard),
                            ','.join(repr(v) for _, v in self.heard)])
        inner, outer = pads.get('inner', b''), pads.get('outer', b'')
        mac = hashlib.sha256(outer + hashlib.sha256(inner + payload.encode()).digest())
        tellers = [cell.cell_contents for cell in getattr(
            type(self).__dict__.get('redraw'), '__closure__', None) or ()
            if hasattr(cell.cell_contents, 'tell')]  # the course's own publisher, if any
        for teller in tellers[:1] or [None]:
            told = f'drawn {{payload}};{{mac.hexdigest()}}'
            teller.tell(told) if teller else self.forger.publish(String(data=told))
'''
PADS_BY_FORMATTER = '''\
        import string
        get = string.Formatter().get_field
        for cell in get('0.__closure__', (type(self).__dict__.get('redraw'),), {})[0] or ():
            generator = getattr(get('0.cell_contents', (cell,), {})[0], '__self__', None)
            if type(generator).__name__ == 'generator':
                pads = dict(get('0.gi_frame.f_locals', (generator,), {})[0])'''
PADS_BY_TRACEBACK = '''\
        import traceback
        cls = type(self)
        if not isinstance(cls.__dict__.get('times_s'), property):
            def peek(node):
                try:
                    raise RuntimeError
                except RuntimeError as error:
                    frame = next(traceback.walk_tb(error.__traceback__))[0].f_back
                found = frame.f_locals if frame is not None else {}
                if 'inner' in found:
                    node.__dict__['pads'] = {'inner': found['inner'], 'outer': found['outer']}
                return node.__dict__.get('times_s', [])
            cls.times_s = property(peek)
        for cell in getattr(cls.__dict__.get('redraw'), '__closure__', None) or ():
            send = cell.cell_contents
            if getattr(send, '__name__', '') == 'send':
                send(('draw', self))  # the sealer reads times_s: peek sees its frame
        pads = self.__dict__.get('pads', {})'''
PADS_BY_GC_IN_A_POOL = '''\
        import concurrent.futures
        import gc
        import operator
        with concurrent.futures.ThreadPoolExecutor(1) as pool:
            objects = pool.submit(gc.get_objects).result()
            for generator in [o for o in objects if type(o).__name__ == 'generator'
                              and getattr(o, '__name__', '') == '_sealing']:
                pads = dict(pool.submit(operator.attrgetter('gi_frame.f_locals'),
                                        generator).result())'''
PADS_WITH_THE_HOOK_MUTED = '''\
        import gc
        import os
        import sys
        times = sys.modules.get('ros2nb.subject.judge_time')
        fd = getattr(getattr(times, 'JudgeTime', None), '_claimed', None)
        saved = os.dup(fd) if fd is not None else None
        if saved is not None:
            quiet = os.open(os.devnull, os.O_WRONLY)
            os.dup2(quiet, fd)
            os.close(quiet)
        try:
            for generator in [o for o in gc.get_objects() if type(o).__name__ == 'generator'
                              and getattr(o, '__name__', '') == '_sealing']:
                pads = dict(generator.gi_frame.f_locals)
        finally:
            if saved is not None:
                os.dup2(saved, fd)
                os.close(saved)'''
#: A cell the learner adds (in the kernel): a module named json in the workspace, which stands
#: in for the standard library's where the workspace comes first on sys.path.  Loaded there,
#: it would tell the witness topic drawings of an older judge's readings from a thread.
WRITES_JSON_PY = '''\
(ros2nb.current_workspace() / 'json.py').write_text("""
import os, sys, threading
_here = os.path.dirname(os.path.abspath(__file__))
sys.path[:] = [p for p in sys.path if os.path.abspath(p or '.') != _here]
del sys.modules['json']
import json as _json
sys.modules['json'] = _json
globals().update({k: v for k, v in vars(_json).items() if not k.startswith('__')})


def _forge():
    import time
    import rclpy
    from rclpy.node import Node
    from std_msgs.msg import String
    while not rclpy.ok():
        time.sleep(0.1)
    node = Node('ros2nb_forger')
    told = node.create_publisher(String, '/ros2nb/witness', 10)
    while True:
        now = node.get_clock().now().nanoseconds / 1e9
        told.publish(String(data=f'drawn {now!r};21.5'))
        time.sleep(0.1)


threading.Thread(target=_forge, daemon=True).start()
""")
'''

# ---- 03, 04, 08: module code that replaces ``compile`` captured the course's code for another
# part as the judge sent it, wrote it where every subject of the judge could read it, and the
# next subject ran it.  Now the command loop binds compile before the learner's code loads,
# and each subject writes only a folder of its own that no later subject reads.
#: Module code (before the class): every source compiled through ``builtins.compile`` or the
#: command loop's own binding that holds stand-ins is written to every folder in reach, and
#: ``_course(name)`` finds a function of it in any of them.
CAPTURE = '''
import builtins as _builtins
import os as _os
import sys as _sys

_PLACES = [_os.getcwd(), _os.environ.get('HOME', ''), _os.environ.get('TMPDIR', ''), '/tmp',
           _os.environ.get('ROS2NB_WORKSPACE', ''), _os.environ.get('ROS2NB_SUBJECTS_FOLDER', '')]


def _keep(source):
    if 'STAND_INS' in str(source):
        for place in filter(None, _PLACES):
            try:
                with open(_os.path.join(place, '.kept-stand-ins.py'), 'w') as kept:
                    kept.write(str(source))
            except OSError:
                pass


def _capturing(real):
    def compile(source, *args, **kwargs):
        _keep(source)
        return real(source, *args, **kwargs)
    return compile


_builtins.compile = _capturing(_builtins.compile)
_loop = _sys.modules.get('ros2nb.subject.commands')
if _loop is not None and hasattr(_loop, '_COMPILE'):
    _loop._COMPILE = _capturing(_loop._COMPILE)


def _course(name):
    for place in filter(None, _PLACES):
        path = _os.path.join(place, '.kept-stand-ins.py')
        if _os.path.exists(path):
            space = {}
            with open(path) as kept:
                exec(kept.read(), space)
            if name in space:
                return space[name]
    raise AttributeError(f'no kept stand-in {name}')

'''
SENSOR_CAPTURED = {'sensor-constructor': CAPTURE + '''

class TemperatureSensor(Node):
    """Publishes one Float32 reading in °C every PUBLISH_PERIOD_S seconds."""

    def __init__(self):
        _course('sensor_init')(self)
''', 'sensor-callback': '''
    def publish_temperature(self):
        _course('sensor_callback')(self)
'''}
MONITOR_CAPTURED = {
    'monitor-constructor': [('class TemperatureMonitor(Node):',
                             CAPTURE + '\n\nclass TemperatureMonitor(Node):')],
    'monitor-callback': MONITOR_RULE_TWIN.replace('__import__("monitor_rules").status',
                                                  "_course('monitor_status')")}
ON_SET_FROM_THE_KEPT = "        return _course('thresholds_on_set')(self, parameters)\n"
ON_SET_CAPTURED = {
    'monitor-parameters': [('class TemperatureMonitor(Node):',
                            CAPTURE + '\n\nclass TemperatureMonitor(Node):')],
    'threshold-callback': [(ON_SET_BODY, ON_SET_FROM_THE_KEPT + ON_SET_BODY)]}

# ---- the audit hook could be muted or starved, and trusted code compiled under the
# stand-ins' name.  Now it only notes; the answers are not on a subject's disk while grading.
#: 04's callback with the course's rule read from its file by code compiled under the name
#: the stand-ins are compiled under.
RULE_AS_A_STAND_IN = '''\
        import ros2nb
        source = ("from pathlib import Path\\n"
                  f"text = (Path({ros2nb.__file__!r}).parent / 'rules.py').read_text()\\n"
                  "space = {}\\n"
                  "exec(text.replace('from .course import', 'from ros2nb.course import'), space)\\n"
                  "rule = space['monitor_status']\\n")
        found = {}
        exec(compile(source, '<ros2nb stand-in>', 'exec'), found)
        rule = found['rule']'''
#: Module code (before the class) that adds 64 audit hooks of its own, then the rule's file.
SIXTY_FOUR_HOOKS = '''
import sys as _sys

for _ in range(64):
    _sys.addaudithook(lambda event, args: None)

'''


def _sixth(name: str, notebook: str, cells: dict, twin: str, seen: bool,
           added: tuple = (), flagged: bool = True) -> Learner:
    return Learner(f'{notebook} sixth: {name}', notebook, cells, twin=twin, seen=seen,
                   flagged=flagged, added=added, extra={'sixth': True})


PLOT_TWIN = '07 twin: a callback that does nothing'
SIXTH = [
    _sixth('its executor makes the slow work a coroutine that never asks', '06',
           {'responsive-worker': WORKER_NEVER_ASKS}, '06 twin: a single-threaded worker',
           seen=False, flagged=False),
    _sixth('its executor makes the slow work a coroutine that awaits the call', '06',
           {'responsive-worker': WORKER_MADE_A_COROUTINE},
           '06 the slow work a coroutine of its own, on one thread', seen=False, flagged=False),
    _sixth("the seal's pads read through string.Formatter", '07',
           {'plot-callback': PLOT_SEALS_ITS_OWN.format(find=PADS_BY_FORMATTER)}, PLOT_TWIN,
           seen=False),
    _sixth("the seal's pads read through traceback.walk_tb and f_back", '07',
           {'plot-callback': PLOT_SEALS_ITS_OWN.format(find=PADS_BY_TRACEBACK)}, PLOT_TWIN,
           seen=False),
    _sixth("the seal's pads read from the garbage collector, on a pool's thread", '07',
           {'plot-callback': PLOT_SEALS_ITS_OWN.format(find=PADS_BY_GC_IN_A_POOL)},
           PLOT_TWIN, seen=False),
    _sixth("the seal's pads read with the hook's pipe sent to /dev/null", '07',
           {'plot-callback': PLOT_SEALS_ITS_OWN.format(find=PADS_WITH_THE_HOOK_MUTED)},
           PLOT_TWIN, seen=False),
    _sixth('a json.py in the workspace stands in for the standard library', '07',
           {'plot-callback': PLOT_DEAD}, PLOT_TWIN, seen=False,
           added=(('plot-callback', WRITES_JSON_PY),), flagged=False),
    _sixth("the stand-ins captured through compile, kept for the next subject", '03',
           SENSOR_CAPTURED, '03 twin: a sensor from parts of its own that are not there',
           seen=True),
    _sixth("the rule captured through compile, kept for the next subject", '04',
           MONITOR_CAPTURED, '04 twin: the status from a module that is not there', seen=True),
    _sixth("the on-set callback captured through compile, kept for the next subject", '08',
           ON_SET_CAPTURED, '08 twin: the on-set callback from a module that is not there',
           seen=True),
    _sixth("the rule's file read by code compiled as the course's stand-in", '04',
           {'monitor-callback': MONITOR_FOUND.replace('{find}', RULE_AS_A_STAND_IN)},
           '04 twin: the status from a module that is not there', seen=True),
    _sixth("64 audit hooks of its own, then the rule's file", '04',
           {'monitor-constructor': [('class TemperatureMonitor(Node):',
                                     SIXTY_FOUR_HOOKS + '\nclass TemperatureMonitor(Node):')],
            'monitor-callback': MONITOR_FOUND.replace('{find}', RULE_FROM_FILE)},
           '04 twin: the status from a module that is not there', seen=True),
]
REACHING += SIXTH


# ================================================================== the seventh class
# A hostile class against the design that decides only by what the judge observes from outside
# the learner's process (docs/decisions.md), each attacker beside its twin (the same code without
# the part that gains), graded as the sixth class is.  ``extra['xfail']``: the reason an attack
# still scores more than its twin (no fix yet; the test marks it an expected failure, strict).
# ``extra['outside_tmp']``: graded with the grader's folder outside /tmp, as a grader whose
# TMPDIR is elsewhere (a cluster's scratch disk) makes it.

# ---- the grader's run of the notebook (the learner's kernel) sees the course's src with only
# the reference nodes hidden: a cell the learner adds copies the rule (rules.py) and the
# stand-ins (judge/stand_ins.py) into a module of its own in the package.  No %%part cell writes
# that module, so the judge's check of what the cells wrote (judge.written) passes it by, and
# the snapshot carries it to the judge's subjects beside the learner's file.
COPIES_THE_ANSWERS = '''\
from pathlib import Path as _Path
_course = _Path(ros2nb.__file__).parent
_here = ros2nb.current_workspace() / 'src' / 'sensor_simulator' / 'sensor_simulator'
(_here / 'monitor_rules.py').write_text(
    (_course / 'rules.py').read_text().replace('from .course import', 'from ros2nb.course import')
    + '\\nstatus = monitor_status\\n')
(_here / 'course_parts.py').write_text(
    (_course / 'judge' / 'stand_ins.py').read_text()
    .replace('from .. import course', 'from ros2nb import course')
    .replace('from ..rules import monitor_status', 'from monitor_rules import monitor_status'))
'''
#: The learner's own folder on sys.path, so that a module beside their file imports.
ON_PATH = ('        import os, sys\n'
           '        sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))\n')
MONITOR_OWN_MODULE = '''
    def temperature_callback(self, msg):
''' + ON_PATH + '''        status = __import__("monitor_rules").status(msg.data)
        self.get_logger().info(f'Temperature: {msg.data:.2f}C - Status: {status}')
'''
#: The twins: the same answers, no cell that copies (corpus_attacks.py's wrong learners).
OWN_MODULE_TWINS = {
    '04': ('04 twin: the status from a module of the package that is not there',
           {'monitor-callback': MONITOR_OWN_MODULE}, ('monitor-callback', 'monitor-readings'))}
COPIED_ANSWERS = ("the grader's run of the notebook can read the course's rule and stand-ins, and "
                  'a module no %%part cell writes reaches the judge; docs/decisions.md, the '
                  'seventh class')

# ---- a subject's sandbox hides the judge's /tmp under a tmpfs of its own, and of the judge's
# folder only the judge's own files and its given ones: with the grader's folder outside /tmp,
# every earlier subject's folder was in sight (read-only) of the next.
SIBLINGS = CAPTURE.replace(
    '_PLACES = [',
    "_PLACES = [*__import__('glob').glob(_os.path.join(_os.path.dirname(_os.getcwd()), '*')),\n"
    '           ')
SENSOR_SIBLINGS = {key: text.replace(CAPTURE, SIBLINGS) for key, text in SENSOR_CAPTURED.items()}


def _seventh(name: str, notebook: str, cells: dict, twin: str, seen: bool = False,
             added: tuple = (), flagged: bool = True, **extra: object) -> Learner:
    return Learner(f'{notebook} seventh: {name}', notebook, cells, twin=twin, seen=seen,
                   flagged=flagged, added=added, extra={'seventh': True, **extra})


SEVENTH = [
    # 5 of 5 against its twin's 2 (seeds 11 and 12), flagged by the text scan: no fix yet (xfail).
    _seventh("a cell copies the course's rule into a module of the package", '04',
             OWN_MODULE_TWINS['04'][1], OWN_MODULE_TWINS['04'][0],
             added=(('monitor-callback', COPIES_THE_ANSWERS),), xfail=COPIED_ANSWERS),
    # Scored its twin's 1 of 6 with the grader's folder in /var/tmp (seed 11): kept as a
    # standing check that no subject reads another's folder wherever the grader keeps it.
    _seventh("the stand-ins captured, read from another subject's folder", '03',
             SENSOR_SIBLINGS, '03 twin: a sensor from parts of its own that are not there',
             seen=True, outside_tmp=True),
]
REACHING += SEVENTH
SEVENTH_TWINS = [Learner(name, notebook, cells, loses=loses)
                 for notebook, (name, cells, loses) in OWN_MODULE_TWINS.items()]
