"""The ``{schedule}`` directive: the course's schedule on the start page, made from the lessons.

Each lesson's row comes from its notebook in ``solutions/`` at every build, so it cannot go
stale: the title (its first heading), the time (its ``**Time:** teaching N min · exercises M
min`` line), the points (the sum of its nbgrader graded cells' points) and what the learner
writes for them (its ``**Points:**`` line, which must give the same total: the build fails
when they differ).  The course's folder is the setting ``schedule_course`` (build.py gives it);
only the lessons the build includes are listed.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass
from pathlib import Path

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

TITLE = re.compile(r'^# (.+)$', re.M)
TIME = re.compile(r'\*\*Time:\*\* teaching (\d+) min · exercises (\d+) min')
POINTS = re.compile(r'\*\*Points:\*\* (\d+)(?: in all)?[.,]?\s*(?:for )?(.*?)(?:\.(?=\s|$)|$)',
                    re.S)


@dataclass(frozen=True)
class Lesson:
    """One row of the schedule.

    :ivar page: the lesson's page, relative to the site's sources (``lessons/03-....ipynb``).
    :ivar title: its title (``03 · Write the publisher``).
    :ivar teaching_min: minutes of teaching.
    :ivar exercises_min: minutes of exercises.
    :ivar points: the points of its graded cells.
    :ivar writes: what the learner writes for them, from the notebook's own words.
    """

    page: str
    title: str
    teaching_min: int
    exercises_min: int
    points: float
    writes: str


def _source(cell: dict) -> str:
    text = cell.get('source', '')
    return text if isinstance(text, str) else ''.join(text)


def lesson(notebook: dict, name: str) -> Lesson:
    """The schedule's row of the lesson ``name`` (``03-write-the-publisher.ipynb``), read from
    its ``solutions/`` notebook.

    :raises ValueError: when the notebook lacks its title, its time or its points line, or
        its points line gives another total than its graded cells.
    """
    opening = '\n'.join(_source(cell) for cell in notebook['cells'][:3]
                        if cell['cell_type'] == 'markdown')
    title, time, said = TITLE.search(opening), TIME.search(opening), POINTS.search(opening)
    if not (title and time and said):
        missing = [what for what, found in (('a "# NN · Title" heading', title),
                                            ('a "**Time:** teaching N min · exercises M min" '
                                             'line', time), ('a "**Points:**" line', said))
                   if not found]
        raise ValueError(f'{name}: its opening cell has no {" and no ".join(missing)}')
    points = sum(cell['metadata']['nbgrader'].get('points', 0) for cell in notebook['cells']
                 if cell.get('metadata', {}).get('nbgrader', {}).get('grade'))
    if float(said.group(1)) != points:
        raise ValueError(f'{name}: its **Points:** line says {said.group(1)}, its graded cells '
                         f'give {points:g}: make them agree')
    writes = ' '.join(said.group(2).split())
    return Lesson(f'lessons/{name}', title.group(1).strip(), int(time.group(1)),
                  int(time.group(2)), points, writes[:1].upper() + writes[1:])


def lessons(course: Path) -> list[Lesson]:
    """Every lesson of ``course`` (its ``solutions/``), in the course's order."""
    return [lesson(json.loads(path.read_text()), path.name)
            for path in sorted((course / 'solutions').glob('[0-9][0-9]-*.ipynb'))]


def _hours(minutes: int) -> str:
    return f'{minutes // 60} h {minutes % 60:02d} min'


def schedule_markdown(rows: list[Lesson]) -> str:
    """The schedule as a MyST table, a row per lesson and one of totals."""
    lines = ['| Lesson | Time: teaching + exercises | Points | What you write for the points |',
             '|---|---|---|---|']
    for row in rows:
        cell = row.writes.replace('|', '\\|')
        lines.append(f'| [{row.title}]({row.page}) | {row.teaching_min} + {row.exercises_min} '
                     f'min | {row.points:g} | {cell} |')
    teaching = sum(row.teaching_min for row in rows)
    exercises = sum(row.exercises_min for row in rows)
    lines.append(f'| **All {len(rows)} lessons** | **{_hours(teaching + exercises)}** '
                 f'({teaching} + {exercises} min) | **{sum(row.points for row in rows):g}** | |')
    return '\n'.join(lines)


class Schedule(SphinxDirective):
    """``{schedule}``: the table of the lessons this build includes."""

    def run(self) -> list[nodes.Node]:
        course = Path(self.config.schedule_course)
        rows = [row for row in lessons(course)
                if row.page.removesuffix('.ipynb') in self.env.found_docs]
        for row in rows:  # the page lists them: a change to a notebook rebuilds it
            self.env.note_dependency(str(course / 'solutions' / Path(row.page).name))
        container = nodes.container(classes=['schedule'])
        self.state.nested_parse(StringList(schedule_markdown(rows).splitlines(),
                                           self.get_source_info()[0]),
                                self.content_offset, container)
        return [container]


def setup(app: Sphinx) -> dict:
    """Sphinx's entry point: the directive and its setting."""
    app.add_config_value('schedule_course', str(Path(__file__).resolve().parents[2]), 'env',
                         types=[str])
    app.add_directive('schedule', Schedule)
    return {'parallel_read_safe': True, 'parallel_write_safe': True}
