"""``grading/report.html``: the class at a glance, one offline page.

Runs on the instructor's host, after nbgrader scored the class.  Per notebook: who handed
it in, how the scores spread (a matplotlib plot, embedded), and per check how many
learners passed; the failure lines learners saw most often, with their counts; every
learner's scores; the answers alike (:mod:`.similarity`); the notes.  The page is built like the feedback pages
(:func:`.feedback.page`): everything a learner wrote is escaped text, nh3 cleans the body,
and the Content-Security-Policy lets it load and run nothing.
"""

from __future__ import annotations

import base64
import collections
import html
import io
import statistics
from pathlib import Path

from ..paths import NOTEBOOKS, SOLUTIONS
from . import feedback, similarity
from .submissions import Learner

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
    for name, notebook, score, _most in rows:
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


def _e(text: object) -> str:
    return html.escape(str(text))


def _notebook_table(notebooks: list[str], handed: dict[str, list[float]],
                    maxima: dict[str, float], learners: list[Learner]) -> str:
    lines = ['<table id="notebooks"><caption>Notebooks</caption><tr><th>notebook</th>'
             '<th>handed in</th><th>median score</th><th>mean</th><th>full marks</th>'
             '<th>points</th></tr>']
    for notebook in notebooks:
        got = handed[notebook]
        full = sum(1 for s in got if s == maxima[notebook])
        median = f'{statistics.median(got):g}' if got else '–'
        mean = f'{statistics.mean(got):.2f}' if got else '–'
        lines.append(f'<tr><td>{_e(notebook)}</td><td class="n">{len(got)} of {len(learners)}'
                     f'</td><td class="n">{median}</td><td class="n">{mean}</td>'
                     f'<td class="n">{full}</td><td class="n">{maxima[notebook]:g}</td></tr>')
    lines.append('</table>')
    return '\n'.join(lines)


def _checks_table(notebooks: list[str], learners: list[Learner]) -> str:
    lines = ['<table id="checks"><caption>Checks: how many learners passed each</caption>'
             '<tr><th>notebook</th><th>check</th><th>passed</th><th>judged</th></tr>']
    for notebook in notebooks:
        passed: collections.Counter = collections.Counter()
        judged: collections.Counter = collections.Counter()
        for learner in learners:
            for check, result in learner.results.get(notebook, {}).items():
                judged[check] += 1
                passed[check] += bool(result.get('passed'))
        for check in sorted(judged):
            low = ' class="low"' if passed[check] < judged[check] / 2 else ''
            lines.append(f'<tr{low}><td>{_e(notebook[:2])}</td><td>{_e(check)}</td>'
                         f'<td class="n">{passed[check]}</td><td class="n">{judged[check]}</td>'
                         '</tr>')
    lines.append('</table>')
    return '\n'.join(lines)


def _failures_table(learners: list[Learner]) -> str:
    counts: collections.Counter = collections.Counter()
    for learner in learners:
        for notebook, results in learner.results.items():
            for check, result in results.items():
                if not result.get('passed'):
                    line = str(result.get('message') or 'failed without a message')
                    counts[check, line[:MAX_LINE]] += 1
    lines = ['<table id="failures"><caption>The failure lines learners saw most often'
             '</caption><tr><th>learners</th><th>check</th><th>line</th></tr>']
    for (check, line), count in counts.most_common(TOP_FAILURES):
        lines.append(f'<tr><td class="n">{count}</td><td>{_e(check)}</td><td>{_e(line)}</td>'
                     '</tr>')
    if not counts:
        lines.append('<tr><td colspan="3" class="none">no check failed</td></tr>')
    lines.append('</table>')
    return '\n'.join(lines)


def _learners_table(notebooks: list[str], scores: dict[str, dict[str, float]],
                    learners: list[Learner], totals: dict[str, str]) -> str:
    head = ''.join(f'<th title="{_e(n)}">{_e(n[:2])}</th>' for n in notebooks)
    lines = ['<table id="learners"><caption>Who handed in what (score; – not handed in)'
             f'</caption><tr><th>learner</th>{head}<th>total</th></tr>']
    for learner in learners:
        cells = ''.join(f'<td class="n">{scores[n][learner.shown]:g}</td>' if n in learner.files
                        else '<td class="n none">–</td>' for n in notebooks)
        lines.append(f'<tr><td>{_e(learner.shown)}</td>{cells}'
                     f'<td class="n">{_e(totals.get(learner.shown, ""))}</td></tr>')
    lines.append('</table>')
    return '\n'.join(lines)


