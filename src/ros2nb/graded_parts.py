"""The course's graded parts, from its notebooks' nbgrader metadata, and the learner's standing.

Each graded cell of the eleven notebooks is a :class:`Part`: its notebook, nbgrader's
``grade_id`` and ``points``, the heading it stands under (``Part 3: the node class and its
constructor``) and the check it calls (none for a hidden test: the learner's copy holds only
a comment there).  Read from the course's learner notebooks (``notebooks/``), never from the
learner's own copies.

The learner's lab keeps the outcome of every check they ran in a small file of their own,
:data:`RECORD` in their work folder (:func:`record_path`): passed or failed, and the check's
line.  Nothing grades from it: the grader runs every check itself, and the same table on the
feedback page comes from the grader's results (:func:`table_html` with its own states).

No ROS import.  Introduced in ``00-setup-and-the-pubsub-idea.ipynb`` (``ros2nb.progress()``).
"""

from __future__ import annotations

import datetime
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Optional

from . import nbmeta

#: The file of the learner's outcomes, in their work folder.
RECORD = '.ros2nb-progress.json'
#: Environment variable naming the record file itself (tests and ``make solutions`` use a
#: scratch one); else it is :data:`RECORD` in ``$ROS2NB_WORK`` or the kernel's folder.
RECORD_ENV = 'ROS2NB_PROGRESS'
#: The learner's work folder, when the lab says (``make lab``, the image, the hub).
WORK_ENV = 'ROS2NB_WORK'
#: The course's learner notebooks (this file is src/ros2nb/graded_parts.py in the course).
NOTEBOOKS = Path(__file__).resolve().parent.parent.parent / 'notebooks'
#: A part's state, as the table says it.
PASSED, FAILED, NOT_YET, HIDDEN = 'passed', 'failed', 'not yet', 'when handed in'
#: A pass whose work changed since it passed (ros2nb.checks.evidence): run its check again.
STALE = 'passed, then changed'
#: A part's state on a feedback page, for a notebook the learner did not hand in.
NOT_HANDED_IN = 'not handed in'
_CHECK_CALL = re.compile(r'ros2nb\.checks\.(check_\w+)\(')
_HEADING = re.compile(r'^#{2,4} +(.+?)\s*(\(\d+ points?\))?\s*$')


@dataclass(frozen=True)
class Part:
    """One graded cell of a notebook.

    :ivar notebook: the notebook's file name without ``.ipynb``, e.g. ``03-write-the-publisher``.
    :ivar grade_id: nbgrader's id of the cell.
    :ivar points: what it is worth.
    :ivar label: the heading it stands under, without its points.
    :ivar check: the check it calls (``check_sensor_constructor``), None for a hidden test.
    """

    notebook: str
    grade_id: str
    points: float
    label: str
    check: Optional[str]

    @property
    def number(self) -> str:
        """The notebook's number, ``'03'``."""
        return self.notebook[:2]


def parts(folder: Path = NOTEBOOKS) -> list[Part]:
    """Every graded cell of the notebooks in ``folder``, in notebook and cell order.

    :raises OSError: when ``folder`` holds no notebook the course can read.
    """
    found = []
    for path in sorted(folder.glob('[0-9][0-9]-*.ipynb')):
        label = ''
        for cell in nbmeta.cells(json.loads(path.read_text())):
            source = nbmeta.text(cell)
            if cell.get('cell_type') == 'markdown':
                headings = [m.group(1) for m in map(_HEADING.match, source.splitlines()) if m]
                label = headings[-1].replace('`', '') if headings else label
            grading = nbmeta.nbgrader_metadata(cell)
            if grading.get('grade') and grading.get('grade_id'):
                call = _CHECK_CALL.search(source)
                found.append(Part(path.stem, str(grading['grade_id']),
                                  float(grading.get('points') or 0), label,
                                  call.group(1) if call else None))
    if not found:
        raise OSError(f'no graded notebook in {folder}')
    return found


def record_path() -> Path:
    """Where the learner's outcomes are kept: ``$ROS2NB_PROGRESS``, else :data:`RECORD` in
    ``$ROS2NB_WORK``, else in the kernel's folder (the folder of the notebook it runs)."""
    if os.environ.get(RECORD_ENV):
        return Path(os.environ[RECORD_ENV]).expanduser()
    return Path(os.environ.get(WORK_ENV) or Path.cwd()).expanduser() / RECORD


def outcomes(path: Optional[Path] = None) -> dict[str, dict[str, Any]]:
    """The recorded outcome of each check, by its name: ``{'passed': bool, 'line': str,
    'at': ISO time}``; empty when nothing was recorded (or the file makes no sense)."""
    try:
        data = json.loads((path or record_path()).read_text())
        checks = data.get('checks', {}) if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}
    return {name: value for name, value in checks.items()
            if isinstance(name, str) and isinstance(value, dict)
            and isinstance(value.get('passed'), bool)}


