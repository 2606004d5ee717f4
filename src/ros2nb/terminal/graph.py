"""``rqt_graph`` in a notebook: the running ROS graph, nodes and topics, as a picture.

Introduced in ``06-five-promises.ipynb``.  The facts come from the kernel's graph (as
:func:`ros2nb.node_list` reads it): every node, in this kernel or in any process on the
kernel's domain, and the topics it publishes or subscribes to.  The picture is laid out
by Graphviz's ``dot``, the layout rqt_graph itself uses: publishers left of their
topics, subscribers right of them, no edge drawn across another when it can be helped.
"""

from __future__ import annotations

import html
from typing import Iterable, Optional

from ..errors import Ros2nbError
from ..nbmeta import CAPTION_START
from ..patience import wait_for_work
from ..runtime import current_runtime
from .background import failures, running_pids
from .topic import INFRASTRUCTURE_TOPICS, hidden

#: Seconds :func:`graph_edges` waits for the nodes it is told to expect.
GRAPH_WAIT_S = 60.0


def _endpoints_now() -> set[tuple[str, str, str]]:
    node = current_runtime().node
    found = set()
    for name, namespace in node.get_node_names_and_namespaces():
        full = namespace.rstrip('/') + '/' + name
        if hidden(full):
            continue
        try:
            pubs = node.get_publisher_names_and_types_by_node(name, namespace)
            subs = node.get_subscriber_names_and_types_by_node(name, namespace)
        except Exception:  # the node left the graph between the two calls
            continue
        for kind, entries in (('publisher', pubs), ('subscription', subs)):
            found |= {(full, kind, topic) for topic, _ in entries
                      if topic not in INFRASTRUCTURE_TOPICS and not hidden(topic)}
    return found


def graph_edges(*, expect: Iterable[str] = (),
                timeout: float = GRAPH_WAIT_S) -> list[tuple[str, str, str]]:
    """The graph's endpoints: ``(node, 'publisher' or 'subscription', topic)``, sorted.

    Hidden nodes and topics (``/_ros2nb``, ``/rosout``, ``/parameter_events``, ``/clock``)
    are left out.  Discovery takes a moment: name the nodes you expect and it waits until
    the graph shows each of them with its publishers and subscriptions.

    Introduced in ``06-five-promises.ipynb``.

    :param expect: full node names to wait for, e.g. ``['/temperature_sensor']``.
    :param timeout: seconds to wait for them at most: of the background processes' work
        while they work, of the wall clock while they wait (:class:`~ros2nb.patience.Patience`).
    :raises Ros2nbError: if ROS is not up, or an expected node did not appear in time.
    """
    want = set(expect)
    found: set[tuple[str, str, str]] = set()

    def shown() -> bool:  # or every process started for it ended, some by themselves
        nonlocal found
        found = _endpoints_now()
        return not want - {node for node, _, _ in found} or \
            (not running_pids() and bool(failures()))

    wait_for_work(shown, running_pids(), timeout)
    missing = want - {node for node, _, _ in found}
    if missing:
        why = '; '.join(failures())
        raise Ros2nbError(f'The graph shows no node {sorted(missing)[0]} with a topic'
                          + (f': {why}' if why else f' after {timeout:g} s: is it running?'))
    return sorted(found)


def graph_caption(edges: Iterable[tuple[str, str, str]], title: str = '') -> str:
    """The caption line of a graph picture, from its edges: each topic with who publishes it
    and who subscribes to it (``Figure: the ROS graph, ...: 3 nodes, 2 topics. /temperature:
    published by /temperature_sensor; subscribed by /temperature_monitor.``).

    Introduced in ``06-five-promises.ipynb``.

    :param edges: from :func:`graph_edges`.
    :param title: the picture's title, if it has one.
    """
    edges = sorted(edges)
    nodes = sorted({node for node, _, _ in edges})
    topics = sorted({topic for _, _, topic in edges})
    what = f'the ROS graph{f", {title}" if title else ""}'
    if not edges:
        return f'{CAPTION_START}{what}: no node with a topic.'
    line = [f'{CAPTION_START}{what}: {len(nodes)} node{"s" * (len(nodes) != 1)}, '
            f'{len(topics)} topic{"s" * (len(topics) != 1)}.']
    for topic in topics:
        ends = {kind: ', '.join(node for node, k, t in edges if t == topic and k == kind) or
                'nobody' for kind in ('publisher', 'subscription')}
        line.append(f'{topic}: published by {ends["publisher"]}; subscribed by '
                    f'{ends["subscription"]}.')
    return ' '.join(line)


class GraphPicture:
    """A graph's picture (SVG) with its caption: shown in a notebook as the picture, then the
    caption line under it; ``data`` is the SVG's text, ``caption`` the line.  The SVG is
    labelled with the caption too (``role="img"``, ``aria-label``), for screen readers."""

    def __init__(self, svg: str, caption: str) -> None:
        from IPython.display import SVG  # the <svg> element alone, as IPython shows an SVG

        label = html.escape(caption.removeprefix(CAPTION_START), quote=True)
        self.data = SVG(svg).data.replace('<svg ', f'<svg role="img" aria-label="{label}" ', 1)
        self.caption = caption

    def _ipython_display_(self) -> None:
        from IPython.display import display
        display({'image/svg+xml': self.data, 'text/plain': self.caption}, raw=True)
        print(self.caption)


def graph_picture(edges: Optional[Iterable[tuple[str, str, str]]] = None, *,
                  title: str = '') -> GraphPicture:
    """Draw the graph as rqt_graph does: nodes as ellipses, topics as boxes, arrows for data,
    captioned in words (:func:`graph_caption`).

    Introduced in ``06-five-promises.ipynb``.

    :param edges: from :func:`graph_edges` (``None`` reads the graph now).
    :param title: a caption under the picture.
    :return: the picture the notebook displays, followed by its caption line.
    :raises Ros2nbError: when Graphviz's ``dot`` is not installed (``make graph-tool``).
    """
    import graphviz

    edges = sorted(_endpoints_now() if edges is None else edges)
    # The graph's name is the SVG's <title>, which a screen reader reads out.
    graph = graphviz.Digraph(name=title or 'ROS graph',
                             graph_attr={'rankdir': 'LR', 'label': title, 'fontsize': '11',
                                         'fontname': 'Helvetica', 'bgcolor': 'white'},
                             node_attr={'fontname': 'Helvetica', 'fontsize': '11',
                                        'style': 'filled'})
    for name in sorted({node for node, _, _ in edges}):
        graph.node('node ' + name, label=name, shape='ellipse', fillcolor='#cfe3f7')
    for topic in sorted({topic for _, _, topic in edges}):
        graph.node('topic ' + topic, label=topic, shape='box', fillcolor='#f3e5c0')
    for node, kind, topic in edges:
        if kind == 'publisher':
            graph.edge('node ' + node, 'topic ' + topic)
        else:
            graph.edge('topic ' + topic, 'node ' + node)
    try:
        svg = graph.pipe(format='svg', encoding='utf-8')
    except graphviz.ExecutableNotFound:
        raise Ros2nbError("Graphviz's dot is not installed: run make graph-tool (or sudo "
                          'apt-get install graphviz); graph_edges() lists the same graph as '
                          'text.') from None
    return GraphPicture(svg, graph_caption(edges, title))
