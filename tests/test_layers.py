"""The layout says where code runs: imports go one way, down the layers, and never in a circle.

The layers are declared once, here (:data:`LAYERS`), and drawn in docs/architecture.md.
Every import statement of ``src/`` counts, also one inside a function: an import placed in
a function to dodge a circle is still a circle.  Each failure names the two modules.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Iterator, Optional

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / 'src'
ARCHITECTURE = ROOT / 'docs' / 'architecture.md'

#: Bottom first.  A module belongs to the longest prefix listed; it may import modules of
#: its own layer (no circles) and of the layers below, never of a layer above.
LAYERS: list[tuple[str, ...]] = [
    # ros2nb: the learner's kernel; the judge and its subjects reuse the lower layers.
    ('ros2nb.errors', 'ros2nb.patience', 'ros2nb.processes', 'ros2nb.temporary',
     'ros2nb.endpoints', 'ros2nb.nbmeta',
     'ros2nb.on_first_use', 'ros2nb.typed_json', 'ros2nb.working', 'ros2nb.unfinished',
     'ros2nb.graded_parts', 'ros2nb.hand_ins', 'ros2nb.outcomes'),
    ('ros2nb.domains',),
    ('ros2nb.terminal.workspace',),
    ('ros2nb.terminal.files', 'ros2nb.terminal.colcon', 'ros2nb.terminal.pkg_templates'),
    ('ros2nb.terminal.pkg_create',),
    ('ros2nb.course',),
    ('ros2nb.rules',),
    ('ros2nb.explain', 'ros2nb.figures'),
    ('ros2nb.runtime', 'ros2nb.qos', 'ros2nb.qos_profiles'),
    ('ros2nb.terminal',),
    ('ros2nb.kernel',),
    ('ros2nb.judge_interface', 'ros2nb.subject_interface', 'ros2nb.subject_replies'),
    ('ros2nb.checks',),
    ('ros2nb.subject',),
    ('ros2nb.judge',),
    ('ros2nb',),
    # ros2nb_instructor: the instructor's host (and, for the runner, the learner's sandbox).
    ('ros2nb_instructor.paths',),
    ('ros2nb_instructor.grading.sandboxed',),
    # grading, one room per role, in the order a notebook goes through them: what was taken
    # in, the sandboxes, a learner run and judged, the pages and files for people, nbgrader.
    ('ros2nb_instructor.grading.intake',),
    ('ros2nb_instructor.grading.sandbox',),
    ('ros2nb_instructor.grading.judging',),
    ('ros2nb_instructor.grading.reports', 'ros2nb_instructor.grading.export'),
    ('ros2nb_instructor.grading.scores',),
    ('ros2nb_instructor.grading.cluster',),
    ('ros2nb_instructor.grading', 'ros2nb_instructor.authoring', 'ros2nb_instructor.hub',
     'ros2nb_instructor.lab'),
    ('ros2nb_instructor',),
]
#: Largest module and function, in lines (docstrings included).
MAX_MODULE_LINES, MAX_FUNCTION_LINES = 400, 60


def module_name(path: Path, root: Path) -> str:
    """``src/ros2nb/checks/base.py`` -> ``ros2nb.checks.base``; a package's ``__init__`` is it."""
    parts = list(path.relative_to(root).with_suffix('').parts)
    return '.'.join(parts[:-1] if parts[-1] == '__init__' else parts)


