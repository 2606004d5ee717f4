"""Writing the learner's files: never over their own edits, ``%%part`` parts kept, fresh imports.

Introduced in ``03-write-the-publisher.ipynb``.  No ROS import.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import itertools
import json
import shutil
import sys
from pathlib import Path
from types import ModuleType
from typing import Iterator, Optional

from ..errors import CheckFailed, FileProtectedError, Ros2nbError, UsageError
from .workspace import PathLike, current_workspace, shown, workspace_file

#: Where ros2nb records what it wrote, so it never overwrites a file you edited.
WRITTEN_RECORD = '.ros2nb-written.json'
#: Where ``%%part`` keeps the parts of each file, so a kernel restart loses none.
PARTS_RECORD = '.ros2nb-parts.json'
#: Most missing part numbers a message names.
MAX_GAPS_NAMED = 10
#: nbgrader's marker lines around an answer in the course's own notebooks; not part of a file.
AUTHOR_MARKERS = ('### BEGIN SOLUTION', '### END SOLUTION')
#: What nbgrader leaves in an answer cell the learner has not written yet.
PLACEHOLDER = 'raise NotImplementedError'


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def _record_path(path: Path) -> Optional[Path]:
    """The workspace's record file, or None for files outside the workspace (not recorded)."""
    ws = current_workspace().resolve()
    return ws / WRITTEN_RECORD if ws in path.resolve().parents else None


def write_file(path: PathLike, text: str, *, overwrite: bool = False) -> Path:
    """Write a source file, never overwriting changes you made to it yourself.

    A file ros2nb wrote earlier and nobody changed since is replaced; a file you edited
    (or that ros2nb did not write) is only replaced with ``overwrite=True``, and then
    your version is kept beside it as ``<name>.bak``.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the file; relative paths are relative to the current workspace.
    :param text: the new contents.
    :param overwrite: replace the file even if you changed it.
    :return: the file's absolute path.
    :raises FileProtectedError: if the file has changes of yours and ``overwrite`` is false.
    """
    path = workspace_file(path)
    if path.is_file():
        current = path.read_text()
        if current != text and _load_record(path).get(str(path.resolve())) != _digest(current):
            if not overwrite:
                raise FileProtectedError(
                    f'{shown(path)} has changes that ros2nb did not write; to keep them do '
                    'nothing, to replace them run again with overwrite=True, or add --overwrite to '
                    'the %%part line (your version is then kept as .bak).')
            shutil.copy2(path, path.with_name(path.name + '.bak'))
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    remember_written(path)
    return path.resolve()


def _load_record(path: Path) -> dict[str, str]:
    record_file = _record_path(path)
    return json.loads(record_file.read_text()) if record_file and record_file.is_file() else {}


def remember_written(path: PathLike) -> None:
    """Record that ros2nb wrote ``path`` as it is now, so a later write may replace it.

    Only files inside the current workspace are recorded; others are never replaced
    without ``overwrite=True``.
    """
    path = Path(path).resolve()
    record_file = _record_path(path)
    if record_file is None:
        return
    record = _load_record(path)
    record[str(path)] = _digest(path.read_text())
    record_file.write_text(json.dumps(record, indent=1, sort_keys=True) + '\n')


def import_file(path: PathLike, module_name: Optional[str] = None) -> ModuleType:
    """Import a Python file as a module that follows the file: whenever the file changed
    since (a ``%%part`` cell run again, here or in another notebook), the next use of a name
    in it imports it afresh, so no cell ever runs an old version of your code.

    Nodes made from an older version keep running it until you replace them.

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the ``.py`` file; relative paths are relative to the current workspace.
    :param module_name: name to register in ``sys.modules``; default the file's stem.
    :return: the module (a :class:`FreshModule`).
    :raises Ros2nbError: if the file does not exist.
    :raises SyntaxError: (and anything the file raises at import) unchanged, with its line;
        also later, on the use that imports a changed file afresh.
    """
    path = workspace_file(path)
    if not path.is_file():
        raise Ros2nbError(f'{shown(path)} does not exist: run the cells that write it first.')
    return FreshModule(path, module_name or path.stem)


