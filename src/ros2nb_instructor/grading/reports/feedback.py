"""Feedback pages that cannot run code: nbgrader's pages, sanitised, under a strict CSP.

Runs on the instructor's host.  nbgrader (through nbconvert) writes a feedback page per
notebook; what the learner wrote reaches it as text already (:mod:`.notebooks`), and this
module is the second wall: the page's body goes through nh3 (the Ammonia sanitiser), its
head is rebuilt from the template's own style sheets only (no script, no remote load), and
a Content-Security-Policy forbids every script and every load but inline styles and
``data:`` images.  A page opens the same in the instructor's and the learner's browser.
The pages' HTML is jinja2's, from ``templates/`` (autoescape on: every value is text unless
a template says it is HTML the grader made, such as a body nh3 cleaned).
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any, Optional, Sequence

import jinja2
import nh3

if TYPE_CHECKING:
    from ..intake.deadlines import Lateness

#: The grader's templates (``templates/*.j2``); every value they show is escaped.
TEMPLATES = jinja2.Environment(loader=jinja2.PackageLoader(__package__, 'templates'),
                               autoescape=True, undefined=jinja2.StrictUndefined)


def render(template: str, **values: Any) -> str:
    """``templates/<template>`` with ``values`` (escaped, unless the template marks one safe).

    :raises jinja2.UndefinedError: when the template uses a value not given.
    """
    return TEMPLATES.get_template(template).render(**values)

#: The page may show inline styles and data: images, and load or run nothing else.
CSP = ("default-src 'none'; img-src data:; style-src 'unsafe-inline'; font-src data:; "
       "base-uri 'none'; form-action 'none'")
#: Tags a feedback page keeps (nbconvert's cells, outputs, markdown, nbgrader's score boxes).
TAGS = {'a', 'abbr', 'b', 'blockquote', 'br', 'caption', 'code', 'dd', 'del', 'details', 'div',
        'dl', 'dt', 'em', 'h1', 'h2', 'h3', 'h4', 'h5', 'h6', 'hr', 'i', 'img', 'kbd', 'li',
        'main', 'ol', 'p', 'pre', 's', 'samp', 'small', 'span', 'strong', 'sub', 'summary',
        'sup', 'table', 'tbody', 'td', 'tfoot', 'th', 'thead', 'tr', 'u', 'ul'}
ATTRIBUTES = {'*': {'class', 'id', 'title'}, 'a': {'href'}, 'img': {'src', 'alt'},
              'td': {'colspan', 'rowspan'}, 'th': {'colspan', 'rowspan'}}
#: Images a page may show: the notebook's own plots and pasted images, inline.
IMAGE_PREFIXES = ('data:image/png;base64,', 'data:image/jpeg;base64,')


def _attribute(element: str, attribute: str, value: str) -> str | None:
    """nh3's attribute filter: an image only from data, a link only to a page or an anchor."""
    if element == 'img' and attribute == 'src':
        return value if value.startswith(IMAGE_PREFIXES) else None
    if element == 'a' and attribute == 'href':
        return value if value.startswith(('#', 'https://', 'http://')) else None
    return value


def clean_body(body: str) -> str:
    """HTML with nothing that runs or loads: nh3 with the tags and attributes above."""
    return nh3.clean(body, tags=TAGS, attributes=ATTRIBUTES, attribute_filter=_attribute,
                     url_schemes={'http', 'https', 'data'}, link_rel='noopener noreferrer',
                     strip_comments=True)


def page(title: str, body: str, styles: Sequence[str] = (), body_class: str = '') -> str:
    """A whole page (``templates/page.html.j2``): CSP, the title as text, the given style
    sheets (none that could end its ``<style>``), the body sanitised."""
    return render('page.html.j2', csp=CSP, title=title, body_class=body_class,
                  styles=[s for s in styles if '</' not in s], body=clean_body(body)) + '\n'


#: What the feedback page says above the judge's flags (:mod:`ros2nb.judge.flags`).
FLAGS_HEADING = 'Code your instructor will look at'
FLAGS_WHY = ('These lines reach past what the lessons use (into the course\'s own answers or '
             'the process they run in). No point changed because of them; your instructor '
             'reads them with your notebook.')


def flags_html(flags: Sequence[str]) -> str:
    """The judge's flags of one notebook as a box of the feedback page (empty for none);
    each flag is text, escaped (``templates/flags.html.j2``)."""
    return render('flags.html.j2', flags=flags, heading=FLAGS_HEADING, why=FLAGS_WHY)


def late_html(late: Optional[Lateness]) -> str:
    """A notebook's lateness as the box of the feedback page that says when it was due (the
    learner's extension, if they have one, beside the class's due date) and handed in (both
    in the due date's time zone), its score before lateness, the penalty and its score
    (empty when it had no due date)."""
    if late is None or late.due is None:
        return ''
    due, when = late.shown()
    return render('late.html.j2', late={
        'due': due, 'handed_in': when or 'the submission says no time', 'raw': f'{late.raw:g}',
        'penalty': f'{late.penalty:g}', 'final': f'{late.final:g}', 'note': late.note,
        'cost': late.penalty > 0, 'extension': late.extension()})


#: The boxes above nbgrader's feedback (:func:`safe_feedback`): bootstrap's panels, which
#: nbgrader's page already styles, with room between a table's label and its value.
ABOVE_STYLE = ('div.above .panel-heading h4{margin:0}'
               'div.late th{padding:2px 2em 2px 0}div.late td{padding:2px 0}'
               'div.late p{margin:.8em 0 0}'
               'div.flags code{white-space:pre-wrap}')


def standing_html(table: str) -> str:
    """The learner's table of every notebook's parts (:func:`ros2nb.graded_parts.table_html`,
    from the grader's results) as the box that heads each feedback page."""
    return f'<div id="standing" class="standing">{table}</div>'


def safe_feedback(made: str, title: str, flags: Sequence[str] = (),
                  late: Optional[Lateness] = None, standing: str = '') -> str:
    """nbgrader's feedback page ``made`` rebuilt by :func:`page` (its styles kept), headed by
    the learner's ``standing`` in every notebook (:func:`standing_html`; '' for none), the
    notebook's lateness (:func:`late_html`) and the judge's ``flags`` (:func:`flags_html`)."""
    head, _, rest = made.partition('<body')
    tag, _, body = rest.partition('>')
    boxes = [standing, late_html(late), flags_html(flags)]
    body = render('above.html.j2', boxes=boxes) + body.rsplit('</body>', 1)[0]
    styles = re.findall(r'<style[^>]*>(.*?)</style>', head, flags=re.S | re.I)
    found = re.search(r'class="([\w\s-]*)"', tag)
    return page(title, body, [*styles, ABOVE_STYLE], found.group(1) if found else '')