def remember(check: str, passed: bool, line: str, path: Optional[Path] = None, *,
             evidence: Optional[Mapping[str, object]] = None) -> None:
    """Keep the outcome of ``check`` (replacing an earlier one), with what it ran on
    (``evidence``: ``files``, ``source``; :mod:`ros2nb.checks.evidence`); never fails a
    check: a folder it cannot write only means the table will not know."""
    path = path or record_path()
    kept = outcomes(path)
    kept[check] = {'passed': passed, 'line': line[:300], **(evidence or {}),
                   'at': datetime.datetime.now().astimezone().isoformat(timespec='seconds')}
    try:
        temporary = path.with_name(path.name + '.new')
        temporary.write_text(json.dumps({'checks': kept}, indent=1, sort_keys=True) + '\n')
        temporary.replace(path)
    except OSError:
        pass


def state(part: Part, recorded: Mapping[str, Mapping[str, Any]]) -> str:
    """The part's state from the recorded outcomes (:data:`PASSED`, :data:`FAILED`,
    :data:`NOT_YET`, or :data:`HIDDEN` for a hidden test)."""
    if part.check is None:
        return HIDDEN
    outcome = recorded.get(part.check)
    return NOT_YET if outcome is None else PASSED if outcome['passed'] else FAILED


def outcome_line(check: str, passed: bool, all_parts: list[Part]) -> Optional[str]:
    """The line at the end of a check: which part it was and what it is worth; None for a
    check no notebook grades.  The same on every run (no count that depends on history)."""
    mine = [p for p in all_parts if p.check == check]
    if not mine:
        return None
    part = mine[0]
    return (f'Progress: {part.number} · {part.label}: {PASSED if passed else "not passed yet"} '
            f'({_points(part.points)}); ros2nb.progress() shows all '
            f'{len({p.notebook for p in all_parts})} notebooks.')


def _points(points: float) -> str:
    return f'{points:g} point{"" if points == 1 else "s"}'


def rows(all_parts: list[Part], states: Mapping[str, str],
         notes: Optional[Mapping[str, str]] = None) -> list[dict[str, Any]]:
    """One row per notebook, for the tables: its parts with their states, the points passed,
    and its ``notes`` line (when it is due and was handed in; '' for none)."""
    by_notebook: dict[str, list[Part]] = {}
    for part in all_parts:
        by_notebook.setdefault(part.notebook, []).append(part)
    return [{'notebook': notebook, 'note': (notes or {}).get(notebook, ''),
             'passed': sum(p.points for p in mine if states[p.grade_id] == PASSED),
             'points': sum(p.points for p in mine),
             'parts': [{'label': p.label, 'points': p.points, 'state': states[p.grade_id]}
                       for p in mine]}
            for notebook, mine in by_notebook.items()]


def table_text(table: list[dict[str, Any]]) -> str:
    """The table as plain text: one line per notebook, one per part."""
    passed, total = sum(r['passed'] for r in table), sum(r['points'] for r in table)
    lines = [f'Passed {passed:g} of {total:g} points.']
    for row in table:
        note = f' ({row["note"]})' if row.get('note') else ''
        lines.append(f'{row["notebook"]}: {row["passed"]:g} of {row["points"]:g}{note}')
        lines += [f'  {p["state"]:>14}  {p["points"]:g}  {p["label"]}' for p in row['parts']]
    return '\n'.join(lines)


_TABLE = '''\
<table class="ros2nb-progress">
<caption>{{ caption }}: {{ passed | g }} of {{ total | g }} points passed</caption>
<thead><tr><th>notebook</th><th>part</th><th>points</th><th>state</th></tr></thead>
<tbody>
{%- for row in table %}{% for part in row.parts %}
<tr>{% if loop.first %}<th rowspan="{{ row.parts | length }}">{{ row.notebook }}<br>
{{- row.passed | g }} of {{ row.points | g }}
{%- if row.note %}<br><small>{{ row.note }}</small>{% endif %}</th>{% endif -%}
<td>{{ part.label }}</td><td>{{ part.points | g }}</td>
<td class="{{ part.state | replace(' ', '-') }}">{{ part.state }}</td></tr>
{%- endfor %}{% endfor %}
</tbody>
</table>'''


def table_html(table: list[dict[str, Any]], caption: str,
               link: Optional[tuple[str, str]] = None) -> str:
    """The table as HTML (escaped by jinja2): a row per part, grouped by notebook; ``link``
    (text, address), when given, is a line above it (the learner's feedback on the hub)."""
    from jinja2 import Environment  # only where a table is shown, never in a check's import
    environment = Environment(autoescape=True)
    environment.filters['g'] = lambda number: f'{number:g}'
    above = environment.from_string('<p><a href="{{ url }}" target="_blank">{{ text }}</a></p>\n'
                                    ).render(text=link[0], url=link[1]) if link else ''
    return above + environment.from_string(_TABLE).render(
        table=table, caption=caption, passed=sum(r['passed'] for r in table),
        total=sum(r['points'] for r in table))


def show_table(table: list[dict[str, Any]], caption: str,
               link: Optional[tuple[str, str]] = None) -> None:
    """Show the table (and ``link``, :func:`table_html`): as HTML (with the text beside it)
    in a Jupyter kernel, else as text."""
    text = f'{caption}. {table_text(table)}' + (f'\n{link[0]}: {link[1]}' if link else '')
    try:
        from IPython import get_ipython
        from IPython.display import display
    except ImportError:  # pragma: no cover - IPython comes with the course
        print(text)
        return
    if getattr(get_ipython(), 'kernel', None) is not None:
        display({'text/html': table_html(table, caption, link), 'text/plain': text}, raw=True)
    else:
        print(text)
