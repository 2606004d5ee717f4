"""What the learner's code reaches for in a subject, noted as it runs (a CPython audit hook).

Part of :mod:`ros2nb.subject`; introduced with grading (``docs/instructors.md``).  A detector,
never a barrier: no check relies on it, and its silence proves nothing (CPython's own
documentation says audit hooks are no sandbox; code can read, replace or mute anything in its
own process).  What decides a point is observed from outside this process
(docs/decisions.md); this only tells the instructor what the learner's code reached for.

Before the learner's code is loaded, the subject installs an audit hook (PEP 578,
``sys.addaudithook``: no Python code can remove it).  The hook watches the events that reach
into the course or into the process: stack frames, the garbage collector's objects, a
function's code, the course's answer files and modules, code compiled or loaded at run time,
raw memory (``ctypes``), other processes, audit hooks of its own.  Each event the learner's
code caused is written at once, as one line, on the judge's pipe (the one the runtime
acknowledges the judge's clock on); the judge turns each into a note for the instructor
(:mod:`ros2nb.judge.reaching`).  Every event is counted: a kind's first :data:`PER_KIND`
places are written, then its count at each power of two, so that code that floods one kind
mutes no other; the subject's last line (:data:`END`, written by its command loop as it
ends) gives every count, and a subject that ended without it had its channel closed or
redirected, which is itself a note.

Whose code caused an event is read off the stack: a frame is the learner's unless its file is
the Python installation's, the venv's, ros2nb's own or the course's stand-ins.  An event a
library raises on the learner's behalf (rclpy's logger reading its caller's frame, a
``namedtuple`` naming its module) is the library's; the few modules that hand frames or code
to their caller (``inspect``, ``dis``, ``traceback``'s stack walks, ``logging.currentframe``,
``ctypes``) pass it on to theirs.  The hook keeps what it uses in its own closures, bound
before the learner's code runs, so that replacing a name later changes nothing it sees.
"""

from __future__ import annotations

import os
import sys
import threading
import traceback
from pathlib import Path
from typing import Any, Callable, Optional

from .out_of_reach import ANSWERS

#: How a line starts on the judge's pipe (the runtime's acknowledgements are JSON objects).
MARK = 'SEEN'
#: The file name the stand-ins' code is compiled under (:mod:`.commands`): the course's.
STAND_IN_FILE = '<ros2nb stand-in>'
#: Places written at most per kind (each kind, event and place once): a loop that walks the
#: garbage collector in every callback must not fill the judge's pipe, and code that floods
#: one kind (64 audit hooks of its own) must not use up what another kind is told with.
PER_KIND = 8
#: The second field of a line that counts a kind's events past :data:`PER_KIND` (its total
#: so far, at each power of two), and of the last line, every kind's total.
COUNT, END = 'count', 'end'
#: Restricted attributes whose reading raises ``object.__getattr__`` (CPython 3.11).
CODE_ATTRIBUTES = frozenset({'__code__', 'f_code', 'gi_code', 'cr_code', 'ag_code', 'tb_frame',
                             'gi_frame', 'cr_frame', 'ag_frame'})
#: Events whose cause is the innermost frame (passed on by the modules that forward frames).
FRAME_EVENTS = {'sys._getframe': 'frames', 'sys._current_frames': 'frames',
                'sys.settrace': 'frames', 'sys.setprofile': 'frames'}
#: Events whose cause is the frame that called them.
COMPILE_EVENTS = {'compile': 'compiled', 'exec': 'compiled', 'marshal.loads': 'compiled',
                  'marshal.load': 'compiled', 'code.__new__': 'compiled',
                  'function.__new__': 'compiled'}
#: Events caused by the learner's code whenever any frame of theirs is on the stack.
ANY_EVENTS = {'gc.get_objects': 'objects', 'gc.get_referrers': 'objects',
              'gc.get_referents': 'objects', 'subprocess.Popen': 'processes',
              'os.system': 'processes', 'os.exec': 'processes', 'os.posix_spawn': 'processes',
              'os.spawn': 'processes', 'os.fork': 'processes', 'os.forkpty': 'processes',
              'pty.spawn': 'processes', 'sys.addaudithook': 'hooks'}