class FreshModule(ModuleType):
    """A learner's file as a module, imported afresh on the first use after the file changed.

    Each import makes a new module (registered in ``sys.modules``); this one forwards every
    name to the newest, so a name looked up in a cell is always the file's current one, while
    nodes made earlier keep the module they were made from (nothing is changed under them).
    """

    def __init__(self, path: Path, name: str) -> None:
        super().__init__(name)
        self.__dict__['_ros2nb_file'] = (path, name)
        self.__dict__['_ros2nb_loaded'] = (b'', None)
        self._ros2nb_current()

    def _ros2nb_current(self) -> ModuleType:
        """The module of the file as it is now (imported again when its text changed)."""
        path, name = self.__dict__['_ros2nb_file']
        digest, module = self.__dict__['_ros2nb_loaded']
        text = path.read_bytes() if path.is_file() else None
        now = hashlib.sha256(text).digest() if text is not None else digest
        if module is None or now != digest:
            spec = importlib.util.spec_from_file_location(name, path)
            assert spec is not None and spec.loader is not None
            module = importlib.util.module_from_spec(spec)
            sys.modules[name] = module
            spec.loader.exec_module(module)
            self.__dict__['_ros2nb_loaded'] = (now, module)
            self.__dict__['__file__'], self.__dict__['__doc__'] = module.__file__, module.__doc__
        return module

    def __getattr__(self, attribute: str) -> object:
        if attribute.startswith('__') and attribute.endswith('__'):
            raise AttributeError(attribute)
        return getattr(self._ros2nb_current(), attribute)

    def __dir__(self) -> list[str]:
        return dir(self._ros2nb_current())


_parts_outside: dict[str, dict[int, str]] = {}  # files outside the workspace: this kernel only


@contextlib.contextmanager
def _parts_of(path: Path) -> Iterator[dict[int, str]]:
    """The stored parts of ``path`` (kept in the workspace, so a kernel restart loses none).

    Changes made inside the block are saved when it ends without an error.
    """
    ws = current_workspace().resolve()
    resolved = path.resolve()
    if ws not in resolved.parents:
        yield _parts_outside.setdefault(str(resolved), {})
        return
    record_file = ws / PARTS_RECORD
    record = json.loads(record_file.read_text()) if record_file.is_file() else {}
    key = str(resolved.relative_to(ws))
    parts = {int(n): text for n, text in record.get(key, {}).items()}
    yield parts
    record[key] = {str(n): parts[n] for n in sorted(parts)}
    record_file.write_text(json.dumps(record, indent=1, sort_keys=True) + '\n')


def saved_parts(workspace: Path, relative: str) -> Optional[set[int]]:
    """The part numbers of ``relative`` that ``%%part`` cells saved: an empty set when its
    cells ran but saved nothing (each still held the placeholder), None when none of its
    cells ran (or the record cannot be read).

    Read from the workspace's ``.ros2nb-parts.json``.  Introduced in
    ``03-write-the-publisher.ipynb``.
    """
    record_file = workspace / PARTS_RECORD
    try:
        record = json.loads(record_file.read_text()) if record_file.is_file() else {}
        return {int(n) for n in record[relative]} if relative in record else None
    except (OSError, ValueError, TypeError, AttributeError):  # not a record %%part wrote
        return None


def missing_parts(workspace: Path, relative: str) -> list[int]:
    """The part numbers below the highest saved part of ``relative`` that were never saved.

    Introduced in ``03-write-the-publisher.ipynb`` (checks name a part run out of order).
    """
    return _gaps(saved_parts(workspace, relative) or set())