def imports(name: str, source: str, is_package: bool, known: set[str]) -> Iterator[str]:
    """Every module of ``known`` that module ``name`` imports, anywhere in its source."""
    package = name if is_package else name.rpartition('.')[0]
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ''
            if node.level:
                anchor = package.split('.')[:len(package.split('.')) - node.level + 1]
                base = '.'.join(anchor + ([node.module] if node.module else []))
            targets = [f'{base}.{alias.name}' if f'{base}.{alias.name}' in known else base
                       for alias in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:  # `import a.b.c` of a package a.b
                target = target.rpartition('.')[0]
            if target and target != name:
                yield target


def layer_of(name: str, layers: list[tuple[str, ...]]) -> Optional[int]:
    """The index of the layer whose longest listed prefix ``name`` has; None when none does."""
    best: Optional[tuple[int, int]] = None
    for index, prefixes in enumerate(layers):
        for prefix in prefixes:
            if (name == prefix or name.startswith(prefix + '.')) and \
                    (best is None or len(prefix) > best[1]):
                best = (index, len(prefix))
    return best[0] if best else None


def graph_of(sources: dict[str, tuple[str, bool]]) -> dict[str, set[str]]:
    """Module -> the modules it imports, for ``{module: (source, is_package)}``."""
    known = set(sources)
    return {name: set(imports(name, source, is_package, known))
            for name, (source, is_package) in sources.items()}


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The import circles (strongly connected components of more than one module)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    found: list[list[str]] = []

    def visit(node: str) -> None:  # Tarjan's algorithm
        index[node] = low[node] = len(index)
        stack.append(node)
        for target in sorted(graph.get(node, ())):
            if target not in index:
                visit(target)
                low[node] = min(low[node], low[target])
            elif target in stack:
                low[node] = min(low[node], index[target])
        if low[node] == index[node]:
            component = []
            while True:
                member = stack.pop()
                component.append(member)
                if member == node:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for node in sorted(graph):
        if node not in index:
            visit(node)
    return found


def problems(sources: dict[str, tuple[str, bool]], layers: list[tuple[str, ...]]) -> list[str]:
    """One line per module in no layer, per upward import and per circle, naming the modules."""
    graph = graph_of(sources)
    found = [f'{name} is in no layer: add it to LAYERS' for name in sorted(graph)
             if layer_of(name, layers) is None]
    for name in sorted(graph):
        for target in sorted(graph[name]):
            mine, theirs = layer_of(name, layers), layer_of(target, layers)
            if mine is not None and theirs is not None and theirs > mine:
                found.append(f'{name} imports {target}, a layer above it')
    for circle in cycles(graph):
        pairs = [f'{a} -> {b}' for a in circle for b in sorted(graph[a]) if b in circle]
        found.append(f'import circle: {", ".join(pairs)}')
    return found


def tree_sources(root: Path = SRC) -> dict[str, tuple[str, bool]]:
    """``{module: (source, is_package)}`` for every module under ``src/``."""
    return {module_name(path, root): (path.read_text(), path.name == '__init__.py')
            for path in sorted(root.rglob('*.py'))}


# ----------------------------------------------------------------------------- tests
def test_imports_run_down_the_layers_with_no_circle():
    assert problems(tree_sources(), LAYERS) == []


def test_a_planted_circle_and_an_upward_import_are_named():
    """The check itself can fail: a circle held together by an import inside a function."""
    planted = {
        'pkg': ('', True),
        'pkg.low': ('from . import high\n', False),
        'pkg.high': ('def later():\n    from .low import helper\n', False),
    }
    layers = [('pkg.low',), ('pkg.high',), ('pkg',)]
    assert problems(planted, layers) == [
        'pkg.low imports pkg.high, a layer above it',
        'import circle: pkg.high -> pkg.low, pkg.low -> pkg.high']


def test_a_grading_room_that_imports_a_later_one_is_named():
    """The grading's rooms are layers too: taken in, sandboxed, judged, scored.  A module of
    the intake that reached for the sandbox, or the sandbox for the judging, is named."""
    sources = tree_sources()
    sources['ros2nb_instructor.grading.intake.planted'] = (
        'from ..sandbox import bubblewrap\n', False)
    sources['ros2nb_instructor.grading.sandbox.planted_too'] = (
        'def later():\n    from ..judging.learners import Graded\n', False)
    assert problems(sources, LAYERS) == [
        'ros2nb_instructor.grading.intake.planted imports '
        'ros2nb_instructor.grading.sandbox.bubblewrap, a layer above it',
        'ros2nb_instructor.grading.sandbox.planted_too imports '
        'ros2nb_instructor.grading.judging.learners, a layer above it']


def test_no_module_or_function_is_too_long():
    too_long = []
    for path in sorted(SRC.rglob('*.py')):
        text = path.read_text()
        if text.count('\n') > MAX_MODULE_LINES:
            too_long.append(f'{path.relative_to(ROOT)}: {text.count(chr(10))} lines')
        for node in ast.walk(ast.parse(text)):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > MAX_FUNCTION_LINES:
                    too_long.append(f'{path.relative_to(ROOT)}: {node.name}() {length} lines')
    assert too_long == []


def folder_problems(text: str, sources: dict[str, tuple[str, bool]]) -> list[str]:
    """One line per folder of the tree without its section in the document ("### `pkg`" with
    "Runs in" and "Trusts"), per module its folder's section does not name, and per section
    or name of the document that is not in the tree."""
    sections = dict(re.findall(r'^### `([\w.]+)`\n(.*?)(?=^#)', text + '\n#', re.M | re.S))
    packages = sorted(name for name, (_, is_package) in sources.items() if is_package)
    found = [f'{name} is a section of docs/architecture.md but no folder of src/'
             for name in sorted(sections) if name not in packages]
    for package in packages:
        section = sections.get(package)
        if section is None:
            found.append(f'{package} has no section in docs/architecture.md: add "### `{package}`"')
            continue
        found += [f'the section of {package} does not say "{what}"'
                  for what in ('**Runs in:**', '**Trusts:**') if what not in section]
        named = set(re.findall(r'`([\w.]+)`', section))
        found += [f'{name} is not named in the section of {package}' for name in sorted(sources)
                  if name.rpartition('.')[0] == package and not sources[name][1]
                  and name not in named]
    return found


def test_the_architecture_document_matches_the_tree():
    """Every folder has its section (where it runs, whom it trusts) naming each of its
    modules; every layer appears; and the document names no module that is not in the tree."""
    text = ARCHITECTURE.read_text()
    sources = tree_sources()
    named = set(re.findall(r'`((?:ros2nb|ros2nb_instructor)(?:\.\w+)*)`', text))
    modules = set(sources)
    layered = {prefix for layer in LAYERS for prefix in layer}
    missing = sorted(name for name in layered if name not in named)
    unknown = sorted(name for name in named if name not in modules | layered
                     and not _attribute_of_a_module(name, sources))
    assert (folder_problems(text, sources), missing, unknown) == ([], [], [])


def _attribute_of_a_module(name: str, sources: dict[str, tuple[str, bool]]) -> bool:
    """``ros2nb.checks.source.TEXT``: a name its module defines at its top level."""
    module, _, attribute = name.rpartition('.')
    if module not in sources:
        return False
    tree = ast.parse(sources[module][0])
    defined = {getattr(node, 'name', None) for node in tree.body}
    defined |= {target.id for node in tree.body if isinstance(node, (ast.Assign, ast.AnnAssign))
                for target in (node.targets if isinstance(node, ast.Assign) else [node.target])
                if isinstance(target, ast.Name)}
    defined |= {alias.asname or alias.name for node in tree.body
                if isinstance(node, ast.ImportFrom) for alias in node.names}
    return attribute in defined


def test_a_module_left_out_of_the_document_is_named():
    """The check itself can fail: a new module, and a folder without its section."""
    sources = {'pkg': ('', True), 'pkg.old': ('', False), 'pkg.new': ('', False),
               'pkg.sub': ('', True), 'pkg.sub.mod': ('', False)}
    text = ('### `pkg`\n- **Runs in:** here.\n- **Trusts:** nothing.\n- **Modules:** '
            '`pkg.old`.\n\n### `gone`\n- **Runs in:** nowhere.\n')
    assert folder_problems(text, sources) == [
        'gone is a section of docs/architecture.md but no folder of src/',
        'pkg.new is not named in the section of pkg',
        'pkg.sub has no section in docs/architecture.md: add "### `pkg.sub`"']


def test_no_two_modules_share_a_name():
    """A module's file name says what it is, once in src/ (``python -m`` needs __main__)."""
    seen: dict[str, list[str]] = {}
    for path in sorted(SRC.rglob('*.py')):
        if path.stem not in ('__init__', '__main__'):
            seen.setdefault(path.stem, []).append(str(path.relative_to(SRC)))
    assert {stem: paths for stem, paths in seen.items() if len(paths) > 1} == {}


def test_every_module_imports():
    """A name moved without its import shows here, not in the middle of grading a class."""
    import subprocess
    import sys
    probe = ('import importlib, pkgutil, ros2nb, ros2nb_instructor\n'
             'for package in (ros2nb, ros2nb_instructor):\n'
             '    for found in pkgutil.walk_packages(package.__path__, package.__name__ + "."):\n'
             '        if not found.name.endswith(("__main__", ".launcher")):\n'
             '            importlib.import_module(found.name)\n')
    done = subprocess.run([sys.executable, '-c', probe], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
