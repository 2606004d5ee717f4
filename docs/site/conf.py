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
sys.path.insert(0, str(HERE))  # launch.py, the lessons' launch box

project = 'ROS 2 topics in Jupyter'
author = 'the course'
copyright = 'the course\'s authors, Apache-2.0'
html_title = 'ROS 2 topics in Jupyter'

extensions = ['myst_nb', 'sphinx.ext.autodoc', 'sphinx_exercise', 'launch']

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
}

#: A hub's URL template for the lessons' launch box, ``{notebook}`` the lesson's file name;
#: empty: no hub link (launch.py).
launch_hub_url = os.environ.get('DOCS_HUB_URL', '')
