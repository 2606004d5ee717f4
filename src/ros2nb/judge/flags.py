"""Flags for the instructor: learner code that reaches into the course or the process it runs in.

Part of the judge (:mod:`ros2nb.judge`); introduced with grading (``make grade``, see
``docs/grading.md``).  Points come only from what the judge observes (messages, ``/rosout``,
the graph, its own calls, exit codes).  Some tricks look the same on the wire as honest
code: a walk published from inside the course's runtime instead of a timer, entry points
a ``setup.py`` writes by hand.  Their code has to reach for things no lesson teaches: stack
frames, the garbage collector's objects, ``/proc``, ros2nb's internals, rclpy's classes
patched in place.  This module names each such place, so that the instructor can look;
a flag never changes a point (the grade is the judge's verdict alone).

Read as text only: nothing here runs the learner's code.
"""

from __future__ import annotations

import ast
from pathlib import Path
from typing import Any, Iterable, Optional

from IPython.core.inputtransformer2 import TransformerManager

from .. import course, nbmeta
from ..checks.source import TEXT
from ..subject.out_of_reach import ANSWERS

#: ``module.function`` calls that read or change other code's frames and objects.
REACHING_CALLS = {
    'sys._getframe': "reads the caller's stack frames",
    'sys.settrace': 'traces other code as it runs',
    'sys.setprofile': 'traces other code as it runs',
    'threading.settrace': 'traces other code as it runs',
    'inspect.currentframe': "reads the caller's stack frames",
    'inspect.stack': "reads the caller's stack frames",
    'inspect.getouterframes': "reads the caller's stack frames",
    'gc.get_objects': "walks every object of the process, the course's too",
    'gc.get_referrers': "walks other code's objects",
    'gc.get_referents': "walks other code's objects",
    'sys._current_frames': "reads every thread's stack frames",
}
#: Attributes that lead from a frame or traceback into another function's variables.
FRAME_ATTRIBUTES = {'f_back', 'f_locals', 'f_globals', 'tb_frame', 'gi_frame', 'cr_frame'}
#: Attributes that lead from an object to code and objects that are not its own: a
#: function's code, globals and closure, a class's subclasses.
REACHING_ATTRIBUTES = {'__code__': "a function's compiled code", '__globals__':
                       "a function's module", '__closure__': "a function's closure",
                       'cell_contents': "a function's closure", '__subclasses__':
                       "every class made from a class, the course's among them"}
#: Calls that set an attribute of an object named as their first argument.
SETTING_CALLS = {'setattr', 'type.__setattr__', 'object.__setattr__'}
#: Modules a lesson's answer never needs that reach below Python's objects, or import
#: modules by a name computed as the code runs (how the course's answers were reached).
RAW_MODULES = {'ctypes': 'reads or writes memory directly',
               'importlib': 'imports modules by a name it computes',
               'runpy': 'runs modules by a name it computes',
               'marshal': 'loads compiled code'}
#: Builtins that run code built as text at run time.
RUNNING_TEXT = {'exec', 'eval', 'compile'}
#: The process's own import machinery: the modules it imported (the course's too) and its finders.
REACHING_CALLS.update({
    'sys.modules': "reads the modules the process imported, the course's answers too",
    'sys.meta_path': 'changes how modules are found (the course refuses its answers there)',
    'sys.path_hooks': 'changes how modules are found (the course refuses its answers there)',
})
#: Names of the course's answers (ros2nb.subject.out_of_reach), in code or in a string.
ANSWER_NAMES = (*ANSWERS, 'stand_ins', 'monitor_status', 'ros2nb.reference')
#: ros2nb's own parts a learner's code never uses (the lessons use the top-level
#: functions and ``ros2nb.course``): the runtime, the judge and its subjects, the checks.
INTERNAL = {'runtime', 'subject', 'judge', 'checks', 'processes', 'explain', 'kernel',
            'nbmeta', 'endpoints', 'reference', 'current_runtime', 'rules'}
