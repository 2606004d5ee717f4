"""axe-core, the accessibility engine, run in a page Playwright opened.

axe-core comes from npm, pinned, into ``.cache/node`` (the Makefile's ``axe-tool``, which
``make test`` runs): the tests inject its ``axe.min.js`` from there into the page, so nothing
is fetched while they run.  Where it is missing, the tests that need it skip with the one
line :func:`problem` gives.

axe sorts what it finds by impact: critical, serious, moderate and minor.  The course's
website may have none of the first three (:data:`FAILING`); what axe cannot decide (text
over a picture or a gradient, say) it lists as ``incomplete``, for a person to review: the
theme's colours are checked by a test of their own (tests/test_site_colours.py).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Optional

ROOT = Path(__file__).resolve().parents[1]
AXE_JS = ROOT / '.cache' / 'node' / 'node_modules' / 'axe-core' / 'axe.min.js'
#: The impacts that fail a page, from axe's four (the fourth, minor, is reported only).
FAILING = ('critical', 'serious', 'moderate')
IMPACTS = (*FAILING, 'minor')
#: WCAG 2.2 AA's least contrast (1.4.3): normal text, and large text (24 px, or bold 18.66 px).
NORMAL_TEXT, LARGE_TEXT = 4.5, 3.0
#: The contrast of each element (a CSS selector) with the background it sits on: the first
#: ancestor's that is not transparent, whatever may lie over it (axe leaves such elements for
#: review when something overlaps them), computed by axe's own colour functions.  Returns
#: [selector, contrast, large text] per selector.
CONTRAST_JS = """(selectors) => selectors.map(selector => {
  const C = axe.commons.color, el = document.querySelector(selector);
  if (!el) return [selector, null, false];
  const colour = (css) => { const c = new C.Color(); c.parseString(css); return c; };
  let bg = colour('rgb(255, 255, 255)');
  for (let e = el; e; e = e.parentElement) {
    const c = colour(getComputedStyle(e).backgroundColor);
    if (c.alpha > 0) { bg = c.alpha < 1 ? C.flattenColors(c, bg) : c; break; }
  }
  const style = getComputedStyle(el), fg = colour(style.color);
  const size = parseFloat(style.fontSize), bold = parseInt(style.fontWeight) >= 700;
  return [selector, C.getContrast(bg, fg.alpha < 1 ? C.flattenColors(fg, bg) : fg),
          size >= 24 || (bold && size >= 18.66)];
})"""


def problem() -> Optional[str]:
    """Why axe cannot run here, in one line (None when it can)."""
    if not AXE_JS.is_file():
        return f'axe-core is not installed in {AXE_JS.parent} (make axe-tool, which needs npm)'
    return None


def version() -> str:
    """The installed axe-core's version, from its file's banner (``4.14.1``)."""
    match = re.match(r'/\*! axe v(\S+)', AXE_JS.read_text(encoding='utf-8')[:100])
    return match.group(1) if match else 'unknown'


def run(page: Any) -> dict:
    """axe's results for the page ``page`` shows now (``axe.run`` on the whole document,
    every rule on, best practices included).

    :return: axe's results object: ``violations``, ``incomplete``, ``passes``, each a list
        of rules with their ``impact`` and ``nodes``.
    """
    if not page.evaluate('typeof window.axe !== "undefined"'):
        page.add_script_tag(path=str(AXE_JS))
    return page.evaluate('axe.run(document, {resultTypes: ["violations", "incomplete"]})')


#: What sticks out past the right edge of the page's article, outside any box of the article
#: that scrolls or clips: text a reader cannot reach (a code line that neither wraps nor
#: scrolls).  An element's content counts where it overflows the element itself.  One line
#: per element.
OVERFLOW_JS = """() => {
  const article = document.querySelector('.bd-article');
  if (!article) return [];
  const right = article.getBoundingClientRect().right, out = [];
  const held = (el) => {
    for (let e = el; e && e !== article; e = e.parentElement)
      if (['auto', 'scroll', 'hidden'].includes(getComputedStyle(e).overflowX)) return true;
    return false;
  };
  for (const el of article.querySelectorAll('*')) {
    const box = el.getBoundingClientRect();
    const reach = Math.max(box.right, box.left + el.scrollWidth);
    if (!box.width || reach <= right + 2 || held(el)) continue;
    out.push(`<${el.tagName.toLowerCase()} class="${el.className}"> ` +
             `${Math.round(reach - right)} px past the page: ${el.textContent.slice(0, 50)}`);
  }
  return out;
}"""


def sticking_out(page: Any) -> list[str]:
    """What runs off the right of the page (:data:`OVERFLOW_JS`), one line per element."""
    return page.evaluate(OVERFLOW_JS)


def _selector(node: dict) -> str:
    target = node['target'][-1]
    return target if isinstance(target, str) else ' '.join(target)


def contrast(page: Any, selectors: list[str]) -> list[tuple[str, float, bool]]:
    """Each element's contrast with its background (:data:`CONTRAST_JS`), axe loaded first:
    ``(selector, contrast, large text)``.

    :raises AssertionError: when a selector names no element of the page.
    """
    if not page.evaluate('typeof window.axe !== "undefined"'):
        page.add_script_tag(path=str(AXE_JS))
    found = [tuple(row) for row in page.evaluate(CONTRAST_JS, selectors)]
    assert all(row[1] is not None for row in found), found
    return found


def reviewed(page: Any, results: dict) -> list[str]:
    """What axe left for review about colour contrast (``incomplete``: an element partly
    covered, say), checked here: one line per element whose text has less contrast with its
    own background than WCAG AA asks (:data:`NORMAL_TEXT`, :data:`LARGE_TEXT`)."""
    selectors = [_selector(node) for rule in results['incomplete']
                 if rule['id'] == 'color-contrast' for node in rule['nodes']]
    if not selectors:
        return []
    return [f'{selector}: contrast {ratio:.2f}, under {LARGE_TEXT if large else NORMAL_TEXT}'
            for selector, ratio, large in contrast(page, selectors)
            if ratio < (LARGE_TEXT if large else NORMAL_TEXT)]


def counts(results: dict) -> dict[str, tuple[int, int]]:
    """Per impact, how many rules axe found violated and on how many elements:
    ``{'serious': (1, 2), ...}``, every impact of :data:`IMPACTS` present."""
    table = {impact: (0, 0) for impact in IMPACTS}
    for rule in results['violations']:
        rules, nodes = table[rule['impact']]
        table[rule['impact']] = (rules + 1, nodes + len(rule['nodes']))
    return table


def failures(results: dict) -> list[str]:
    """The violations of :data:`FAILING` impact, one line each: the rule, its impact, and
    the first elements it names (their CSS selectors)."""
    lines = []
    for rule in results['violations']:
        if rule['impact'] in FAILING:
            where = ', '.join(_selector(node) for node in rule['nodes'][:3])
            lines.append(f'{rule["id"]} ({rule["impact"]}, {len(rule["nodes"])} elements: '
                         f'{where}): {rule["help"]}')
    return lines
