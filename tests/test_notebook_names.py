"""Every ``ros2nb`` name a notebook's cell uses exists in the module it is read from.

A module split that forgot a re-export otherwise fails only in nbval, at the end of make test,
far from the change that caused it.  Importing a module starts no ROS process, so this stays in
the check lane.
"""
from __future__ import annotations

import ast
import importlib
from pathlib import Path

import nbformat
import pytest

ROOT = Path(__file__).resolve().parent.parent


def _dotted(node: ast.AST) -> list[str]:
    """``a.b.c`` as ``['a', 'b', 'c']``; anything but names and attributes gives ``[]``."""
    parts: list[str] = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name):
        return []
    parts.append(node.id)
    return parts[::-1]


def _uses(notebook: Path) -> set[tuple[str, str]]:
    """(module, name) for every ``ros2nb.module.name`` read in the notebook's code cells."""
    found: set[tuple[str, str]] = set()
    for cell in nbformat.read(notebook, as_version=4).cells:
        if cell.cell_type != 'code':
            continue
        source = '\n'.join(line for line in cell.source.splitlines()
                           if not line.lstrip().startswith(('%', '!')))
        try:
            tree = ast.parse(source)
        except SyntaxError:
            continue  # a challenge's unfinished answer; nbval reports real ones
        for node in ast.walk(tree):
            parts = _dotted(node)
            if len(parts) >= 3 and parts[0] == 'ros2nb':
                found.add(('.'.join(parts[:2]), parts[2]))
    return found


NOTEBOOKS = sorted([*ROOT.glob('notebooks/*.ipynb'), *ROOT.glob('solutions/*.ipynb')])


@pytest.mark.parametrize('notebook', NOTEBOOKS, ids=lambda p: f'{p.parent.name}/{p.name}')
def test_every_ros2nb_name_a_notebook_reads_exists(notebook: Path) -> None:
    missing = []
    for module_name, name in sorted(_uses(notebook)):
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError:
            continue  # ros2nb.<attribute>.<attribute>: not a module, read at run time
        if not hasattr(module, name):
            missing.append(f'{module_name}.{name}')
    assert not missing, f'{notebook.name} reads names its modules lack: {missing}'


def test_a_missing_name_is_found(tmp_path: Path) -> None:
    """The test above fails on the mistake it exists for: a name a module does not have."""
    notebook = nbformat.v4.new_notebook(cells=[nbformat.v4.new_code_cell(
        "import ros2nb.qos\nros2nb.qos.no_such_name(1)\n%matplotlib inline")])
    path = tmp_path / 'x.ipynb'
    nbformat.write(notebook, path)
    assert ('ros2nb.qos', 'no_such_name') in _uses(path)
    assert not hasattr(importlib.import_module('ros2nb.qos'), 'no_such_name')