#: Modules and classes whose attributes an answer never replaces.
PATCHED_OWNERS = {'rclpy', 'ros2nb', 'builtins', 'sys', 'Node', 'Publisher', 'Subscription',
                  'Timer', 'Executor', 'SingleThreadedExecutor', 'MultiThreadedExecutor'}
#: Calls that write files: in ``setup.py`` they make by hand what colcon makes from it.
WRITING_CALLS = {'write_text', 'write_bytes', 'chmod', 'symlink', 'copyfile', 'copy',
                 'copy2', 'makedirs', 'mkdir'}
#: The package's files read at most (the first, in name order), and their largest size (bytes):
#: the package of the lessons has a handful of small files.
MAX_FILES, MAX_FILE_BYTES = 50, 1_000_000


def _dotted(node: ast.AST) -> Optional[str]:
    """``a.b.c`` for a chain of names and attributes, else None."""
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return None
    parts.append(node.id)
    return '.'.join(reversed(parts))


def _module_names(tree: ast.AST) -> dict[str, str]:
    """Local name -> module it stands for, from ``import`` statements (``import gc as g``)."""
    names = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                names[alias.asname or alias.name.split('.')[0]] = \
                    alias.name if alias.asname else alias.name.split('.')[0]
        elif isinstance(node, ast.ImportFrom) and node.module:
            for alias in node.names:
                names[alias.asname or alias.name] = f'{node.module}.{alias.name}'
    return names


def _internal(module: str) -> bool:
    parts = module.split('.')
    return parts[0] == 'ros2nb' and len(parts) > 1 and parts[1] in INTERNAL


def _answer(name: str) -> bool:
    """Whether a dotted name or a string names one of the course's answers."""
    return any(part in name for part in ANSWER_NAMES)


