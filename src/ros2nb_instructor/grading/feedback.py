"""Feedback pages that cannot run code: nbgrader's pages, sanitised, under a strict CSP.

Runs on the instructor's host.  nbgrader (through nbconvert) writes a feedback page per
notebook; what the learner wrote reaches it as text already (:mod:`.notebooks`), and this
module is the second wall: the page's body goes through nh3 (the Ammonia sanitiser), its
head is rebuilt from the template's own style sheets only (no script, no remote load), and
a Content-Security-Policy forbids every script and every load but inline styles and
``data:`` images.  A page opens the same in the instructor's and the learner's browser.
"""

from __future__ import annotations

import html
import re
from typing import Sequence

import nh3

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
    """A whole page: CSP, the title as text, the given style sheets, the body sanitised."""
    css = ''.join(f'<style>{s}</style>' for s in styles if '</' not in s)
    return (f'<!DOCTYPE html>\n<html><head><meta charset="utf-8">'
            f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
            f'<title>{html.escape(title)}</title>{css}</head>\n'
            f'<body class="{html.escape(body_class)}">{clean_body(body)}</body></html>\n')


#: What the feedback page says above the judge's flags (:mod:`ros2nb.judge.flags`).
FLAGS_HEADING = 'Code your instructor will look at'
FLAGS_WHY = ('These lines reach past what the lessons use (into the course\'s own answers or '
             'the process they run in). No point changed because of them; your instructor '
             'reads them with your notebook.')


def flags_html(flags: Sequence[str]) -> str:
    """The judge's flags of one notebook as a box of the feedback page (empty for none);
    each flag is text, escaped."""
    if not flags:
        return ''
    items = ''.join(f'<li><code>{html.escape(flag)}</code></li>' for flag in flags)
    return (f'<div id="flags" class="flags"><h2>{FLAGS_HEADING}</h2><p>{FLAGS_WHY}</p>'
            f'<ul>{items}</ul></div>')


def safe_feedback(made: str, title: str, flags: Sequence[str] = ()) -> str:
    """nbgrader's feedback page ``made`` rebuilt by :func:`page` (its styles kept), with the
    judge's ``flags`` of the notebook first (:func:`flags_html`)."""
    head, _, rest = made.partition('<body')
    tag, _, body = rest.partition('>')
    body = flags_html(flags) + body.rsplit('</body>', 1)[0]
    styles = re.findall(r'<style[^>]*>(.*?)</style>', head, flags=re.S | re.I)
    found = re.search(r'class="([\w\s-]*)"', tag)
    return page(title, body, styles, found.group(1) if found else '')
