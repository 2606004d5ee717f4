"""``grading/report.html``: the class at a glance, one offline page.

Runs on the instructor's host, after nbgrader scored the class.  Per notebook: who handed
it in, how the scores spread (a matplotlib plot, embedded), and per check how many
learners passed; the failure lines learners saw most often, with their counts; every
learner's scores; the answers alike (:mod:`.similarity`); the notes.  This module counts;
``templates/report.html.j2`` lays it out (jinja2, autoescape on: everything a learner wrote
is escaped text), framed like the feedback pages (:func:`.feedback.page`: nh3 cleans the
body, and the Content-Security-Policy lets it load and run nothing).
"""

from __future__ import annotations

import base64
import collections
import io
import statistics
from pathlib import Path

from ...paths import NOTEBOOKS, SOLUTIONS
from ..intake.deadlines import late_by
from ..intake.submissions import Learner
from . import feedback, similarity

#: Failure lines listed (the most frequent first).
TOP_FAILURES = 20
#: Longest failure line shown (a learner's own exception can be long).
MAX_LINE = 400
STYLE = """body{font-family:sans-serif;margin:1.5em;max-width:70em}
table{border-collapse:collapse;margin:.5em 0 1.5em}td,th{border:1px solid #bbb;padding:.2em .5em;
text-align:left;vertical-align:top}td.n{text-align:right}caption{text-align:left;font-weight:bold}
.low{background:#fde2e1}.none{color:#888}"""


def _scores(rows: list[list[str]]) -> dict[str, dict[str, float]]:
    """notebook -> {learner's name: score} from grades.csv's rows (TOTAL rows left out)."""
    found: dict[str, dict[str, float]] = collections.defaultdict(dict)
    for name, notebook, score, _most, *_late in rows:
        if notebook != 'TOTAL':
            found[notebook][name] = float(score)
    return found


def spread_plot(notebooks: list[str], scores: dict[str, list[float]],
                maxima: dict[str, float]) -> str:
    """A PNG (as a ``data:`` URI) of each notebook's scores, as a share of its points.

    :param scores: notebook -> the scores of the learners who handed it in.
    :param maxima: notebook -> its points.
    """
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.figure import Figure
    figure = Figure(figsize=(9, 3.6), dpi=100)
    axes = figure.subplots()
    shares = [[100 * s / maxima[n] for s in scores.get(n, [])] if maxima[n] else []
              for n in notebooks]
    positions = range(1, len(notebooks) + 1)
    kept = [(p, v) for p, v in zip(positions, shares) if v]
    if kept:
        axes.boxplot([v for _p, v in kept], positions=[p for p, _v in kept], widths=0.5,
                     showfliers=False)
        for position, values in kept:
            axes.scatter([position] * len(values), values, s=12, alpha=0.5, color='tab:blue')
    axes.set_xticks(list(positions), [n[:2] for n in notebooks])
    axes.set_xlim(0.4, len(notebooks) + 0.6)
    axes.set_ylim(-5, 105)
    axes.set_xlabel('notebook')
    axes.set_ylabel('score (% of its points)')
    axes.set_title('Scores of the learners who handed each notebook in')
    figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format='png')
    return 'data:image/png;base64,' + base64.b64encode(buffer.getvalue()).decode()


def _notebook_rows(notebooks: list[str], handed: dict[str, list[float]],
                   maxima: dict[str, float]) -> list[dict[str, object]]:
    """Per notebook: who handed it in, the median and mean score, full marks, its points."""
    rows = []
    for notebook in notebooks:
        got = handed[notebook]
        rows.append({'notebook': notebook, 'handed': len(got),
                     'median': f'{statistics.median(got):g}' if got else '–',
                     'mean': f'{statistics.mean(got):.2f}' if got else '–',
                     'full': sum(1 for s in got if s == maxima[notebook]),
                     'points': f'{maxima[notebook]:g}'})
    return rows


def _check_rows(notebooks: list[str], learners: list[Learner]) -> list[dict[str, object]]:
    """Per notebook and check: how many learners passed it, of those judged (``low``: fewer
    than half)."""
    rows = []
    for notebook in notebooks:
        passed: collections.Counter[str] = collections.Counter()
        judged: collections.Counter[str] = collections.Counter()
        for learner in learners:
            for check, result in learner.results.get(notebook, {}).items():
                judged[check] += 1
                passed[check] += result.passed
        rows += [{'notebook': notebook, 'check': check, 'passed': passed[check],
                  'judged': judged[check], 'low': passed[check] < judged[check] / 2}
                 for check in sorted(judged)]
    return rows