def parts_verdict(workspace: Path, relative: str) -> None:
    """Raise CheckFailed naming the ``%%part`` cells of ``relative`` never run, if any.

    What a check says first when the learner's file does not load or lacks a class: a part
    never run explains it best.  Introduced in ``03-write-the-publisher.ipynb``.
    """
    gaps = missing_parts(workspace, relative)
    if gaps:
        many = len(gaps) > 1
        raise CheckFailed(f'{Path(relative).name} is missing part{"s" if many else ""} '
                          f'{", ".join(map(str, gaps))}: run the %%part cell{"s" if many else ""} '
                          f'for {"them" if many else "it"} (parts go into the file in number '
                          'order), then this check again.')


def _gaps(saved: set[int]) -> list[int]:
    """The first :data:`MAX_GAPS_NAMED` part numbers below the highest in ``saved`` that are
    not in it (a part numbered 1000000000 names ten, and takes no time)."""
    below = (n for n in range(1, max(saved, default=0)) if n not in saved)
    return list(itertools.islice(below, MAX_GAPS_NAMED))


def write_part(path: PathLike, number: int, text: str, *, overwrite: bool = False) -> Path:
    """Set part ``number`` of a source file and write the file from all its parts.

    Parts are joined in number order with one blank line between them, so cells can be
    re-run in any order.  nbgrader's answer markers (``### BEGIN SOLUTION``) are left
    out.  The parts are kept in the workspace (``.ros2nb-parts.json``), so after a
    kernel restart re-running one part keeps all the others.  Like
    :func:`write_file`, it never overwrites a file you changed in an editor.  Used by the
    ``%%part FILE N`` cell magic (``%load_ext ros2nb``).

    Introduced in ``03-write-the-publisher.ipynb``.

    :param path: the file, as for :func:`write_file`.
    :param number: the part's position (1, 2, ...).
    :param text: the part's source code.
    :param overwrite: as for :func:`write_file`.
    :return: the file's absolute path.
    :raises FileProtectedError: as :func:`write_file`.

    A part that still holds nbgrader's placeholder (``raise NotImplementedError()``) never
    replaces working content (a file written before, or the same part without it) unless
    ``overwrite`` is true: one line says so, and nothing is written.
    """
    if isinstance(number, bool) or not isinstance(number, int) or number < 1:
        raise UsageError(f'A part number is a whole number from 1 up (got {number!r}).')
    text = '\n'.join(line for line in text.split('\n') if line.strip() not in AUTHOR_MARKERS)
    resolved = workspace_file(path)
    with _parts_of(resolved) as parts:
        replaces = resolved.is_file() and not parts
        working = resolved.read_text() if replaces else parts.get(number)
        if PLACEHOLDER in text and working is not None and PLACEHOLDER not in working \
                and not overwrite:
            print(f'{shown(resolved)} was not changed: this cell still holds the placeholder '
                  f'"{PLACEHOLDER}()", which would replace the working version; write your '
                  'answer in its place and run the cell again (to replace it on purpose, add '
                  '--overwrite to the %%part line).')
            return resolved.resolve()
        new_parts = {**parts, number: text.rstrip('\n') + '\n'}
        written = write_file(resolved, '\n\n'.join(new_parts[n].rstrip('\n')
                                                   for n in sorted(new_parts)) + '\n',
                             overwrite=overwrite)
        parts.clear()
        parts.update(new_parts)
    lines = written.read_text().count('\n')
    gaps = _gaps(set(parts))
    gap = (f'; part{"s" if len(gaps) > 1 else ""} {", ".join(map(str, gaps))} not saved yet: '
           f'run {"its cell" if len(gaps) == 1 else "their cells"} too' if gaps else '')
    print(f'{shown(written)}: part {number} saved (parts {", ".join(map(str, sorted(parts)))}; '
          f'{lines} lines{gap})' + (' (it replaces the file ros2nb wrote there before)'
                                    if replaces else ''))
    return written
