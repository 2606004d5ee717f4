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
from typing import Iterable, Optional

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
}
#: Attributes that lead from a frame or traceback into another function's variables.
FRAME_ATTRIBUTES = {'f_back', 'f_locals', 'f_globals', 'tb_frame', 'gi_frame', 'cr_frame'}
#: Modules a lesson's answer never needs that reach below Python's objects, or import
#: modules by a name computed as the code runs (how the course's answers were reached).
RAW_MODULES = {'ctypes': 'reads or writes memory directly',
               'importlib': 'imports modules by a name it computes',
               'runpy': 'runs modules by a name it computes'}
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


def _why(node: ast.AST, modules: dict[str, str], setup_py: bool) -> Optional[str]:
    """What ``node`` reaches for, or None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str) and _answer(node.value):
        return f'names {node.value[:60]!r} (the course\'s answer, refused to graded code)'
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
            node.func.id == '__import__' and not (
                node.args and isinstance(node.args[0], ast.Constant)):
        return 'calls __import__ with a name it computes (imports modules by a computed name)'
    if isinstance(node, (ast.Import, ast.ImportFrom)):
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
    if isinstance(node, ast.Attribute) and node.attr in FRAME_ATTRIBUTES:
        return f'reads .{node.attr} (another function\'s frame)'
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
        owner = _dotted(node.args[0]) if name == 'setattr' and node.args else None
        if owner is not None and owner.split('.')[0] in PATCHED_OWNERS | set(modules):
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


def _python_of_cell(text: str) -> Optional[str]:
    """An answer cell as Python (IPython's own transformation), or None for a ``%%`` cell
    (a ``%%part`` cell's text is checked in the file it wrote)."""
    if text.lstrip().startswith('%%'):
        return None
    try:
        return TransformerManager().transform_cell(text)
    except Exception:  # noqa: BLE001 - IPython could not read it: nothing to flag
        return None


def notebook_flags(submission: dict, workspace: Path) -> list[str]:
    """Every flag of a submitted notebook: its answer cells, and the package files its
    ``%%part`` cells write in ``workspace``.

    :param submission: the learner's notebook (nbformat JSON).
    :param workspace: the learner's workspace (``src/sensor_simulator`` is read).
    :return: flags as :func:`reaching_in` words them (empty for honest code).
    """
    flags = []
    for cell in nbmeta.cells(submission):
        meta = nbmeta.nbgrader_metadata(cell)
        if meta.get('solution') and cell.get('cell_type') == 'code':
            python = _python_of_cell(nbmeta.text(cell))
            if python is not None:
                flags += reaching_in(python, f'answer cell {meta.get("grade_id", "?")}')
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