def _failure_rows(learners: list[Learner]) -> list[dict[str, object]]:
    """The failure lines learners saw most often: how many learners, the check, the line."""
    counts: collections.Counter[tuple[str, str]] = collections.Counter()
    for learner in learners:
        for notebook, results in learner.results.items():
            for check, result in results.items():
                if not result.passed:
                    line = result.message or 'failed without a message'
                    counts[check, line[:MAX_LINE]] += 1
    return [{'count': count, 'check': check, 'line': line}
            for (check, line), count in counts.most_common(TOP_FAILURES)]


def _learner_rows(notebooks: list[str], scores: dict[str, dict[str, float]],
                  learners: list[Learner], totals: dict[str, str]) -> list[dict[str, object]]:
    """Per learner: their score per notebook (None: not handed in) and their total."""
    return [{'name': learner.shown, 'total': totals.get(learner.shown, ''),
             'scores': [f'{scores[n][learner.shown]:g}' if n in learner.files else None
                        for n in notebooks]} for learner in learners]


def _alike(notebooks: list[str], learners: list[Learner], course: Path) -> dict[str, object]:
    """Answers alike (:mod:`.similarity`): for a person to judge, never a grade."""
    pairs: list[similarity.Pair] = []
    common: list[similarity.Common] = []
    for notebook in notebooks:
        own = course / f'{notebook}.ipynb'
        given = NOTEBOOKS / f'{notebook}.ipynb'
        found, usual = similarity.alike(notebook, own if own.is_file() else None,
                                        {lr.shown: lr.files[notebook] for lr in learners
                                         if notebook in lr.files},
                                        given if given.is_file() else None)
        pairs, common = pairs + found, common + usual
    return {'pairs': pairs, 'common': common, 'threshold': f'{similarity.THRESHOLD:.0%}'}


def _late_rows(notebooks: list[str], learners: list[Learner]) -> list[dict[str, object]]:
    """Per learner and notebook with a due date: when it was due (their extension's due date,
    marked) and handed in, its score before lateness, the penalty, its score, and the note
    (:mod:`.deadlines`)."""
    rows = []
    for learner in learners:
        for notebook in notebooks:
            late = learner.late.get(notebook)
            if late is not None and late.due is not None:
                due, handed_in = late.shown()
                rows.append({'learner': learner.shown, 'notebook': notebook, 'due': due,
                             'extension': late.extension(),
                             'handed_in': handed_in or '–',
                             'late_by': late_by(late.late_s) if late.late_s else '',
                             'raw': f'{late.raw:g}', 'penalty': f'{late.penalty:g}',
                             'final': f'{late.final:g}', 'note': late.note})
    return rows


def write_report(out: Path, learners: list[Learner], notebooks: list[str],
                 rows: list[list[str]], refused: list[str], course: Path = SOLUTIONS) -> Path:
    """Write ``out/report.html`` for the graded class (``templates/report.html.j2``); return
    its path.

    :param rows: grades.csv's rows (learner's name as shown, notebook or ``TOTAL``, score,
        most points, and optionally the rest of :data:`.gradebook.CSV_COLUMNS`), as
        :func:`.gradebook.write_results` returns them.
    :param refused: the lines about entries not graded.
    :param course: the course's own notebooks (``NN-title.ipynb``), for the answers alike.
    """
    scores = _scores(rows)
    maxima = {notebook: 0.0 for notebook in notebooks}
    for _name, notebook, _score, most, *_late in rows:
        if notebook != 'TOTAL':
            maxima[notebook] = float(most)
    totals = {row[0]: f'{row[2]} of {row[3]}' for row in rows if row[1] == 'TOTAL'}
    handed = {n: [scores[n][learner.shown] for learner in learners if n in learner.files]
              for n in notebooks}
    body = feedback.render(
        'report.html.j2', learners=learners, plot=spread_plot(notebooks, handed, maxima),
        notebooks=_notebook_rows(notebooks, handed, maxima), checks=_check_rows(notebooks,
                                                                                learners),
        failures=_failure_rows(learners), notebook_names=notebooks,
        learner_rows=_learner_rows(notebooks, scores, learners, totals),
        alike=_alike(notebooks, learners, course), refused=refused,
        late_rows=_late_rows(notebooks, learners),
        notes=[(learner.shown, key, text) for learner in learners
               for key, text in sorted(learner.notes.items())])
    path = out / 'report.html'
    path.write_text(feedback.page('The class at a glance', body, [STYLE]))
    return path
