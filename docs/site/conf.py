"""Sphinx's settings for the course's website (``make docs``; docs/site/build.py).

The site is read from the folder build.py prepares (the lessons made from ``solutions/``,
the guides linked in from ``docs/`` and README.md) and must open offline: nothing on a page
loads from the network.
"""

import os
import sys
from pathlib import Path

from pygments.lexers.special import TextLexer
from sphinx.highlighting import lexers

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))  # launch.py (the lessons' launch box), schedule.py (the start page's)

project = 'ROS 2 topics in Jupyter'
author = 'the course'
copyright = 'the course\'s authors, Apache-2.0'
html_title = 'ROS 2 topics in Jupyter'

extensions = ['myst_nb', 'sphinx.ext.autodoc', 'sphinx_exercise', 'launch', 'schedule']

# The pages show the outputs stored in the notebooks: the build runs no ROS.
nb_execution_mode = 'off'
myst_enable_extensions = ['colon_fence']
# README's and the guides' links to a section (#platforms) resolve to its heading.
myst_heading_anchors = 3
# MyST-NB's widget support loads require.js and the widget manager from a CDN; the lessons'
# widgets are shown by their stored snapshots instead (lessons.py).
nb_ipywidgets_js = {}
# Tracebacks are shown with their colours, whatever text a program printed into them (the
# IPython traceback lexer stops at text it does not expect, such as colcon's "Aborted!").
nb_render_error_lexer = 'myst-ansi'

# The Mermaid diagram in docs/architecture.md is shown as its text: rendering it would need
# mermaid.js, from the network.
lexers['mermaid'] = TextLexer()

autodoc_default_options = {'members': True, 'show-inheritance': True}
autodoc_member_order = 'bysource'
autodoc_typehints = 'description'

html_theme = 'sphinx_book_theme'
html_theme_options = {
    'home_page_in_toc': True,
    'show_toc_level': 2,
    'use_download_button': True,
    # One search box: the sidebar's (on a phone, the page header's icon). The theme's top bar
    # held a second one, and nothing else.
    'navbar_persistent': [],
}
# The theme's colour mode when the reader has chosen none: without it the page starts with
# an empty mode and logs "Got invalid theme mode" on every page.
html_context = {'default_mode': 'auto'}
# The course's templates (_templates/) come before the theme's: the search button named by
# its visible text, and the site's title inside a landmark (course-brand.html).
templates_path = ['_templates']
html_sidebars = {'**': ['course-brand.html', 'search-button-field.html', 'sbt-sidebar-nav.html']}
html_static_path = ['_static']
html_css_files = ['course.css']
# The browser asks every site for an icon: without one, each page's first load logs a 404.
html_favicon = '_static/favicon.svg'

#: A hub's URL template for the lessons' launch box, ``{notebook}`` the lesson's file name;
#: empty: no hub link (launch.py).
launch_hub_url = os.environ.get('DOCS_HUB_URL', '')