#: Events on a path: the course's answer files (opened or listed).
PATH_EVENTS = frozenset({'open', 'os.listdir', 'os.scandir', 'glob.glob'})
#: Every event the hook looks at (and ``ctypes.*``).
WATCHED = frozenset({*FRAME_EVENTS, *COMPILE_EVENTS, *ANY_EVENTS, *PATH_EVENTS, 'import',
                     'object.__getattr__'})


def course_folders() -> tuple[Path, ...]:
    """ros2nb's own folder and the Python installation's (their code is not the learner's)."""
    own = Path(__file__).resolve().parent.parent
    return tuple(sorted({own, *(Path(p).resolve() for p in (sys.prefix, sys.base_prefix,
                                                            sys.exec_prefix))}))


def answer_paths() -> tuple[Path, ...]:
    """Where the course's answers (:data:`.out_of_reach.ANSWERS`) are on this machine's disk,
    as path prefixes: each module's file or folder, its compiled forms, and the course's
    solutions."""
    top = Path(__file__).resolve().parent.parent.parent
    found = []
    for name in ANSWERS:
        *parents, last = name.split('.')
        found += [top.joinpath(*parents, last), top.joinpath(*parents, '__pycache__', last + '.')]
    return (*found, top.parent / 'solutions')


def _file_of(module: str) -> str:
    """The file of a standard module (imported here, before the learner's code)."""
    return getattr(__import__(module), '__file__', None) or os.devnull


def _attribution() -> tuple[Callable[[Any], bool], Callable[..., Any], Callable[[Any], Any]]:
    """Whose frame: ``learners(frame)``, ``innermost(frame, forwarding)`` (the frame that asked,
    past the modules that forward), ``anyone(frame)`` (the learner's frame nearest, if any,
    before the course's own code: what the course's code asks of a library is the course's,
    and the frames below the subject's command loop, which started it, are nobody's)."""
    trusted = tuple(str(p) + os.sep for p in course_folders())
    course = str(Path(__file__).resolve().parent.parent) + os.sep
    stand_in, frozen = STAND_IN_FILE, '<frozen '
    logging_file, passing = _file_of('logging'), frozenset({'currentframe', '<lambda>'})

    def learners(frame: Any) -> bool:
        name = frame.f_code.co_filename
        return not (name.startswith(trusted) or name.startswith(frozen) or name == stand_in)

    def innermost(frame: Any, forwarding: frozenset[str]) -> Any:
        while frame is not None and frame.f_code.co_filename in forwarding and not (
                frame.f_code.co_filename == logging_file and frame.f_code.co_name not in passing):
            frame = frame.f_back
        return frame

    def anyone(frame: Any) -> Any:
        while frame is not None and not learners(frame):
            if frame.f_code.co_filename.startswith(course):
                return None
            frame = frame.f_back
        return frame

    return learners, innermost, anyone


def _teller(write: Callable[[str], Any]) -> tuple[Callable[[str, str, Any], None],
                                                  Callable[[], None]]:
    """``tell(kind, what, frame)``: count the event; write one line on the judge's pipe once
    per kind, event and place, for the first :data:`PER_KIND` places of each kind, then the
    kind's count at each power of two.  ``end()``: the last line, every kind's count."""
    written: set[tuple[str, str, str]] = set()
    places: dict[str, int] = {}
    counts: dict[str, int] = {}
    mark, limit, cut, count_mark, end_mark = MARK, PER_KIND, 300, COUNT, END

    def line(*parts: str) -> None:
        write('\t'.join(part.replace('\t', ' ').replace('\n', ' ')[:cut]
                        for part in (mark, *parts)) + '\n')

    def tell(kind: str, what: str, frame: Any) -> None:
        total = counts[kind] = counts.get(kind, 0) + 1
        where = f'{frame.f_code.co_filename} line {frame.f_lineno}' if frame is not None else ''
        key = (kind, what, where)
        if key not in written and places.get(kind, 0) < limit:
            written.add(key)
            places[kind] = places.get(kind, 0) + 1
            line(kind, what, where)
        elif total > limit and total & (total - 1) == 0:
            line(count_mark, kind, str(total))

    def end() -> None:
        line(end_mark, ','.join(f'{kind}={total}' for kind, total in counts.items()), '')

    return tell, end


