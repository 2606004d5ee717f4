"""``make docs``: the course's website, a static HTML site that opens offline.

Prepares the site's sources in a build folder (``docs/_build/source``): the lesson pages made
from ``solutions/`` and ``notebooks/`` (lessons.py), and the pages that already exist
(README.md as the start page, the guides in ``docs/``, this folder's index and reference
pages) hard-linked in, laid out as in the repository so that their relative links hold.  Then
Sphinx builds ``docs/_build/html`` from them with every warning an error, and the built
pages are checked: every relative ``href`` and ``src`` names a file of the site (and an
``id`` on it, for ``#fragment``), and nothing is loaded from the network (a ``src``, a
stylesheet, a script or a font from ``http(s)://``).

    python docs/site/build.py [--solutions] [--out DIR] [--course DIR] [--lessons NN ...]
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from html.parser import HTMLParser
from pathlib import Path
from typing import Optional
from urllib.parse import unquote, urlsplit

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import lessons  # noqa: E402 - this folder's module, found through the line above

#: The guides of ``docs/`` that are not pages of the site: its own index for GitHub, which
#: the site's index replaces.
NOT_PAGES = {'index.md'}
#: Attributes whose URL the browser loads by itself (a link, ``<a href>``, only if followed).
LOADED = {('img', 'src'), ('script', 'src'), ('link', 'href'), ('iframe', 'src'),
          ('source', 'src'), ('video', 'src'), ('audio', 'src'), ('embed', 'src'),
          ('object', 'data'), ('image', 'href'), ('use', 'href')}


def _link(target: Path, link: Path) -> None:
    """``link`` made the same file as ``target``: a hard link (Sphinx and MyST resolve a
    symbolic one, and the page's relative links would then start from the repository), or
    a copy where the build folder is on another file system."""
    link.parent.mkdir(parents=True, exist_ok=True)
    if link.exists() and not link.is_symlink() and link.samefile(target):
        return
    if link.exists() or link.is_symlink():
        link.unlink()
    try:
        os.link(target, link)
    except OSError:
        shutil.copy2(target, link)


def source_tree(into: Path, course: Path, *, solutions: bool,
                only: Optional[list[str]] = None) -> Path:
    """Lay out the site's sources in ``into``: the lesson pages written, the rest linked.

    :param course: the folder with ``solutions/`` and ``notebooks/`` (the repository's own,
        or a test's copy).
    :param only: the lessons to include (their numbers); None for every lesson.
    :return: ``into``, Sphinx's source folder.
    """
    lessons.prepare(course, into / 'lessons', solutions=solutions, only=only)
    _link(ROOT / 'README.md', into / 'README.md')
    _link(HERE / 'index.md', into / 'index.md')
    for page in sorted((HERE / 'reference').glob('*.md')):
        _link(page, into / 'reference' / page.name)
    for guide in sorted((ROOT / 'docs').glob('*.md')):
        if guide.name not in NOT_PAGES:
            _link(guide, into / 'docs' / guide.name)
    for image in sorted((ROOT / 'docs' / 'images').iterdir()):
        _link(image, into / 'docs' / 'images' / image.name)
    return into


class _Links(HTMLParser):
    """The ids of one page, and its URLs: (tag, attribute, URL)."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.ids: set[str] = set()
        self.urls: list[tuple[str, str, str]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, Optional[str]]]) -> None:
        for name, value in attrs:
            if value is None:
                continue
            if name in ('id', 'name'):
                self.ids.add(value)
            elif name in ('href', 'src', 'data') or name.endswith(':href'):
                self.urls.append((tag, name.rpartition(':')[2], value))


def _parse(page: Path) -> _Links:
    parser = _Links()
    parser.feed(page.read_text(encoding='utf-8', errors='replace'))
    return parser


def link_problems(html: Path) -> list[str]:
    """What is wrong with the built site's links, one line each (nothing: an empty list).

    A relative URL must name a file of the site, and its ``#fragment`` an id on that page;
    no page may load anything from the network (``LOADED``).
    """
    # _static/ holds the themes' files, templates among them (*macros.html), never a page.
    pages = {page: _parse(page) for page in sorted(html.rglob('*.html'))
             if page.relative_to(html).parts[0] != '_static'}
    problems = []
    for page, parsed in pages.items():
        name = page.relative_to(html)
        for tag, attribute, url in parsed.urls:
            parts = urlsplit(url)
            if parts.scheme in ('http', 'https') or url.startswith('//'):
                if (tag, attribute) in LOADED:
                    problems.append(f'{name}: <{tag} {attribute}="{url}"> loads from the network')
                continue
            if parts.scheme or not (parts.path or parts.fragment):
                continue  # data:, mailto:, javascript: and the like, or an empty href
            target = (page.parent / unquote(parts.path)).resolve() if parts.path else page
            if target.is_dir():
                target = target / 'index.html'
            if not target.is_file() or not target.is_relative_to(html.resolve()):
                problems.append(f'{name}: {url} names no file of the site')
                continue
            if parts.fragment and target.suffix == '.html':
                ids = pages[target].ids if target in pages else _parse(target).ids
                if unquote(parts.fragment) not in ids:
                    problems.append(f'{name}: {url}: no id "{parts.fragment}" on that page')
    return problems


def build(out: Path, *, course: Path = ROOT, solutions: bool = False,
          only: Optional[list[str]] = None) -> list[str]:
    """Build the site into ``out/html`` (its sources in ``out/source``, Sphinx's cache in
    ``out/doctrees``).

    :return: every problem, one line each: Sphinx's warnings (which fail the build) and
        :func:`link_problems`; an empty list for a good site.
    """
    from sphinx.cmd.build import build_main
    source = source_tree(out / 'source', course, solutions=solutions, only=only)
    html = out / 'html'
    # -E: every page read again, so that each build repeats every warning (an incremental
    # build only warns about the pages it reads).
    # schedule_course: the start page's schedule is read from this course's notebooks.
    status = build_main(['-b', 'html', '-W', '--keep-going', '-E', '-q', '-c', str(HERE),
                         '-D', f'schedule_course={course.resolve()}',
                         '-d', str(out / 'doctrees'), str(source), str(html)])
    if status:
        return [f'sphinx-build failed (exit {status}): its warnings are above']
    return link_problems(html)


def main(argv: Optional[list[str]] = None) -> int:
    """The command line (the module's docstring); exit status 1 on any problem."""
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', type=Path, default=ROOT / 'docs' / '_build',
                        help='where the site goes: OUT/html (default docs/_build)')
    parser.add_argument('--course', type=Path, default=ROOT,
                        help='the folder with solutions/ and notebooks/ (default: this one)')
    parser.add_argument('--solutions', action='store_true',
                        help="the instructor's site: each exercise followed by its solution")
    parser.add_argument('--lessons', nargs='+', metavar='NN',
                        help='only these lessons (their numbers), for a quick look')
    parser.add_argument('--clean', action='store_true', help='remove OUT first')
    args = parser.parse_args(argv)
    if args.clean:
        shutil.rmtree(args.out, ignore_errors=True)
    problems = build(args.out, course=args.course, solutions=args.solutions,
                     only=args.lessons)
    for problem in problems:
        print(problem, file=sys.stderr)
    if not problems:
        print(f'The site: {args.out / "html" / "index.html"}')
    return 1 if problems else 0


if __name__ == '__main__':
    sys.exit(main())
