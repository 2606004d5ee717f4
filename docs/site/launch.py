"""The ``{launch}`` directive: the box at the top of each lesson page saying how to open it.

Three ways, as README.md says: ``make lab`` on the learner's machine, the course's image,
and, when the site's builder names one, a JupyterHub: the conf.py setting
``launch_hub_url``, a URL template whose ``{notebook}`` is the lesson's file name (from the
environment variable ``DOCS_HUB_URL``, like Jupyter Book's launch buttons).  Without it the
page shows no hub link at all.
"""

from __future__ import annotations

from docutils import nodes
from docutils.statemachine import StringList
from sphinx.application import Sphinx
from sphinx.util.docutils import SphinxDirective

IMAGE_RUN = ('podman run --rm -p 127.0.0.1:8888:8888 -v ros2-course-work:/home/learner/work '
             'ros2-course')


def launch_markdown(notebook: str, hub_url: str) -> str:
    """The box's text (MyST) for the lesson ``notebook`` (``04-write-the-subscriber.ipynb``).

    :param hub_url: the hub's URL template (``{notebook}`` is replaced); empty for no hub.
    """
    lines = [
        ':::{admonition} Open this lesson',
        ':class: tip launch',
        '',
        f'- **On your machine:** `make lab` in the course folder, then open `{notebook}` in '
        'the `work/` folder JupyterLab shows ([Start](../README.md)).',
        f'- **In the course\'s image** (any machine with podman or Docker): `make image`, then '
        f'`{IMAGE_RUN}`, open the `http://127.0.0.1:8888/lab?token=...` line it prints and '
        f'then `work/{notebook}`.',
    ]
    if hub_url:
        lines.append(f'- **On your class\'s hub:** [open {notebook}]'
                     f'({hub_url.replace("{notebook}", notebook)})')
    return '\n'.join([*lines, ':::'])


class Launch(SphinxDirective):
    """``{launch} NN-title.ipynb``: how to open this lesson."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        container = nodes.container(classes=['launch'])
        text = launch_markdown(self.arguments[0], self.config.launch_hub_url)
        self.state.nested_parse(StringList(text.splitlines(), self.get_source_info()[0]),
                                self.content_offset, container)
        return [container]


def setup(app: Sphinx) -> dict:
    """Sphinx's entry point: the directive and its setting."""
    app.add_config_value('launch_hub_url', '', 'env', types=[str])
    app.add_directive('launch', Launch)
    return {'parallel_read_safe': True, 'parallel_write_safe': True}