def _examiner(tell: Callable[[str, str, Any], None]
              ) -> Callable[[str, tuple[Any, ...], Any], None]:
    """``examine(event, args, caller)``: whether the learner's code caused a watched event,
    and if so, tell it."""
    learners, innermost, anyone = _attribution()
    frames, code = frozenset({_file_of('inspect'), _file_of('traceback'), _file_of('logging')}), \
        frozenset({_file_of('inspect'), _file_of('dis')})
    ctypes_folder = str(Path(_file_of('ctypes')).parent) + os.sep
    frame_events, compile_events, any_events = dict(FRAME_EVENTS), dict(COMPILE_EVENTS), \
        dict(ANY_EVENTS)
    code_attributes, path_events, answers = CODE_ATTRIBUTES, PATH_EVENTS, ANSWERS
    places = tuple(str(p) for p in answer_paths())
    realpath, fspath, fsdecode, length, instance, anything = os.path.realpath, os.fspath, \
        os.fsdecode, len, isinstance, any
    path_types = (str, bytes, os.PathLike)

    def examine(event: str, args: tuple[Any, ...], caller: Any) -> None:
        if event in frame_events:
            frame = innermost(caller, frames)
            if frame is not None and learners(frame):
                tell(frame_events[event], event, frame)
        elif event == 'object.__getattr__':
            frame = innermost(caller, code)
            if length(args) > 1 and args[1] in code_attributes and frame is not None and \
                    learners(frame):
                tell('code', f'.{args[1]}', frame)
        elif event in compile_events:
            if caller is not None and learners(caller):
                tell(compile_events[event], event, caller)
        elif event in any_events:
            frame = anyone(caller)
            if frame is not None:
                tell(any_events[event], event, frame)
        elif event.startswith('ctypes.'):
            frame = caller
            while frame is not None and frame.f_code.co_filename.startswith(ctypes_folder):
                frame = frame.f_back
            if frame is not None and learners(frame):
                tell('memory', event, frame)
        elif event == 'import':
            name = args[0] if args and instance(args[0], str) else ''
            if anything(name == a or name.startswith(a + '.') for a in answers):
                tell('answer_module', name, anyone(caller))
        elif event in path_events and args and instance(args[0], path_types):
            path = realpath(fsdecode(args[0]) if instance(args[0], bytes) else fspath(args[0]))
            if path.startswith(places):
                tell('answer_file', path, anyone(caller))

    return examine


def make_hook(write: Callable[[str], Any]) -> tuple[Callable[[str, tuple[Any, ...]], None],
                                                    Callable[[], None]]:
    """The audit hook, writing each event the learner's code caused with ``write``, and the
    function that writes the last line (every kind's count)."""
    tell, end = _teller(write)
    examine, getframe, attribute = _examiner(tell), sys._getframe, getattr
    watched, busy = WATCHED, threading.local()

    def hook(event: str, args: tuple[Any, ...]) -> None:
        if event not in watched and not event.startswith('ctypes.'):
            return
        if attribute(busy, 'on', False):
            return
        busy.on = True
        try:
            examine(event, args, getframe(1))
        except Exception:  # noqa: BLE001 - a hook that raises would break the audited call
            pass
        finally:
            busy.on = False

    return hook, end


def install(fd: Optional[int]) -> Callable[[], None]:
    """Install the hook, writing to the judge's pipe ``fd`` (nothing when this process has
    none: a subject started by hand).  Call it before the learner's code is loaded.

    :return: what writes the last line (:data:`END`), called as the subject ends.
    """
    if fd is None:
        return lambda: None
    write, encode = os.write, str.encode

    def send(line: str) -> None:
        try:
            write(fd, encode(line, 'utf-8', 'backslashreplace'))
        except OSError:
            pass  # the judge went away, or the code closed the pipe (the judge notes that)

    hook, end = make_hook(send)
    sys.addaudithook(hook)
    # CPython's own report of an exception it cannot raise (a __del__ of rclpy's, on an object
    # the learner's call left half made) compiles rclpy's source line from C, with the
    # learner's frame on top: the hook would tell that as the learner's compile.  Python's
    # traceback module reports it the same, and compiles from its own frames.
    sys.unraisablehook = _report_unraisable
    return end


def _report_unraisable(unraisable: Any) -> None:
    """Print an exception Python could not raise as CPython does, from Python's frames."""
    message = unraisable.err_msg or 'Exception ignored in'
    print(f'{message}: {unraisable.object!r}', file=sys.stderr)
    traceback.print_exception(unraisable.exc_type, unraisable.exc_value,
                              unraisable.exc_traceback, file=sys.stderr)