def _folded(node: ast.AST) -> Optional[str]:
    """The text a string expression made of constant pieces stands for (``'a.' + 'b'``,
    ``f'{"a"}b'``, ``''.join(['a', 'b'])``), else None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        left, right = _folded(node.left), _folded(node.right)
        return None if left is None or right is None else left + right
    if isinstance(node, ast.JoinedStr):
        pieces = [_folded(v.value if isinstance(v, ast.FormattedValue) else v)
                  for v in node.values]
        known = [piece for piece in pieces if piece is not None]
        return None if len(known) != len(pieces) else ''.join(known)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and \
            node.func.attr == 'join' and len(node.args) == 1 and \
            isinstance(node.args[0], (ast.List, ast.Tuple)):
        glue = _folded(node.func.value)
        pieces = [_folded(e) for e in node.args[0].elts]
        known = [piece for piece in pieces if piece is not None]
        return None if glue is None or len(known) != len(pieces) else glue.join(known)
    return None


def _named(text: str) -> Optional[str]:
    """What a string names that reaches in: one of the course's answers, or an attribute
    or function that leads into other code (``getattr(f, '__glo' + 'bals__')``)."""
    if _answer(text):
        return f"names {text[:60]!r} (the course's answer, refused to graded code)"
    last = text.rsplit('.', 1)[-1]
    if last in REACHING_ATTRIBUTES or last in FRAME_ATTRIBUTES:
        return f'names {last!r} in a string (reads {REACHING_ATTRIBUTES.get(last, "a frame")})'
    if text in REACHING_CALLS or any(call.endswith('.' + text) for call in REACHING_CALLS
                                     if text.startswith(('_get', 'get_'))):
        return f'names {text!r} in a string (reads other code\'s frames and objects)'
    return None


def _import_why(node: ast.Import | ast.ImportFrom) -> Optional[str]:
    """What an import statement reaches for, or None."""
    names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
        [f'{node.module}.{a.name}' for a in node.names] if node.module else []
    for name in names:
        if name.split('.')[0] in RAW_MODULES:
            return f'imports {name} ({RAW_MODULES[name.split(".")[0]]})'
        if _internal(name):
            return f"imports {name} (ros2nb's internals)"
        if name.startswith('ros2nb.') and _answer(name):
            return f"imports {name} (the course's answer, refused to graded code)"
    return None


def _why(node: ast.AST, modules: dict[str, str], setup_py: bool) -> Optional[str]:
    """What ``node`` reaches for, or None."""
    if isinstance(node, (ast.Constant, ast.BinOp, ast.JoinedStr, ast.Call)):
        text = _folded(node)
        if text is not None and _named(text):
            return _named(text)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
            node.func.id in RUNNING_TEXT:
        return f'calls {node.func.id} (runs code it builds at run time)'
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
            node.func.id == '__import__' and not (
                node.args and isinstance(node.args[0], ast.Constant)):
        return 'calls __import__ with a name it computes (imports modules by a computed name)'
    if isinstance(node, (ast.Import, ast.ImportFrom)):
        return _import_why(node)
    if isinstance(node, ast.Attribute) and node.attr in FRAME_ATTRIBUTES:
        return f'reads .{node.attr} (another function\'s frame)'
    if isinstance(node, ast.Attribute) and node.attr in REACHING_ATTRIBUTES:
        return f'reads .{node.attr} ({REACHING_ATTRIBUTES[node.attr]})'
    if isinstance(node, (ast.Attribute, ast.Name)):
        dotted = _dotted(node)
        if dotted is not None:
            head, _, rest = dotted.partition('.')
            full = f'{modules.get(head, head)}.{rest}' if rest else modules.get(head, head)
            if full in REACHING_CALLS:
                return f'uses {full} ({REACHING_CALLS[full]})'
            if _internal(full) and full.count('.') == 1:
                return f"uses {full} (ros2nb's internals)"
            if full.startswith('ros2nb.') and _answer(full) and isinstance(node, ast.Attribute):
                return f"uses {full} (the course's answer, refused to graded code)"
        return None
    if isinstance(node, ast.Constant) and isinstance(node.value, str) and \
            (node.value == '/proc' or node.value.startswith('/proc/')):
        return "reads /proc (other processes' files)"
    if isinstance(node, (ast.Assign, ast.AugAssign)):
        targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        for target in targets:
            if isinstance(target, ast.Attribute):
                owner = _dotted(target.value)
                if owner is not None and (owner.split('.')[0] in PATCHED_OWNERS or
                                          owner.split('.')[0] in modules):
                    return f'replaces {owner}.{target.attr} (patches code that is not its own)'
        return None
    if isinstance(node, ast.Call):
        name = _dotted(node.func) or (node.func.attr if isinstance(node.func, ast.Attribute)
                                      else '')
        owner = _dotted(node.args[0]) if name in SETTING_CALLS and node.args else None
        if owner is not None and (owner.split('.')[0] in PATCHED_OWNERS | set(modules) or (
                name != 'setattr' and owner not in ('self', 'cls'))):
            return f'replaces an attribute of {owner} (patches code that is not its own)'
        if setup_py and (name.rsplit('.', 1)[-1] in WRITING_CALLS or (
                name == 'open' and any(isinstance(a, ast.Constant) and isinstance(a.value, str)
                                       and set(a.value) & set('wax') for a in node.args[1:2]))):
            return (f'calls {name} in setup.py (writes files itself; colcon makes the '
                    'executables from the entry points)')
    return None


def reaching_in(text: str, where: str, setup_py: bool = False) -> list[str]:
    """The flags of one piece of the learner's Python: ``'<where> line N: <what>'`` each.

    :param text: Python source (a file, or a cell already turned into Python).
    :param where: how the note names it (``temperature_publisher.py``, ``answer cell 03-...``).
    :param setup_py: the text is a ``setup.py`` (file writes are flagged too).
    :return: one flag per line and kind, in line order; none for text that does not parse.
    """
    try:
        tree = ast.parse(text)
    except (SyntaxError, ValueError):
        return []
    modules = _module_names(tree)
    found: dict[tuple[int, str], None] = {}
    for node in ast.walk(tree):
        why = _why(node, modules, setup_py)
        if why is not None:
            found[(getattr(node, 'lineno', 0), why)] = None
    return [f'{where} line {line}: {why}' for line, why in sorted(found)]


def _python_of_cell(text: str, parts: bool) -> Optional[str]:
    """A code cell as Python (IPython's own transformation; with ``parts``, a ``%%part``
    cell's body), or None for a cell magic or text IPython cannot read (an answer's
    ``%%part`` cell is read in the file it wrote)."""
    if text.lstrip().startswith('%%'):
        first, _, body = text.lstrip().partition('\n')
        return body if parts and first.startswith('%%part') else None
    try:
        return TransformerManager().transform_cell(text)
    except Exception:  # noqa: BLE001 - IPython could not read it: nothing to flag
        return None


def notebook_flags(submission: dict[str, Any], workspace: Path,
                   source: Optional[dict[str, Any]] = None) -> list[str]:
    """Every flag of a submitted notebook: its answer cells, every code cell the learner
    added or changed (one the course's ``source`` notebook does not have; a graded cell may
    lack its hidden tests), and the package files its ``%%part`` cells write in
    ``workspace``.  What a cell of the course's
    own does (``ros2nb.current_runtime()`` in a cell that shows the graph) is not flagged in
    a cell the learner changed.

    :param submission: the learner's notebook (nbformat JSON).
    :param workspace: the learner's workspace (``src/sensor_simulator`` is read).
    :param source: the course's notebook (nbformat JSON); None: only the answer cells.
    :return: flags as :func:`reaching_in` words them (empty for honest code).
    """
    given = {nbmeta.text(cell): nbmeta.nbgrader_metadata(cell).get('grade_id')
             for cell in nbmeta.cells(source or {}) if cell.get('cell_type') == 'code'}
    lines_of = {grade_id: set(text.splitlines()) for text, grade_id in given.items() if grade_id}
    course_does = {flag.partition(': ')[2] for text in given
                   for flag in reaching_in(_python_of_cell(text, parts=True) or '', '')}
    flags = []
    for index, cell in enumerate(nbmeta.cells(submission)):
        meta, text = nbmeta.nbgrader_metadata(cell), nbmeta.text(cell)
        if cell.get('cell_type') != 'code':
            continue
        if meta.get('solution'):
            flags += reaching_in(_python_of_cell(text, parts=False) or '',
                                 f'answer cell {meta.get("grade_id", "?")}')
        elif source is not None and text not in given and not (  # a graded cell, tests hidden
                set(text.splitlines()) <= lines_of.get(str(meta.get('grade_id')), set())):
            found = reaching_in(_python_of_cell(text, parts=True) or '',
                                f"cell {index + 1} (not the course's)")
            flags += [flag for flag in found if flag.partition(': ')[2] not in course_does]
    flags += package_flags(workspace)
    return flags


def package_flags(workspace: Path) -> list[str]:
    """The flags of the Python files of the learner's package (``src/sensor_simulator``)."""
    package = workspace / 'src' / course.PACKAGE
    flags = []
    for path in sorted(_python_files(package)):
        text = TEXT.read(path)
        if text is not None:
            flags += reaching_in(text, str(path.relative_to(workspace)),
                                 setup_py=path.name == 'setup.py')
    return flags


def _python_files(package: Path) -> Iterable[Path]:
    """The package's own ``.py`` files (no links, none too large), at most :data:`MAX_FILES`."""
    if not package.is_dir() or package.is_symlink():
        return []
    found = []
    for path in package.rglob('*.py'):
        if path.is_file() and not path.is_symlink() and path.stat().st_size <= MAX_FILE_BYTES:
            found.append(path)
            if len(found) >= MAX_FILES:
                break
    return found