def _similarity_table(notebooks: list[str], learners: list[Learner], course: Path) -> str:
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
    lines = ['<table id="similarity"><caption>Answers alike: what the judge graded (each '
             'answer, and the parts cells the learner added wrote), names and layout set '
             'aside, beside the course\'s and every classmate\'s (at least '
             f'{similarity.THRESHOLD:.0%} of one found in the other; small parts compared '
             'together per notebook); for you to judge, no point changed</caption><tr>'
             '<th>notebook</th><th>cell</th><th>answer</th><th>beside</th><th>alike</th></tr>']
    for pair in pairs:
        lines.append(f'<tr><td>{_e(pair.notebook[:2])}</td><td>{_e(pair.cell)}</td>'
                     f'<td>{_e(pair.first)}</td><td>{_e(pair.second)}</td>'
                     f'<td class="n">{pair.ratio:.0%}</td></tr>')
    if not pairs:
        lines.append('<tr><td colspan="5" class="none">no two answers alike</td></tr>')
    lines.append('</table>')
    if common:
        lines.append('<p id="common">Cells most of the class wrote like the course\'s answer '
                     '(they leave little to choose; not listed pair by pair): ' + ', '.join(
                         f'{_e(c.cell)}: {len(c.alike)} of {c.handed} '
                         f'({_e(", ".join(c.alike))})' for c in common) + '</p>')
    return '\n'.join(lines)


def _notes(learners: list[Learner], refused: list[str]) -> str:
    lines = ['<h2 id="notes">Notes</h2><dl>']
    for learner in learners:
        for key, text in sorted(learner.notes.items()):
            lines.append(f'<dt>{_e(learner.shown)}, {_e(key)}</dt><dd>{_e(text)}</dd>')
    lines.append('</dl>')
    if refused:
        lines.append('<h3>Not graded</h3><ul>' + ''.join(f'<li>{_e(r)}</li>' for r in refused)
                     + '</ul>')
    return '\n'.join(lines)


def write_report(out: Path, learners: list[Learner], notebooks: list[str],
                 rows: list[list[str]], refused: list[str], course: Path = SOLUTIONS) -> Path:
    """Write ``out/report.html`` for the graded class; return its path.

    :param rows: grades.csv's rows (learner's name as shown, notebook or ``TOTAL``, score,
        most points), as :func:`.gradebook.write_results` returns them.
    :param refused: the lines about entries not graded.
    :param course: the course's own notebooks (``NN-title.ipynb``), for the answers alike.
    """
    scores = _scores(rows)
    maxima = {notebook: 0.0 for notebook in notebooks}
    for _name, notebook, _score, most in rows:
        if notebook != 'TOTAL':
            maxima[notebook] = float(most)
    totals = {row[0]: f'{row[2]} of {row[3]}' for row in rows if row[1] == 'TOTAL'}
    handed = {n: [scores[n][learner.shown] for learner in learners if n in learner.files]
              for n in notebooks}
    plot = spread_plot(notebooks, handed, maxima)
    body = '\n'.join([
        f'<h1>The class at a glance: {len(learners)} learners</h1>',
        '<h2>Scores</h2>',
        f'<img id="spread" src="{plot}" alt="the spread of scores per notebook">',
        _notebook_table(notebooks, handed, maxima, learners),
        '<h2>Checks</h2>', _checks_table(notebooks, learners),
        '<h2>Failures</h2>', _failures_table(learners),
        '<h2>Learners</h2>', _learners_table(notebooks, scores, learners, totals),
        '<h2 id="alike">Answers alike</h2>', _similarity_table(notebooks, learners, course),
        _notes(learners, refused)])
    path = out / 'report.html'
    path.write_text(feedback.page('The class at a glance', body, [STYLE]))
    return path
